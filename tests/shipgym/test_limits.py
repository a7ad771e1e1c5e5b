"""Documented limits (issue 19, finding 8): a scenario beyond one is refused early, in one
line naming the key and the limit (the audit's probes: 7 GB, hangs, ``std::bad_alloc``)."""

from __future__ import annotations

import time
from pathlib import Path

import gymnasium as gym
import pytest
import yaml

import shipgym  # noqa: F401  (registers the envs)
from shipgym.limits import (
    MAX_CONFIG_BYTES,
    MAX_EPISODE_STEPS,
    MAX_SUBSTEPS,
    MAX_WAYPOINTS,
    LimitError,
    worker_count,
)
from shipgym.scenarios import ScenarioError, load_scenario
from shipgym.scenarios.loader import catalogue_dir, check_scenario_file
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
