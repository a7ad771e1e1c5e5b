"""Documented limits (docs/records.md, "Limits"): a scenario beyond one is refused early, in one
line naming the key and the limit (the audit's probes: 7 GB, hangs, ``std::bad_alloc``)."""

from __future__ import annotations

import re
import time
from pathlib import Path

import gymnasium as gym
import pytest
import yaml

import shipgym  # noqa: F401  (registers the envs)
from shipgym.config import ConfigError, read_yaml
from shipgym.limits import (
    MAX_CONFIG_BYTES,
    MAX_CONFIG_DEPTH,
    MAX_CONFIG_NODES,
    MAX_EPISODE_STEPS,
    MAX_NAME_BYTES,
    MAX_NAME_CHARS,
    MAX_SUBSTEPS,
    MAX_WAYPOINTS,
    LimitError,
    worker_count,
)
from shipgym.scenarios.loader import (
    ScenarioError,
    catalogue_dir,
    check_scenario_file,
    load_scenario,
)
from shipgym.scenarios.trials import TrialRandomization


def _nominal(tmp_path: Path, **changes: object) -> Path:
    data = yaml.safe_load(catalogue_dir().joinpath("nominal.yaml").read_text())
    for dotted, value in changes.items():
        *parents, last = dotted.split("__")
        node = data
        for part in parents:
            node = node.setdefault(part, {})
        node[last] = value
    file = tmp_path / "probe.yaml"
    file.write_text(yaml.safe_dump(data))
    return file


@pytest.mark.parametrize(
    ("change", "key", "limit"),
    [
        ({"time_limit": 1e12}, "time_limit", MAX_EPISODE_STEPS),
        ({"fine_step": 1e-7}, "fine_step", MAX_SUBSTEPS),
        ({"control_period": 1e6}, "control_period", MAX_SUBSTEPS),
        ({"initial_state__x": 1e300}, "initial_state.x", "±1e+06 m"),
        ({"path__waypoints": [[0, 0], [1e300, 0]]}, "path.waypoints", "±1e+06 m"),
    ],
)
def test_finding8_a_scenario_beyond_a_limit_is_refused_naming_key_and_limit(
    tmp_path: Path, change: dict, key: str, limit: object
) -> None:
    file = _nominal(tmp_path, **change)
    start = time.perf_counter()
    (problem,) = check_scenario_file(file)
    assert problem.key == key and f"beyond the limit of {limit}" in problem.message
    with pytest.raises(ScenarioError, match=f"key '{key}'"):
        gym.make("ShipPathFollow-v0", scenario=str(file), compile=False)
    assert time.perf_counter() - start < 10  # refused early: no 7 GB log, no hang


def test_finding8_waypoints_beyond_the_limit_are_refused(tmp_path: Path) -> None:
    points = [[float(i), 0.0] for i in range(MAX_WAYPOINTS + 1)]
    (problem,) = check_scenario_file(_nominal(tmp_path, path__waypoints=points))
    assert problem.key == "path.waypoints"
    assert f"{MAX_WAYPOINTS + 1} waypoints, beyond the limit of {MAX_WAYPOINTS}" in problem.message


def test_finding8_a_million_waypoint_file_is_refused_before_parsing(tmp_path: Path) -> None:
    file = _nominal(tmp_path)
    lines = "\n".join(f"  - [{i}.5, 1.25]" for i in range(1_000_000))
    file.write_text(file.read_text().split("path:")[0] + "path:\n waypoints:\n" + lines + "\n")
    start = time.perf_counter()
    with pytest.raises(ScenarioError, match=f"larger than the limit of {MAX_CONFIG_BYTES} bytes"):
        load_scenario(str(file))
    (problem,) = check_scenario_file(file)
    assert f"limit of {MAX_CONFIG_BYTES} bytes" in problem.message
    assert time.perf_counter() - start < 5  # the audit's file parsed for over a minute


def test_finding8_absurd_randomize_ranges_are_refused() -> None:
    with pytest.raises(ValueError, match=r"heading_error_deg\n.*beyond the limit \[-180, 180\]"):
        TrialRandomization(heading_error_deg=(-1e9, 1e9))
    with pytest.raises(ValueError, match=r"current_speed_factor\n.*beyond the limit \[0, 10\]"):
        TrialRandomization(current_speed_factor=(-5.0, 1.0))
    TrialRandomization(cross_track_offset_L=(-1.0, 1.0), heading_error_deg=(-10.0, 10.0))


def test_finding8_workers_are_clamped_to_the_jobs_and_at_least_one() -> None:
    assert worker_count(100, jobs=12) == 12
    assert worker_count(2, jobs=12) == 2
    assert worker_count(3, jobs=0) == 1
    for bad in (-5, 0, 2.5, True):
        with pytest.raises(LimitError, match=r"--workers must be a whole number ≥ 1"):
            worker_count(bad, jobs=12)


@pytest.mark.parametrize(
    ("name", "problem"),
    [
        ("s" * 240, f"the name has 240 characters, beyond the limit of {MAX_NAME_CHARS}"),
        ("船" * 70, f"the name takes 210 bytes in UTF-8, beyond the limit of {MAX_NAME_BYTES}"),
        ("two\nlines", "the name holds the character U+000A"),
        ("  ", "the name is empty"),
    ],
)
def test_a_scenario_name_no_file_name_can_carry_is_refused(
    tmp_path: Path, name: str, problem: str
) -> None:
    """A figure's file is named after its scenario: a name too long for a file name (255
    bytes with the figure's prefix and a temporary's suffix) or with a control character
    is refused when the file is read and by the validator, naming the key."""
    file = _nominal(tmp_path, name=name)
    (found,) = check_scenario_file(file)
    assert found.key == "name" and problem in found.message
    with pytest.raises(ScenarioError, match=f"key 'name': .*{re.escape(problem)}"):
        load_scenario(str(file))
    assert load_scenario(str(_nominal(tmp_path, name="a" * MAX_NAME_CHARS))).name == "a" * 100


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ("bad: " + "[" * 5000 + "]" * 5000, f"nested deeper than the limit of {MAX_CONFIG_DEPTH}"),
        (
            'a: &a ["x", "x", "x", "x", "x", "x", "x", "x", "x"]\n'
            + "".join(
                f"{b}: &{b} [{', '.join([f'*{a}'] * 9)}]\n"
                for a, b in zip("abcdefgh", "bcdefghi", strict=True)
            ),
            f"more than the limit of {MAX_CONFIG_NODES} values (aliases expanded)",
        ),
    ],
)
def test_a_deep_or_exploding_yaml_is_refused_in_one_line(
    tmp_path: Path, text: str, problem: str
) -> None:
    """5,000 nested lists (PyYAML composes them recursively: a RecursionError of 3,000
    lines) and nested aliases (a few lines that expand to 10⁹ values) are refused while
    parsing, in one line naming the file, the line and the limit."""
    file = tmp_path / "deep.yaml"
    file.write_text("name: deep\n" + text + "\n")
    start = time.perf_counter()
    with pytest.raises(ConfigError) as refused:
        read_yaml(file)
    message = str(refused.value)
    assert "\n" not in message and message.startswith(f"{file}, line ") and problem in message
    (found,) = check_scenario_file(file)
    assert found.line is not None and problem in found.message
    assert time.perf_counter() - start < 5
