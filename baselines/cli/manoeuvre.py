"""``shipgym manoeuvre SHIP KIND``: turning circle or zig-zag of a ship model.

The text output opens with the ship's length L [m] and approach speed U0 [m/s, kn], then
one figure a line, each with its unit (:data:`shipgym.manoeuvres.FIGURE_UNITS`): times in
s, angles in deg, turn rates in deg/s, distances in m and in ship lengths L, speeds in m/s
and kn, the speed loss in % of U0 (a fraction in ``--json``); then the IMO criteria, value
and limit in the criterion's unit.  ``--json`` prints the figures under their names (SI and
deg, as :mod:`shipgym.manoeuvres` returns them), ``units`` (figure → unit) and
``imo_criteria``.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from typing import Any

from shipgym.manoeuvres import (
    FIGURE_UNITS,
    KNOT,
    ManoeuvreLog,
    plot_manoeuvre,
    turning_circle,
    zigzag,
)
from shipgym.manoeuvring_standards import TURNING_RUDDER_DEG, imo_criteria
from shipgym.models import MODELS
from shipgym.models.base import ShipModel
from shipgym_baselines.cli.options import add_json_option, emit
from shipgym_baselines.errors import RunError

Manoeuvre = Callable[[ShipModel, argparse.Namespace], tuple[ManoeuvreLog, dict[str, float]]]


def _turning(model: ShipModel, args: argparse.Namespace) -> tuple[ManoeuvreLog, dict]:
    """Turning circle at --rudder [deg] (default 35° or the ship's rudder limit)."""
    if args.rudder is None:
        args.rudder = min(TURNING_RUDDER_DEG, math.degrees(model.rudder_limit))
    return turning_circle(model, args.rudder)


def _zigzag(model: ShipModel, args: argparse.Namespace) -> tuple[ManoeuvreLog, dict]:
    """--rudder/--switch zig-zag [deg] (default 20/20; the switch defaults to the rudder)."""
    args.rudder = args.rudder if args.rudder is not None else 20.0
    args.switch = args.switch if args.switch is not None else args.rudder
    return zigzag(model, args.rudder, args.switch)


#: manoeuvre kind -> the run on a ship with the parsed options
MANOEUVRES: dict[str, Manoeuvre] = {"turning": _turning, "zigzag": _zigzag}


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "manoeuvre", help="turning circle or zig-zag of a ship model, with figures and a plot"
    )
    p.add_argument("ship", help=f"ship model id ({', '.join(MODELS)})")
    p.add_argument("kind", choices=list(MANOEUVRES))
    p.add_argument(
        "--rudder",
        type=float,
        default=None,
        help="rudder angle [deg] (default: 35 turning, limited to the ship's maximum rudder; "
        "20 zig-zag; the output's first line says the angle used)",
    )
    p.add_argument("--switch", type=float, default=None, help="zig-zag heading switch [deg]")
    p.add_argument("--variant", default=None, help="model variant (e.g. esso_osaka literal)")
    p.add_argument("--out", default="results/manoeuvres", help="directory of the plot")
    add_json_option(
        p,
        "print the figures as a JSON object, with units (figure -> unit) and imo_criteria: "
        "the MSC.137(76) criteria the manoeuvre measures (turning at 35°/the rudder limit, "
        "zig-zag 10/10 and 20/20)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Check the ship and ``--out`` (a writable folder; its plot of the same manoeuvre is
    replaced), run the manoeuvre, save its plot, print the figures."""
    from shipgym_baselines.records.folders import check_out_dir

    if args.ship not in MODELS:
        raise RunError(f"unknown ship {args.ship!r}; valid: {', '.join(sorted(MODELS))}")
    out = check_out_dir(args.out, force=True)
    model = MODELS[args.ship](variant=args.variant)
    log, figures = MANOEUVRES[args.kind](model, args)
    out.mkdir(parents=True, exist_ok=True)
    plot = out / f"{args.ship}_{args.kind}.png"
    plot_manoeuvre(model, args.kind, log, figures, str(plot))
    criteria = imo_criteria(
        args.kind,
        figures,
        length=model.length,
        speed=model.nominal_speed,
        rudder_deg=args.rudder,
        switch_deg=args.switch,
        max_rudder_deg=math.degrees(model.rudder_limit),
    )
    lines = [_heading(args, model)]
    lines += figure_lines(figures, model.length, model.nominal_speed)
    lines += [_criterion_line(c) for c in criteria] + [f"plot: {plot}"]
    units = {k: FIGURE_UNITS[k] for k in figures if k in FIGURE_UNITS}
    document: dict[str, Any] = {**figures, "units": units, "imo_criteria": criteria}
    emit(args, document, "\n".join(lines))
    return 0


def _heading(args: argparse.Namespace, model: ShipModel) -> str:
    """The manoeuvre, its angles [deg] and the ship's L [m] and U0 [m/s, kn]."""
    if args.kind == "turning":
        what = f"turning circle, rudder {args.rudder:.4g} deg"
    else:
        what = f"zig-zag, rudder {args.rudder:.4g} deg, switch {args.switch:.4g} deg"
    speed = model.nominal_speed
    return (
        f"{args.ship} {what}; ship length L = {model.length:.4g} m, approach speed "
        f"U0 = {speed:.4g} m/s = {speed / KNOT:.4g} kn"
    )


def figure_lines(figures: dict[str, float], length: float, speed: float) -> list[str]:
    """One line per figure, its value with its unit: a distance [m] also in ship lengths
    ``length`` [m], a speed [m/s] also in kn and in % of U0 ``speed`` [m/s], the speed loss
    (a fraction of U0) in %."""
    lines = []
    for key, value in figures.items():
        unit = FIGURE_UNITS.get(key, "")
        if unit == "m":
            text = f"{value:.4g} m = {value / length:.4g} L"
        elif unit == "m/s":
            text = f"{value:.4g} m/s = {value / KNOT:.4g} kn ({100 * value / speed:.4g} % of U0)"
        elif unit == "1":
            text = f"{100 * value:.4g} % of U0"  # the fraction (--json) in per cent
        else:
            text = f"{value:.4g} {unit}".rstrip()
        lines.append(f"{key:22s} {text}")
    return lines


def _criterion_line(c: dict[str, Any]) -> str:
    unit = c["unit"]
    value = "not reached" if c["value"] is None else f"{c['value']:.4g} {unit}"
    verdict = "pass" if c["passed"] else "FAIL"
    return f"IMO {c['criterion']:18s} {value} ≤ {c['limit']:.4g} {unit}: {verdict}"
