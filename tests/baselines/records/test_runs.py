"""The run folder's names (:mod:`shipgym_baselines.records.runs`): each lives in the module
named for what it holds and is still importable from ``records.runs``; the records import
nothing above them."""

from __future__ import annotations

import importlib

import pytest

from shipgym_baselines import executor
from shipgym_baselines.records import runs
from tests.import_graph import import_graph

#: every public name ``records.runs`` defined before it was split, by its module now
HOMES = {
    "episodes": "BOOL_METRICS EPISODES_FILE EPISODE_KEYS Key TEXT_METRICS episode_key "
    "episode_record read_episodes",
    "folders": "check_out_dir check_out_usable clear_outputs",
    "jsonfiles": "as_json differences from_plain plain write_json",
    "runlog": "FSYNC_INTERVAL_S NO_ROOM RunInterrupted RunLog cpu_seconds outside_problem",
    "runrecord": "PACKAGES RUN_FILE git_commit now read_run versions",
    "trajectories": "TRAJECTORY_DIR episode_result light_trajectory read_trajectory "
    "trajectory_file",
}
#: (home module, name) of every former name
FORMER = [(module, name) for module, names in HOMES.items() for name in names.split()]
#: what the records may import: shipgym and the ground floor of ``baselines``
BELOW = (
    "shipgym",
    "shipgym_baselines.errors",
    "shipgym_baselines.executor",
    "shipgym_baselines.extras",
    "shipgym_baselines.jsonout",
    "shipgym_baselines.records",
    "shipgym_baselines.signals",
)


@pytest.mark.parametrize(("module", "name"), FORMER)
def test_a_former_name_imports_from_runs_as_its_home_holds_it(module: str, name: str) -> None:
    home = importlib.import_module(f"shipgym_baselines.records.{module}")
    assert getattr(runs, name) is getattr(home, name)
    assert name in runs.__all__


def test_runs_holds_the_backends_and_no_other_name_of_its_own() -> None:
    assert runs.BACKENDS is executor.BACKENDS == ("local", "ray")
    assert set(runs.__all__) == {name for _, name in FORMER} | {"BACKENDS"}


def test_the_records_import_nothing_above_them() -> None:
    """Data flows down: no module of ``records`` imports the controllers, the evaluation
    loop or the leaderboard (an episode its controller ended is told there too)."""
    upward = [
        (module, target)
        for module, targets in sorted(import_graph().items())
        if module.startswith("shipgym_baselines.records")
        for target in sorted(targets)
        if not any(target == b or target.startswith(b + ".") for b in BELOW)
    ]
    assert not upward, upward
