"""Every ship's standard manoeuvres beside the published measurements of its hull.

:func:`measure` runs a ship's 35° turning circles (both ways), 10/10 and 20/20 zig-zags
(:mod:`shipgym.manoeuvres`) and returns the figures of :data:`FIGURES` (lengths in ship
lengths L, times in L/U0, angles in degrees).  :data:`PUBLISHED` holds what the literature
gives for each hull (read off each ship's record, ``Ship.published``), each value with its
source; a value with a ``tolerance`` is asserted by ``tests/shipgym/test_validation.py``, one
without it is shown and not asserted (the reason is its ``note``).  The docs page
``docs/validation.md`` renders both at build time.
"""

from __future__ import annotations

import math

from shipgym.manoeuvres import turning_circle, zigzag
from shipgym.models import MODELS
from shipgym.models.base import ShipModel
from shipgym.models.ship import Published, ShipTable

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


#: model id -> the published values of its hull (each ship record's ``published``; ships
#: with none are left out)
PUBLISHED: ShipTable[tuple[Published, ...]] = ShipTable(
    lambda ship: ((ship.name, ship.published),) if ship.published else ()
)


def published(ship: str) -> list[Published]:
    """The published values of ``ship``, in its record's order."""
    return list(PUBLISHED.get(ship, ()))


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
