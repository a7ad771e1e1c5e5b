"""The no-change twin of a scenario: the same trial with its change removed.

A scenario *changes* when it has a parameter event (a jump or a ramp) or a two-phase
current, whose switch is a change of the current.  Its **twin** keeps everything else —
ship, route, start, time limit, guidance, sensors, waves, the reward — and drops the
change:

* every parameter event is removed, so the ship keeps its nominal parameters;
* a two-phase current becomes its first phase for the whole episode: a Gauss–Markov
  current about the first phase's mean with the same fluctuation, or no current at all
  when that phase is calm and steady (speed 0, no fluctuation);
* its change family is :data:`~shipgym.scenarios.families.NOMINAL`.

The twin of a trial is the twin of the scenario, drawn with the same seed: the trial
randomisation (:mod:`shipgym.scenarios.trials`) draws every range on every trial from the
seed alone, so ``trial_scenario(twin(s), r, seed) == twin(trial_scenario(s, r, seed))``.
The leaderboard compares a controller's cost on a trial with its cost on the trial's twin:
how much the change cost it (docs/leaderboard.md, "Steering and adapting, apart").
"""

from __future__ import annotations

from typing import Any

from shipgym.scenarios.families import NOMINAL
from shipgym.scenarios.loader import Scenario

#: the settings that label a scenario without changing what happens in it
LABELS = ("name", "description", "source")


def has_change(scenario: Scenario) -> bool:
    """Whether ``scenario`` has a parameter event or a two-phase current (module doc)."""
    current = scenario.config.disturbances.current
    return bool(scenario.config.events) or getattr(current, "kind", None) == "two_phase"


def nominal_twin(scenario: Scenario, name: str | None = None) -> Scenario | None:
    """The no-change twin of ``scenario`` (module doc), named ``name`` (default: the
    scenario's own name); None when the scenario has no change."""
    if not has_change(scenario):
        return None
    config = scenario.config
    current = config.disturbances.current
    drop = ["events"]
    overrides: dict[str, Any] = {"family": NOMINAL}
    if getattr(current, "kind", None) == "two_phase":
        drop.append("disturbances.current")
        if current.speed > 0.0 or current.sigma > 0.0 or current.direction_sigma_deg > 0.0:
            first = current.model_dump(exclude={"kind", "second_speed", "switch_time"})
            first.pop("transition_time")
            overrides["disturbances"] = {"current": {"kind": "gauss_markov", **first}}
    return scenario.with_overrides(overrides, name=name or scenario.name, drop=drop)


def same_trial(a: Scenario, b: Scenario) -> bool:
    """Whether two scenarios are the same task: equal settings but for their labels
    (:data:`LABELS`), so every seed gives both the same episode."""
    return settings_without_labels(a) == settings_without_labels(b)


def settings_without_labels(scenario: Scenario) -> dict[str, Any]:
    """The scenario's settings as JSON values, without :data:`LABELS`."""
    config = scenario.config.model_dump(mode="json")
    return {k: v for k, v in config.items() if k not in LABELS}
