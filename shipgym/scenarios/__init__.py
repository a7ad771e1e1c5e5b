"""Scenarios: ship + initial state + path + disturbances + sensors + event schedule."""

from shipgym.scenarios.events import ParameterEvent, ParameterSchedule
from shipgym.scenarios.loader import (
    Scenario,
    ScenarioError,
    build_scenario,
    catalogue_dir,
    list_scenarios,
    load_scenario,
    load_scenario_file,
    scenario_from_dict,
)
from shipgym.scenarios.schema import ScenarioConfig

__all__ = [
    "ParameterEvent",
    "ParameterSchedule",
    "Scenario",
    "ScenarioConfig",
    "ScenarioError",
    "build_scenario",
    "catalogue_dir",
    "list_scenarios",
    "load_scenario",
    "load_scenario_file",
    "scenario_from_dict",
]
