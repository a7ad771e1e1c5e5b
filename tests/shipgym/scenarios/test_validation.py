"""Scenario validation: every bad number is named (key, file, line) before any simulation —
events after the time limit, non-finite numbers, ship parameters no real plant has — and
:func:`check_scenario_file` lists all problems of a file at once."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
import yaml

from shipgym.models import MODELS
from shipgym.models.base import ParameterError
from shipgym.models.nomoto2 import Nomoto2Params
from shipgym.scenarios.loader import (
    Problem,
    ScenarioError,
    check_scenario_file,
    list_scenarios,
    load_scenario,
    scenario_from_dict,
    yaml_line,
)


def config(**overrides: Any) -> dict[str, Any]:
    data: dict[str, Any] = {
        "name": "test",
        "ship": {"model": "nomoto2", "params": {"Tc": 0.1}},
        "path": {"waypoints": [[1, 1], [15, 1], [15, 10]]},
        "time_limit": 30.0,
    }
    data.update(overrides)
    return data


def write(tmp_path: Path, text: str, name: str = "scenario.yaml") -> Path:
    file = tmp_path / name
    file.write_text(text)
    return file


def error_of(data: dict[str, Any]) -> str:
    with pytest.raises(ScenarioError) as info:
        scenario_from_dict(data)
    return str(info.value)


# --------------------------------------------------------------------------------------------
# Events and the time limit
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("time", [30.0, 45.0])
def test_an_event_at_or_after_the_time_limit_is_named(time: float) -> None:
    events = [{"time": 5.0, "params": {"Tc": 0.5}}, {"time": time, "params": {"Tc": 1.0}}]
    msg = error_of(config(events=events))
    assert "key 'events.1.time'" in msg
    assert f"{time} s" in msg and "time_limit: 30.0 s" in msg
    assert "events.0" not in msg


def test_an_event_before_the_time_limit_loads() -> None:
    sc = scenario_from_dict(config(events=[{"time": 29.5, "params": {"Tc": 1.0}}]))
    assert sc.change_time == 29.5


def test_shortening_a_catalogue_scenario_below_its_event_is_refused() -> None:
    with pytest.raises(ScenarioError, match=r"events\.0\.time.*12\.0 s"):
        load_scenario("rudder_aging").with_overrides({"time_limit": 10.0})


def test_events_out_of_order_name_the_later_event() -> None:
    events = [{"time": 5.0, "params": {"Tc": 1.0}}, {"time": 1.0, "params": {"Tc": 0.5}}]
    assert "key 'events.1.time': events must be listed in time order" in error_of(
        config(events=events)
    )


# --------------------------------------------------------------------------------------------
# Non-finite numbers (YAML .inf / .nan) anywhere a scenario number is read
# --------------------------------------------------------------------------------------------

#: (YAML line that sets the key, the dotted key named in the error)
NON_FINITE = [
    ("time_limit: {v}", "time_limit"),
    ("initial_state: {{heading_deg: {v}}}", "initial_state.heading_deg"),
    ("initial_state: {{x: {v}}}", "initial_state.x"),
    ("disturbances: {{current: {{speed: 0.1, direction_deg: {v}}}}}", "direction_deg"),
    ("disturbances: {{current: {{speed: {v}}}}}", "disturbances.current"),
    ("events: [{{time: {v}, params: {{Tc: 1.0}}}}]", "events.0.time"),
    ("events: [{{time: 5.0, params: {{Tc: {v}}}}}]", "events.0.params.Tc"),
    ("reward: {{heading_weight: {v}}}", "reward.heading_weight"),
    ("guidance: {{los_radius_L: {v}}}", "guidance.los_radius_L"),
    ("sensors: {{heading_noise_deg: {v}}}", "sensors.heading_noise_deg"),
    ("control_period: {v}", "control_period"),
]


@pytest.mark.parametrize("value", [".inf", "-.inf", ".nan"])
@pytest.mark.parametrize(("line", "key"), NON_FINITE, ids=[k for _, k in NON_FINITE])
def test_non_finite_numbers_are_named(tmp_path: Path, line: str, key: str, value: str) -> None:
    data = config()
    if line.split(":")[0] == "time_limit":
        data.pop("time_limit")
    text = yaml.safe_dump(data, sort_keys=False) + line.format(v=value) + "\n"
    file = write(tmp_path, text)
    with pytest.raises(ScenarioError) as info:
        load_scenario(file)
    msg = str(info.value)
    assert str(file) in msg and key in msg
    assert "finite" in msg


def test_a_non_finite_waypoint_is_named(tmp_path: Path) -> None:
    data = config()
    data["path"]["waypoints"][1] = [math.inf, 1.0]
    assert "key 'path.waypoints.1.0': Input should be a finite number" in error_of(data)


# --------------------------------------------------------------------------------------------
# Ship parameters a real plant cannot have
# --------------------------------------------------------------------------------------------

#: (model, parameter, a non-physical value) for every ship
NON_PHYSICAL = [
    ("nomoto2", "K", 0.0),
    ("nomoto2", "K", -0.5),
    ("nomoto2", "Kc", 0.0),
    ("nomoto2", "T1", 0.0),
    ("nomoto2", "Tc", -0.1),
    ("nomoto2", "L", 0.0),
    ("mariner", "a3", 0.0),
    ("mariner", "T_delta", 0.0),
    ("mariner", "L", -1.0),
    ("mariner", "S", -0.1),
    ("blanke", "Iz", 0.0),
    ("blanke", "U0", 0.0),
    ("blanke", "X_uau", 10.0),
    ("blanke", "N_rdot", 1e9),  # Iz − N_rdot < 0: no sway–yaw mass matrix
    ("esso_osaka", "L", 0.0),
    ("esso_osaka", "T_servo", 0.0),
    ("esso_osaka", "m", 0.0),
    ("esso_osaka", "wake", 1.0),
    ("esso_osaka", "C_R", -0.001),
]


@pytest.mark.parametrize(("model", "name", "value"), NON_PHYSICAL)
def test_non_physical_ship_parameters_are_named(model: str, name: str, value: float) -> None:
    data = config(ship={"model": model, "params": {name: value}})
    msg = error_of(data)
    assert "key 'ship.params'" in msg
    assert name in msg


@pytest.mark.parametrize("name", ["K", "Kc"])
def test_an_event_that_makes_the_plant_non_physical_is_named(name: str) -> None:
    msg = error_of(config(events=[{"time": 5.0, "params": {name: 0.0}}]))
    assert "key 'events.0.params'" in msg and f"Nomoto2Params.{name} must be > 0" in msg
    assert "after the event at 5.0 s" in msg


def test_an_estimate_may_have_a_negative_gain_a_plant_may_not() -> None:
    """The weighted LS-SVM keeps K < 0 estimates (Liu et al. 2019 Fig. 7): only a plant
    built from a config is held to K > 0."""
    estimate = Nomoto2Params(K=-0.1)
    assert estimate.K == -0.1
    with pytest.raises(ParameterError, match=r"Nomoto2Params\.K must be > 0"):
        estimate.check_plant()
    with pytest.raises(ParameterError, match=r"Nomoto2Params\.K must be > 0"):
        MODELS["nomoto2"].from_config({"K": -0.1})


def test_every_bad_parameter_is_named_at_once() -> None:
    with pytest.raises(ParameterError) as info:
        Nomoto2Params().plant(K=-1.0, T1=0.0, Tc=-0.2)
    assert len(info.value.problems) == 3
    for name in ("K", "T1", "Tc"):
        assert f"Nomoto2Params.{name} must be > 0" in str(info.value)
    msg = error_of(config(ship={"model": "nomoto2", "params": {"K": -1.0, "T1": 0.0}}))
    assert msg.count("key 'ship.params'") == 2


def test_the_catalogue_ships_are_real_plants() -> None:
    for model in MODELS.values():
        model.params_type().check_plant()
    for name in list_scenarios():
        assert check_scenario_file(name) == [], name


# --------------------------------------------------------------------------------------------
# check_scenario_file: every problem, with key and line
# --------------------------------------------------------------------------------------------

BAD_FILE = """\
name: bad
ship:
  model: nomoto2
  params: {K: -0.5}
