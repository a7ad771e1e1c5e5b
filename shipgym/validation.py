"""Every ship's standard manoeuvres beside the published measurements of its hull.

:func:`measure` runs a ship's 35° turning circles (both ways), 10/10 and 20/20 zig-zags
(:mod:`shipgym.manoeuvres`) and returns the figures of :data:`FIGURES` (lengths in ship
lengths L, times in L/U0, angles in degrees).  :data:`PUBLISHED` holds what the literature
gives for each hull, each value with its source; a value with a ``tolerance`` is asserted by
``tests/shipgym/test_validation.py``, one without it is shown and not asserted (the reason is
its ``note``).  The docs page ``docs/validation.md`` renders both at build time.
"""

from __future__ import annotations

import dataclasses
import math

from shipgym.manoeuvres import turning_circle, zigzag
from shipgym.models import MODELS
from shipgym.models.base import ShipModel

#: figure key -> (what, unit); turning figures of the starboard turn (δ > 0), ``_port`` the
#: port turn, ``_mean`` their mean; zig-zags start to starboard
FIGURES: dict[str, tuple[str, str]] = {
    "advance": ("35° turn: advance", "L"),
    "tactical_diameter": ("35° turn: tactical diameter", "L"),
    "r_prime": ("35° turn: steady r′ = rL/U0", "-"),
    "r_prime_local": ("35° turn: steady rL/U (U the speed in the turn)", "-"),
    "steady_turn_rate": ("35° turn: steady turn rate", "rad/s"),
    "speed_loss": ("35° turn: speed loss 1 − U/U0", "-"),
    "overshoot_10_1": ("10/10 zig-zag: first overshoot", "deg"),
    "overshoot_10_2": ("10/10 zig-zag: second overshoot", "deg"),
    "overshoot_20_1": ("20/20 zig-zag: first overshoot", "deg"),
    "overshoot_20_2": ("20/20 zig-zag: second overshoot", "deg"),
    "switch_20": ("20/20 zig-zag: time to the first rudder switch", "L/U0"),
}
TURNING = ("advance", "tactical_diameter", "r_prime", "r_prime_local", "steady_turn_rate")
TURNING += ("speed_loss",)


@dataclasses.dataclass(frozen=True)
class Published:
    """One published value of a hull: the ship, our figure it compares with, the value (in
    the figure's unit), its source and, when asserted, the relative tolerance and why."""

    ship: str
    figure: str  # a key of FIGURES, with "_port" or "_mean" for the port turn or the mean
    value: float
    source: str
    tolerance: float | None = None  # relative; None: shown, not asserted (see note)
    note: str = ""


#: SIMMAN 2008 free-running tests of the KVLCC2 L7 model (MARIN, λ = 45.714, Fn 0.142,
#: constant rps): the six files MARIN_FREE_KVLCC2_{tc,zz}_*_m.dat of the SIMMAN data set;
#: our reading of them (heading and rudder from the execute point, switches where the
#: heading reaches the switch angle, as shipgym.manoeuvres does)
MARIN = "SIMMAN 2008, MARIN free-running tests of the KVLCC2 L7 model (file {})"
#: turning geometry: the tests' port and starboard tactical diameters differ by about 9 %
TURN_TOL = 0.10
TURN_WHY = "10 %: the tests' own port/starboard tactical diameters differ by about 9 %"
#: 20/20 overshoots: the tests' port-first and starboard-first first overshoots differ by 25 %
ZZ_TOL = 0.25
ZZ_WHY = "25 %: the tests' port-first and starboard-first 20/20 first overshoots differ by 25 %"
#: the 3 m Esso Osaka model of Osaka University (FRT-DS-ESSO, CC BY-NC: numbers only),
#: means of its port and starboard 35° turns and its 20/20 zig-zag, as quoted
FRT = "NAOE-5thLab FRT-DS-ESSO, free-running tests of a 3 m Esso Osaka model (quoted)"
FRT_WHY = "15 %: the 3 m model is another scale and loading than the seeds' 1:100 model"

