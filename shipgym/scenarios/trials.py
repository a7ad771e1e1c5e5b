"""What an evaluation seed varies: the trial randomisation of a scenario (docs/leaderboard.md).

A catalogue scenario is one deterministic task; the leaderboard's evaluation seeds make it
a distribution of trials.  :class:`TrialRandomization` (a suite's ``randomize:`` block)
states the ranges, :func:`trial_scenario` draws one trial from a seed:

* ``cross_track_offset_L``: the start moved perpendicular to the first leg by U(lo, hi)·L
  (positive to the left of the path), on top of the scenario's own start;
* ``heading_error_deg``: U(lo, hi) added to the initial heading;
* ``jump_time_jitter_s``: every parameter event (jump, ramp) and a two-phase current's
  switch shifted by the same U(lo, hi) seconds (clipped to [0, time limit − Ts]), so the
  jump time is not known in advance;
* ``current_speed_factor`` / ``current_direction_deg``: the scenario's current (if it has
  one) scaled by U(lo, hi) and turned by U(lo, hi) degrees (its second phase too);
* the sensor-noise realisation (and that of any stochastic current or wave) varies with
  the env seed itself, as always.

A trial is two pure steps: :func:`draw_trial` draws the values from a
``numpy.random.Generator``, :func:`apply_trial` applies them to a scenario.  Every range is
drawn on every trial, in this order, so adding one range does not change the others' draws.
An evaluation seed's generator is its own stream
``numpy.random.default_rng([TRIAL_STREAM, seed])`` (independent of the env's generator), so
a leaderboard trial is reproducible from its seed (:func:`trial_scenario`).  The registered
env ids draw from the env's own ``np_random`` at ``reset(seed=…)`` instead
(:data:`ENV_RANDOMIZE_SUITE`'s ranges).  Controllers see a trial as they see any scenario:
the start through their observations, never the event schedule.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable, Mapping
from typing import Annotated, Any

import numpy as np
from pydantic import AfterValidator, ValidationInfo, field_validator

from shipgym.config import StrictModel, read_yaml, resolve
from shipgym.limits import RANDOMIZE_BOUNDS

#: the trial draws' stream, apart from the env's own seeding
TRIAL_STREAM = 0x7121A1


def _ordered(r: tuple[float, float]) -> tuple[float, float]:
    if not (math.isfinite(r[0]) and math.isfinite(r[1]) and r[0] <= r[1]):
        raise ValueError(f"a range is [low, high] with finite low ≤ high, got {list(r)}")
    return r


Range = Annotated[tuple[float, float], AfterValidator(_ordered)]


class TrialRandomization(StrictModel):
    """Uniform ranges of what each evaluation seed draws (module doc); None: fixed.  Each
    lies within its documented bounds (:data:`shipgym.limits.RANDOMIZE_BOUNDS`)."""

    cross_track_offset_L: Range | None = None
    heading_error_deg: Range | None = None
    jump_time_jitter_s: Range | None = None
    current_speed_factor: Range | None = None
    current_direction_deg: Range | None = None

    @field_validator(*RANDOMIZE_BOUNDS)
    @classmethod
    def _within_limits(
        cls, r: tuple[float, float] | None, info: ValidationInfo
    ) -> tuple[float, float] | None:
        low, high = RANDOMIZE_BOUNDS[str(info.field_name)]
        if r is not None and not (low <= r[0] and r[1] <= high):
            raise ValueError(f"{list(r)} is beyond the limit [{low:g}, {high:g}]")
        return r


#: the suite whose ``randomize:`` ranges the registered env ids draw at ``reset(seed=…)``:
#: the leaderboard's trials, so that an agent trains on the distribution it is ranked on
ENV_RANDOMIZE_SUITE = "default"


@functools.cache
def env_randomization() -> TrialRandomization:
    """The ranges the registered env ids draw (:data:`ENV_RANDOMIZE_SUITE`'s ``randomize:``)."""
    data = read_yaml(resolve("suites", ENV_RANDOMIZE_SUITE))
    return TrialRandomization(**data["randomize"])


_ORDER = (
    "cross_track_offset_L",
    "heading_error_deg",
    "jump_time_jitter_s",
    "current_speed_factor",
    "current_direction_deg",
)


def draw_trial(randomization: TrialRandomization, rng: np.random.Generator) -> dict[str, float]:
    """The values ``rng`` draws for the ranges that are set (module doc): one uniform per
    range, set or not, in the module's order."""
    u = rng.random(len(_ORDER))
    out = {}
    for name, x in zip(_ORDER, u.tolist(), strict=True):
        r = getattr(randomization, name)
        if r is not None:
            out[name] = r[0] + (r[1] - r[0]) * x
    return out


def trial_draws(randomization: TrialRandomization, seed: int) -> dict[str, float]:
    """The values evaluation seed ``seed`` draws (its own stream, module doc)."""
    return draw_trial(randomization, np.random.default_rng([TRIAL_STREAM, int(seed)]))


def seed_trials(
    scenario: Any, randomize: Mapping[str, Any] | None, seeds: Iterable[int]
) -> list[Any]:
    """:func:`trial_scenario` of each seed, the ranges given as a dict (a
    :class:`TrialRandomization`'s fields, as a suite or ``run.json`` holds them; None: the
    scenario itself for every seed)."""
    randomization = None if randomize is None else TrialRandomization(**randomize)
    return [trial_scenario(scenario, randomization, int(seed)) for seed in seeds]


def trial_scenario(scenario: Any, randomization: TrialRandomization | None, seed: int) -> Any:
    """The trial of ``scenario`` (a :class:`shipgym.scenarios.loader.Scenario`) that ``seed``
    draws; the scenario itself without randomisation.  The name is kept (a leaderboard row
    is a scenario over its trials)."""
    if randomization is None:
        return scenario
    return apply_trial(scenario, trial_draws(randomization, seed))


def apply_trial(scenario: Any, draws: Mapping[str, float]) -> Any:
    """``scenario`` with the drawn values of :func:`draw_trial` applied (module doc); the
    scenario itself when nothing was drawn.  The name is kept."""
    if not draws:
        return scenario
    cfg = scenario.config
    overrides: dict[str, Any] = {}
    start = cfg.initial_state
    x, y, heading = start.x, start.y, start.heading_deg
    if "cross_track_offset_L" in draws:
        (x0, y0), (x1, y1) = cfg.path.waypoints[0], cfg.path.waypoints[1]
        length = math.hypot(x1 - x0, y1 - y0)
        shift = draws["cross_track_offset_L"] * scenario.ship_length
        x += -(y1 - y0) / length * shift  # the left normal of the first leg
        y += (x1 - x0) / length * shift
    heading += draws.get("heading_error_deg", 0.0)
    overrides["initial_state"] = {"x": x, "y": y, "heading_deg": heading}
    latest = cfg.time_limit - scenario.control_period
    jitter = draws.get("jump_time_jitter_s")
    if jitter is not None and cfg.events:
        events = [e.model_dump() for e in cfg.events]
        for e in events:
            e["time"] = min(max(e["time"] + jitter, 0.0), latest)
        overrides["events"] = events
    current = cfg.disturbances.current
    changed: dict[str, Any] = {}
    two_phase = getattr(current, "second_speed", None) is not None
    if current.speed > 0 or (two_phase and current.second_speed > 0):
        factor = draws.get("current_speed_factor", 1.0)
        changed["speed"] = current.speed * factor
        changed["direction_deg"] = current.direction_deg + draws.get("current_direction_deg", 0.0)
        if two_phase:
            changed["second_speed"] = current.second_speed * factor
    if two_phase and jitter is not None:
        switch = 0.5 * cfg.time_limit if current.switch_time is None else current.switch_time
        changed["switch_time"] = min(max(switch + jitter, 0.0), latest)
    if changed:
        overrides["disturbances"] = {"current": changed}
    return scenario.with_overrides(overrides, name=scenario.name)