initial_state:
  heading_deg: .nan
path:
  waypoints: [[0, 0], [50, 0]]
  colour: red
disturbances:
  current: {kind: gauss_markov, speed: 0.1, direction_deg: .inf}
time_limit: .inf
"""


def test_check_lists_every_problem_with_key_and_line(tmp_path: Path) -> None:
    problems = check_scenario_file(write(tmp_path, BAD_FILE))
    found = {(p.key, p.line) for p in problems}
    assert found == {
        ("ship.params", 4),
        ("initial_state.heading_deg", 6),
        ("path.colour", 9),
        ("disturbances.current.gauss_markov.direction_deg", 11),
        ("time_limit", 12),
    }
    by_key = {p.key: p for p in problems}
    assert "K must be > 0" in by_key["ship.params"].message
    assert "Extra inputs" in by_key["path.colour"].message


def test_check_reports_build_problems_once_the_schema_passes(tmp_path: Path) -> None:
    data = config(events=[{"time": 5.0, "params": {"Tc": -1.0}}])
    data["initial_state"] = {"states": {"rdot": 0.1}}
    file = write(tmp_path, yaml.safe_dump(data, sort_keys=False))
    keys = {p.key for p in check_scenario_file(file)}
    assert keys == {"events.0.params", "initial_state.states"}


def test_check_names_the_line_of_malformed_yaml(tmp_path: Path) -> None:
    file = write(tmp_path, "name: x\npath: [1, 2\ntime_limit: 3\n")
    (problem,) = check_scenario_file(file)
    assert problem.key == "" and problem.line == 3
    assert "malformed YAML" in problem.message


def test_check_of_a_missing_file_says_so(tmp_path: Path) -> None:
    (problem,) = check_scenario_file(tmp_path / "nowhere.yaml")
    assert "not found" in problem.message and "nowhere.yaml" in problem.message


def test_yaml_line_finds_the_deepest_written_part() -> None:
    root = yaml.compose("a:\n  b:\n    - x: 1\n    - y: 2\nc: 3\n")
    assert yaml_line(root, "a.b.1.y") == 4
    assert yaml_line(root, "a.b.1.missing") == 4  # a missing key: its parent's line
    assert yaml_line(root, "c") == 5
    assert yaml_line(root, "") is None


def test_problem_text_with_and_without_the_file() -> None:
    problem = Problem("time_limit", "Input should be a finite number", 12)
    assert problem.text() == "line 12: key 'time_limit': Input should be a finite number"
    assert problem.text("s.yaml") == "s.yaml:12: key 'time_limit': Input should be a finite number"
    assert Problem("", "malformed YAML").text("s.yaml") == "s.yaml: malformed YAML"
