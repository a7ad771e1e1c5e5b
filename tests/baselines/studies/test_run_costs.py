"""Where a leaderboard run's CPU time goes (shipgym_baselines.studies.run_costs)."""

from __future__ import annotations

import pytest

from shipgym_baselines.evaluation import EVAL_SEED_OFFSET
from shipgym_baselines.leaderboard.costs import limit_steps
from shipgym_baselines.leaderboard.jobs import Job, suite_scenario, work
from shipgym_baselines.studies.run_costs import profile_suite
from shipgym_baselines.suite import load_suite


@pytest.fixture(scope="module")
def profile() -> dict:
    return profile_suite(
        "smoke",
        seeds=1,
        controllers=["pid_los", "zero_rudder", "oracle"],
        scenarios=["rudder_aging"],
    )


def test_profile_counts_the_episodes_and_steps_the_leaderboard_runs(profile: dict) -> None:
    spec = load_suite("smoke")
    randomize = spec.randomize.model_dump(mode="json")
    for name in ("pid_los", "zero_rudder", "oracle"):
        (result,) = work(Job(name, "rudder_aging", (EVAL_SEED_OFFSET,), None, randomize))
        entry = profile["per_controller"][name]
        assert entry["episodes"] == 1
        assert entry["steps"] == result.metrics["steps"]  # the same trial, the same episode
    assert profile["jobs"] == 3 and profile["scenarios"] == 1 and profile["suite_seeds"] == 2


def test_profile_splits_add_up(profile: dict) -> None:
    controllers = profile["per_controller"].values()
    assert sum(e["cpu_s"] for e in controllers) == pytest.approx(profile["cpu_s"])
    assert list(profile["per_ship"]) == ["nomoto2"]
    assert profile["per_ship"]["nomoto2"]["cpu_s"] == pytest.approx(profile["cpu_s"])
    for name, entry in profile["per_controller"].items():
        assert 0 <= entry["act_cpu_s"] <= entry["cpu_s"]
        # the whole suite runs each cell's trials with its 2 seeds: twice the CPU measured
        assert entry["suite_cpu_s"] == pytest.approx(2 * entry["cpu_s"])
        assert entry["us_per_step"] == pytest.approx(1e6 * entry["cpu_s"] / entry["steps"])
        assert profile["per_controller_ship"][name]["nomoto2"]["steps"] == entry["steps"]
    assert profile["per_controller"]["oracle"]["act_cpu_s"] == 0.0  # read from its table
    cpu = list(profile["per_controller"].values())
    assert [e["cpu_s"] for e in cpu] == sorted((e["cpu_s"] for e in cpu), reverse=True)
    limit = limit_steps(suite_scenario("rudder_aging"))
    for entry in profile["per_controller"].values():  # the time limit bounds the steps
        assert entry["steps"] <= entry["limit_steps"] == limit
