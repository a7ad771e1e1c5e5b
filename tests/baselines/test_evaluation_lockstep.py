"""Lockstep evaluation through the evaluation trials env: a job's seeds, each its
own trial variant as the leaderboard draws it, run as the rows of one vectorized env and
give, bit for bit, what ``run_episode`` gives one seed at a time (compute times aside)."""

from __future__ import annotations

import numpy as np
import pytest

from shipgym.envs.eval_trials import lockstep_problem
from shipgym.scenarios.loader import load_scenario
from shipgym_baselines import evaluation
from shipgym_baselines.classical.pid import PIDLOS
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET, evaluate_batch, run_episode
from shipgym_baselines.leaderboard.jobs import Job, trials
from shipgym_baselines.registry import make_controller
from shipgym_baselines.suite import load_suite

from .test_evaluation import _assert_same_episodes, _one_by_one

SEEDS = [EVAL_SEED_OFFSET + i for i in range(3)]

# heldout:8: nomoto2 with a parameter jump, a current and noisy sensors; heldout:6: the
# 3-DOF Mariner with a parameter jump, a current shift and noisy sensors
SCENARIOS = ("heldout:8", "heldout:6")


def _randomize() -> dict:
    randomize = load_suite("default").randomize
    return randomize.model_dump() if hasattr(randomize, "model_dump") else randomize


def _suite_trials(controller: str, scenario: str) -> list:
    """The default suite's trial of each seed (start offset, heading, jump-time jitter,
    current factor), as the leaderboard resolves them."""
    return trials(Job(controller, scenario, tuple(SEEDS), None, _randomize()))


@pytest.mark.parametrize(
    "name",
    [
        "pid_los",  # a classical controller, rudder mode
        "adaptive_lqr",  # identifies online from info["samples"]
        "nmpc_lambda_lssvm",  # identifies online (λ-LS-SVM) from info["samples"]
        "ppo",  # a learned BatchPolicy, rudder mode
        "ppo_guidance",  # a learned BatchPolicy, guidance mode
    ],
)
@pytest.mark.parametrize("scenario", SCENARIOS)
def test_lockstep_episodes_equal_run_episode(name: str, scenario: str) -> None:
    if name.startswith("ppo"):
        pytest.importorskip("stable_baselines3")
    per_seed = _suite_trials(name, scenario)
    assert len({t.config.model_dump_json() for t in per_seed}) == len(SEEDS)  # trials differ
    assert lockstep_problem(per_seed) is None  # so they run as one env's rows
    batched = evaluate_batch(name, per_seed, SEEDS)
    _assert_same_episodes(batched, _one_by_one(name, per_seed, SEEDS))


# a PCHIP route with a parameter jump (the rows' path tracking and, for a batch policy, the
# lean rows: no per-step info, the trajectory from the env's columns)
CURVED = "mariner_maneuverability_change_curved"


@pytest.mark.parametrize("name", ["pid_los", "ppo", "ppo_guidance"])
def test_lockstep_episodes_on_a_curved_route_equal_run_episode(name: str) -> None:
    if name.startswith("ppo"):
        pytest.importorskip("stable_baselines3")
    per_seed = _suite_trials(name, CURVED)
    _assert_same_episodes(evaluate_batch(name, per_seed, SEEDS), _one_by_one(name, per_seed, SEEDS))


@pytest.mark.parametrize("scenario", [CURVED, "heldout:6"])
def test_lean_rows_give_the_full_info_results(scenario: str) -> None:
    """A batch policy's lean rows (row_infos="end", trajectories from the env's columns)
    give the EpisodeResults of full-info rows: metrics, ends and trajectories bit for bit."""
    pytest.importorskip("stable_baselines3")
    per_seed = _suite_trials("ppo", scenario)
    results = {}
    for lean in (True, False):
        policy, mode = make_controller("ppo")
        episodes = evaluation._VectorEpisodes(per_seed, SEEDS, mode or "rudder", lean=lean)
        assert episodes.env.row_infos == ("end" if lean else "all")
        results[lean] = evaluation._run_lockstep(policy, episodes)
    _assert_same_episodes(results[True], results[False])
    for a, b in zip(results[True], results[False], strict=True):
        assert a.metrics["termination_reason"] == b.metrics["termination_reason"]
        for key, values in a.trajectory.items():
            assert values.dtype == b.trajectory[key].dtype == np.float64
            assert np.array_equal(values, b.trajectory[key]), key


def test_each_classical_episode_is_timed_on_its_own() -> None:
    """Per-row controllers: each ``act`` call is timed alone (compute_ms of its episode)."""
    ticks = iter(range(10**6))
    nominal = load_scenario("nominal")
    short = nominal.with_overrides({"time_limit": 20.0})
    with evaluation.act_clock(lambda: float(next(ticks))):
        long_run, short_run = evaluate_batch("zero_rudder", [nominal, short], [0, 0])
    assert len(short_run.trajectory["t"]) < len(long_run.trajectory["t"])
    for result in (long_run, short_run):
        assert (result.metrics["compute_ms"], result.metrics["compute_ms_max"]) == (1e3, 1e3)


def test_what_falls_back_to_one_env_per_episode() -> None:
    """Trials of different ships run one env each (still equal to ``run_episode``); a
    Policy instance and the privileged oracle run one by one."""
    mixed = [load_scenario("rudder_aging"), load_scenario("mariner_rudder_aging")]
    assert "ship model" in lockstep_problem(mixed)
    seeds = SEEDS[:2]
    _assert_same_episodes(
        evaluate_batch("pid_los", mixed, seeds), _one_by_one("pid_los", mixed, seeds)
    )
    expected = []
    for scenario, seed in zip(mixed, seeds, strict=True):
        expected.append(run_episode(PIDLOS(), scenario, seed))
    _assert_same_episodes(evaluate_batch(PIDLOS(), mixed, seeds), expected)


def test_one_plant_call_per_step_for_all_seeds(monkeypatch) -> None:
    """Ten seeds of a classical controller: the plant is integrated once per control step
    for all rows (as many calls as the longest episode's steps, not the sum of them)."""
    from shipgym.models.integrator import PeriodIntegrator

    calls = []
    real = PeriodIntegrator.substep_states

    def counted(self, x0, u, w, p):
        calls.append(len(x0))
        return real(self, x0, u, w, p)

    monkeypatch.setattr(PeriodIntegrator, "substep_states", counted)
    seeds = [EVAL_SEED_OFFSET + i for i in range(10)]
    per_seed = trials(Job("zero_rudder", "rudder_aging", tuple(seeds), None, _randomize()))
    results = evaluate_batch("zero_rudder", per_seed, seeds)
    steps = [r.metrics["steps"] for r in results]
    assert len(set(steps)) > 1  # the trials end apart
    assert calls == [len(seeds)] * max(steps)
