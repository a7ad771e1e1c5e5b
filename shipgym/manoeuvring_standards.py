"""IMO Standards for ship manoeuvrability, resolution MSC.137(76) (4 December 2002), applied
to the figures of :mod:`shipgym.manoeuvres`.

The criteria a turning circle or a zig-zag measures (Annex, paragraph 5.3):

* 5.3.1 turning ability: advance ≤ 4.5 L and tactical diameter ≤ 5 L in the turning circle
  manoeuvre (35° rudder or the maximum permissible, 4.2.2; advance and tactical diameter as
  defined in 4.2.3 and 4.2.4);
* 5.3.3.1 first overshoot of the 10°/10° zig-zag ≤ 10° if L/V < 10 s, ≤ 20° if
  L/V ≥ 30 s, and (5 + ½·L/V)° for 10 s ≤ L/V < 30 s;
* 5.3.3.2 second overshoot of the 10°/10° zig-zag ≤ 25° if L/V < 10 s, ≤ 40° if
  L/V ≥ 30 s, and (17.5 + 0.75·L/V)° for 10 s ≤ L/V < 30 s;
* 5.3.3.3 first overshoot of the 20°/20° zig-zag ≤ 25°;

with L the ship's length [m] and V the test speed [m/s] (4.2.1; here the model's nominal
speed).  Initial turning ability (5.3.2) and stopping ability (5.3.4) need manoeuvres
:mod:`shipgym.manoeuvres` does not run.
"""

from __future__ import annotations

from typing import TypedDict

#: the standard turning circle's rudder angle [deg] (4.2.2: 35° or the maximum permissible)
TURNING_RUDDER_DEG = 35.0
#: 5.3.1: advance and tactical diameter limits [ship lengths]
ADVANCE_LIMIT_L = 4.5
TACTICAL_DIAMETER_LIMIT_L = 5.0
#: 5.3.3.3: first overshoot of the 20°/20° zig-zag [deg]
FIRST_OVERSHOOT_20_LIMIT_DEG = 25.0


class Criterion(TypedDict):
    """One criterion: the measured ``value`` against its ``limit`` (both in ``unit``);
    ``value`` is None when the manoeuvre never reached the point it is measured at."""

    criterion: str
    value: float | None
    limit: float
    unit: str
    passed: bool


def _overshoot_limit(
    l_over_v: float, short: float, long: float, offset: float, slope: float
) -> float:
    """An overshoot limit [deg] for L/V [s]: ``short`` below L/V = 10 s, ``long`` from 30 s,
    ``offset`` + ``slope``·L/V between."""
    if l_over_v < 10.0:
        return short
    if l_over_v >= 30.0:
        return long
    return offset + slope * l_over_v


def first_overshoot_limit(l_over_v: float) -> float:
    """5.3.3.1: limit of the 10°/10° zig-zag's first overshoot [deg] for L/V [s]."""
    return _overshoot_limit(l_over_v, 10.0, 20.0, 5.0, 0.5)


def second_overshoot_limit(l_over_v: float) -> float:
    """5.3.3.2: limit of the 10°/10° zig-zag's second overshoot [deg] for L/V [s]."""
    return _overshoot_limit(l_over_v, 25.0, 40.0, 17.5, 0.75)


def _criterion(name: str, value: float | None, limit: float, unit: str) -> Criterion:
    passed = value is not None and value <= limit
    return {"criterion": name, "value": value, "limit": limit, "unit": unit, "passed": passed}


def imo_criteria(
    kind: str,
    figures: dict[str, float],
    length: float,
    speed: float,
    rudder_deg: float,
    switch_deg: float | None = None,
    max_rudder_deg: float = TURNING_RUDDER_DEG,
) -> list[Criterion]:
    """The MSC.137(76) criteria that a manoeuvre's ``figures`` measure (empty when it is not
    one of the standard manoeuvres).

    ``kind`` is ``"turning"`` or ``"zigzag"``; ``figures`` as :func:`~shipgym.manoeuvres.
    turning_circle` (advance, tactical_diameter [m]) or :func:`~shipgym.manoeuvres.zigzag`
    (overshoot_1, overshoot_2 [deg]) return them; ``length`` L [m], ``speed`` V [m/s];
    ``rudder_deg`` / ``switch_deg`` [deg] the manoeuvre's angles (the switch defaults to the
    rudder); ``max_rudder_deg`` the ship's rudder limit [deg].  A turning circle is standard at
    min(35°, rudder limit) (4.2.2), a zig-zag at 10°/10° or 20°/20° (4.2.6, 4.2.7).
    Distances are given in ship lengths (unit ``"L"``), overshoots in degrees.
    """
    if not length > 0 or not speed > 0:
        raise ValueError(f"length {length} m and speed {speed} m/s must be > 0")
    rudder = abs(rudder_deg)
    switch = abs(switch_deg) if switch_deg is not None else rudder
    if kind == "turning":
        if abs(rudder - min(TURNING_RUDDER_DEG, max_rudder_deg)) > 1e-9:
            return []
        advance, diameter = figures.get("advance"), figures.get("tactical_diameter")
        return [
            _criterion(
                "advance", None if advance is None else advance / length, ADVANCE_LIMIT_L, "L"
            ),
            _criterion(
                "tactical_diameter",
                None if diameter is None else diameter / length,
                TACTICAL_DIAMETER_LIMIT_L,
                "L",
            ),
        ]
    if kind != "zigzag":
        raise ValueError(f"unknown manoeuvre {kind!r}; valid: turning, zigzag")
    first, second = figures.get("overshoot_1"), figures.get("overshoot_2")
    if rudder == switch == 10.0:
        l_over_v = length / speed
        return [
            _criterion("first_overshoot_10_10", first, first_overshoot_limit(l_over_v), "deg"),
            _criterion("second_overshoot_10_10", second, second_overshoot_limit(l_over_v), "deg"),
        ]
    if rudder == switch == 20.0:
        return [_criterion("first_overshoot_20_20", first, FIRST_OVERSHOOT_20_LIMIT_DEG, "deg")]
    return []
