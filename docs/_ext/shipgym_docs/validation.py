"""The validation tables: every ship's standard manoeuvres beside the published values.

Run at build time from :mod:`shipgym.validation` (all five ships' manoeuvres take about a
second), so the page ``docs/validation.md`` cannot go stale: one table per ship
(``_generated/validation/<ship>.inc.md``: every figure of ours, the published value, the
relative error, the tolerance the tests assert and the source) and the Esso Osaka
propulsion options (``_generated/validation/esso_osaka_options.inc.md``).
"""

from __future__ import annotations

import math
from pathlib import Path

from shipgym.models import MODELS
from shipgym.validation import (
    FIGURES,
    figure_label,
    measure_ship,
    published,
    relative_error,
)
from shipgym_docs.pages import table, write_text

#: the figures every ship's table shows, published or not
SHOWN = tuple(FIGURES)

#: Esso Osaka configurations compared with the 3 m model's tests: (label, variant, params)
ESSO_OPTIONS: tuple[tuple[str, str | None, dict[str, float]], ...] = (
    ("`literal`, PI speed control (default)", None, {}),
    ("`literal`, `speed_control = 0` (n → n0 = 0.68 rps full scale)", None, {"speed_control": 0.0}),
    ("`literal`, `constant_revolutions = 1`", None, {"constant_revolutions": 1.0}),
    ("`intended_fix`, `constant_revolutions = 1`", "intended_fix", {"constant_revolutions": 1.0}),
)
#: the figures of the options table (port/starboard means, as the tests are quoted) and
#: their column names
ESSO_FIGURES: dict[str, str] = {
    "advance_mean": "advance [L]",
    "tactical_diameter_mean": "tactical diameter [L]",
    "r_prime_mean": "r′ = rL/U0",
    "r_prime_local_mean": "rL/U",
    "speed_loss_mean": "speed loss",
    "overshoot_20_1": "20/20 first overshoot [deg]",
    "switch_20": "20/20 first switch [L/U0]",
}


def fmt(value: float) -> str:
    """A figure with three significant digits; NaN (never reached) as a dash."""
    return "—" if value is None or math.isnan(value) else f"{value:.3g}"


def ship_table(ship: str, ours: dict[str, float]) -> str:
    """The ship's figures, each published value beside ours with its error and source."""
    rows = []
    refs = published(ship)
    done = set()
    for ref in refs:
        what, unit = figure_label(ref.figure)
        err = relative_error(ours[ref.figure], ref.value)
        if ref.tolerance is None:
            verdict = f"not asserted: {ref.note}"
        else:
            within = "within" if abs(err) <= ref.tolerance else "OUTSIDE"
            verdict = f"{within} ±{ref.tolerance:.0%} ({ref.note})"
        rows.append(
            (what, unit, fmt(ours[ref.figure]), fmt(ref.value), f"{err:+.1%}", verdict, ref.source)
        )
        done.add(ref.figure)
    for key in SHOWN:
        if key not in done:
            what, unit = figure_label(key)
            rows.append((what, unit, fmt(ours[key]), "—", "", "", "none published"))
    header = ["figure", "unit", "ours", "published", "error", "tolerance", "source"]
    return table(header, rows)


def esso_options_table() -> str:
    """The Esso Osaka options beside the 3 m model's tests (port/starboard means of the
    35° turns), each figure with its error against the tests."""
    tests = {p.figure: p.value for p in published("esso_osaka")}
    rows = []
    for label, variant, params in ESSO_OPTIONS:
        ours = measure_ship("esso_osaka", variant, **params)
        cells = []
        for key in ESSO_FIGURES:
            cell = fmt(ours[key])
            if key in tests:
                cell += f" ({relative_error(ours[key], tests[key]):+.0%})"
            cells.append(cell)
        rows.append([label, *cells])
    rows.append(["3 m model tests (quoted)"] + [fmt(tests.get(k, math.nan)) for k in ESSO_FIGURES])
    return table(["configuration", *ESSO_FIGURES.values()], rows)


def write(root: Path) -> list[Path]:
    out = []
    for ship in MODELS:
        text = ship_table(ship, measure_ship(ship))
        out.append(write_text(root / "validation" / f"{ship}.inc.md", text))
    out.append(write_text(root / "validation" / "esso_osaka_options.inc.md", esso_options_table()))
    return out