PUBLISHED: tuple[Published, ...] = (
    Published("kvlcc2", "advance", 3.09, MARIN.format("tc_-35"), TURN_TOL, TURN_WHY),
    Published("kvlcc2", "tactical_diameter", 3.33, MARIN.format("tc_-35"), TURN_TOL, TURN_WHY),
    Published("kvlcc2", "advance_port", 3.02, MARIN.format("tc_35"), TURN_TOL, TURN_WHY),
    Published("kvlcc2", "tactical_diameter_port", 3.07, MARIN.format("tc_35"), TURN_TOL, TURN_WHY),
    Published(
        "kvlcc2",
        "speed_loss",
        0.635,
        MARIN.format("tc_-35") + ", over the last 360° with the rudder held",
        TURN_TOL,
        "10 %: as the geometry",
    ),
    Published(
        "kvlcc2",
        "r_prime_local",
        0.78,
        MARIN.format("tc_-35") + ", over the last 360° with the rudder held",
        None,
        "outside 10 %: our steady turn is tighter than the tests' (their steady diameter "
        "2.55 L) though our tactical diameter is within 10 %",
    ),
    Published(
        "kvlcc2",
        "overshoot_10_1",
        8.1,
        MARIN.format("zz_-10") + " (port first, zz_10: 9.3°)",
        None,
        "outside: our 10/10 first overshoot is under both directions of the tests",
    ),
    Published(
        "kvlcc2",
        "overshoot_10_2",
        22.0,
        MARIN.format("zz_-10") + " (port first, zz_10: 15.2°)",
        None,
        "outside the starboard-first test; the tests' two directions differ by 45 %",
    ),
    Published(
        "kvlcc2",
        "overshoot_20_1",
        12.6,
        MARIN.format("zz_-20") + " (port first: 15.7°)",
        ZZ_TOL,
        ZZ_WHY,
    ),
    Published(
        "kvlcc2",
        "overshoot_20_2",
        16.0,
        MARIN.format("zz_-20") + " (port first: 12.7°)",
        ZZ_TOL,
        ZZ_WHY,
    ),
    Published("kvlcc2", "switch_20", 1.77, MARIN.format("zz_-20"), ZZ_TOL, ZZ_WHY),
    Published("esso_osaka", "advance_mean", 2.57, FRT, 0.15, FRT_WHY),
    Published("esso_osaka", "tactical_diameter_mean", 2.55, FRT, 0.15, FRT_WHY),
    Published(
        "esso_osaka",
        "r_prime_mean",
        0.38,
        FRT,
        None,
        "outside: the tests lose 61 % of their speed at constant rps; the model holds it",
    ),
    Published("esso_osaka", "speed_loss_mean", 0.61, FRT, None, "outside: as r′"),
    Published("esso_osaka", "overshoot_20_1", 3.1, FRT, None, "outside: the model answers faster"),
    Published("esso_osaka", "switch_20", 3.14, FRT, None, "outside: as the overshoot"),
    Published(
        "mariner",
        "steady_turn_rate",
        0.0191,
        "Borkowski (2018) §5: r_max at full rudder (0.6 rad; our turn at the rudder limit)",
        0.01,
        "1 %: a closed form of the same model",
    ),
)


def published(ship: str) -> list[Published]:
    """The published values of ``ship``, in :data:`PUBLISHED` order."""
    return [p for p in PUBLISHED if p.ship == ship]


def _turning(model: ShipModel, sign: float) -> dict[str, float]:
    """The 35° (or rudder-limit) turn to starboard (sign +1) or port (−1) in L, L/U0, rad/s."""
    rudder = sign * min(35.0, math.degrees(model.rudder_limit))
    _, fig = turning_circle(model, rudder)
    length, speed = model.length, model.nominal_speed
    r = abs(math.radians(fig["steady_turn_rate"]))
    return {
        "advance": fig["advance"] / length,
        "tactical_diameter": fig["tactical_diameter"] / length,
        "r_prime": r * length / speed,
        "r_prime_local": r * length / fig["steady_speed"],
        "steady_turn_rate": r,
        "speed_loss": fig["speed_loss"],
    }


def measure(model: ShipModel) -> dict[str, float]:
    """The figures of :data:`FIGURES` of ``model``: turning ones to starboard, ``_port`` and
    ``_mean`` of the two; zig-zags starting to starboard."""
    out = _turning(model, 1.0)
    port = _turning(model, -1.0)
    for key in TURNING:
        out[f"{key}_port"] = port[key]
        out[f"{key}_mean"] = 0.5 * (out[key] + port[key])
    for angle in (10, 20):
        _, fig = zigzag(model, float(angle))
        out[f"overshoot_{angle}_1"] = fig.get("overshoot_1", math.nan)
        out[f"overshoot_{angle}_2"] = fig.get("overshoot_2", math.nan)
        if angle == 20:
            time = fig.get("time_to_first_switch", math.nan)
            out["switch_20"] = time * model.nominal_speed / model.length
    return out


def measure_ship(ship: str, variant: str | None = None, **params: float) -> dict[str, float]:
    """:func:`measure` of the registered ``ship`` (its default parameters changed by
    ``params``)."""
    cls = MODELS[ship]
    record = cls.params_type().replace(**params) if params else None
    return measure(cls(record, variant))


def figure_label(key: str) -> tuple[str, str]:
    """(what, unit) of a figure key with its ``_port``/``_mean`` suffix."""
    for suffix, words in (("_port", " (port turn)"), ("_mean", " (mean of port and starboard)")):
        if key.endswith(suffix):
            what, unit = FIGURES[key.removesuffix(suffix)]
            return what + words, unit
    return FIGURES[key]


def relative_error(ours: float, value: float) -> float:
    """(ours − published) / published."""
    return (ours - value) / value
