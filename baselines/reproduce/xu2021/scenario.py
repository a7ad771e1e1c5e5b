"""Xu et al. (2021) §5: the scenario, Esso Osaka in a two-phase stochastic current."""

from __future__ import annotations

from typing import Any

from shipgym.scenarios.loader import load_scenario

SCENARIO = "osaka_stochastic_current"


def build_scenario(time_limit: float | None = None) -> Any:
    """``osaka_stochastic_current``, its 2000 s episode shortened to ``time_limit`` [s] if
    given (the current's switch moves to half of it)."""
    scenario = load_scenario(SCENARIO)
    if time_limit is None:
        return scenario
    return scenario.with_overrides({"time_limit": float(time_limit)})


def switch_time(scenario: Any) -> float:
    """Start of the strong-current phase [s] (the scenario's, default half the time limit)."""
    current = scenario.config.disturbances.current
    t = getattr(current, "switch_time", None)
    return 0.5 * scenario.config.time_limit if t is None else float(t)
