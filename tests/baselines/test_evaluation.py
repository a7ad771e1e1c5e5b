"""The evaluation loop: what a policy sees and what the loop measures (SPEC §8–9)."""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np
import pytest

from shipgym.scenarios import Scenario, load_scenario
from shipgym_baselines import evaluation
from shipgym_baselines.classical.pid import PIDLOS
from shipgym_baselines.classical.reference import ZeroRudder
from shipgym_baselines.errors import ControllerError
from shipgym_baselines.evaluation import (
    EVAL_SEED_OFFSET,
    EpisodeResult,
    compute_time_metrics,
    evaluate,
    evaluate_batch,
    run_episode,
)
from shipgym_baselines.registry import make_controller, training_seeds

SLEEP_S = 0.002


class SleepyZero(ZeroRudder):
    """Zero rudder that spends ``SLEEP_S`` in every ``act`` (not a registered controller)."""

    name = "sleepy_zero"

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        time.sleep(SLEEP_S)
        return super().act(obs, info)


def _same(a: Any, b: Any) -> bool:
    """Equal, with NaN equal to NaN (t_c of an episode without a change is NaN)."""
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


def test_compute_time_metrics_are_mean_and_max_in_ms() -> None:
    assert compute_time_metrics([0.001, 0.003]) == pytest.approx(
        {"compute_ms": 2.0, "compute_ms_max": 3.0}
    )


def test_compute_ms_is_the_time_spent_in_act() -> None:
    """A policy sleeping 2 ms per act() shows ≥ 2 ms per step; the same actions without the
    sleep show less (the loop times act(), nothing else)."""
    sleepy = run_episode(SleepyZero(), "nominal", seed=0)
    quick = run_episode(ZeroRudder(), "nominal", seed=0)
    m = sleepy.metrics
    assert m["compute_ms"] >= 1e3 * SLEEP_S
    assert m["compute_ms_max"] >= m["compute_ms"]
    assert quick.metrics["compute_ms"] < m["compute_ms"]
    # the sleep changes nothing else
    for key in m:
        if not key.startswith("compute_ms"):
            assert _same(m[key], quick.metrics[key]), key


def test_same_seed_gives_the_same_metrics_apart_from_compute_time() -> None:
    """Two runs of one seed (random rudder and sensor noise on a stochastic scenario)."""
    a, b = evaluate("random", "osaka_stochastic_current", seeds=[7, 7])
    assert a.metrics.keys() == b.metrics.keys()
    differ = [k for k in a.metrics if not _same(a.metrics[k], b.metrics[k])]
    assert all(k.startswith("compute_ms") for k in differ), differ
    for key, values in a.trajectory.items():
        np.testing.assert_array_equal(values, b.trajectory[key], err_msg=key)
    (c,) = evaluate("random", "osaka_stochastic_current", seeds=[8])
    assert c.metrics["ace"] != a.metrics["ace"]  # the seed does matter


def test_pid_los_sees_no_truth() -> None:
    """The controller context carries the nominal model only, not the post-event parameters."""
    policy = PIDLOS()
    result = run_episode(policy, "rudder_aging", seed=0)
    assert policy.ctx.nominal_params.Tc == pytest.approx(0.1)
    assert not hasattr(policy.ctx, "schedule")
    assert result.metrics["steps"] > 0


def test_a_policy_instance_runs_in_its_own_action_mode() -> None:
    """Without an ``action_mode`` the loop makes the env in the policy's (zero action in
    guidance mode is the env's PID LOS: it reaches the goal)."""
    policy = ZeroRudder()
    policy.action_mode = "guidance"
    (result,) = evaluate(policy, "nominal", seeds=[0])
    assert result.metrics["termination_reason"] == "goal"
    (rudder,) = evaluate(ZeroRudder(), "nominal", seeds=[0])
    assert rudder.metrics["termination_reason"] != "goal"


# --------------------------------------------------------------------- batched evaluation

SHIPPED = ("ppo", "sac", "td3", "recurrent_ppo", "ppo_guidance")


def _trials(scenario: str, n: int) -> list[Scenario]:
    """``n`` trial variants of ``scenario``, one per seed: the start moved across the path,
    and time limits that differ (the episodes end at different steps: the goal, the limits)."""
    base = load_scenario(scenario)
    start, limit = base.config.initial_state, base.config.time_limit
    return [
        base.with_overrides(
            {
                "initial_state": {"y": start.y + 0.4 * i, "heading_deg": 5.0 * i},
                "time_limit": limit / (1 + i),
            }
        )
        for i in range(n)
    ]


#: metrics that are times measured on the machine (the controller's act, its solver)
TIMINGS = ("compute_ms", "solve_ms")


def _assert_same_episodes(batched: list[EpisodeResult], one_by_one: list[EpisodeResult]) -> None:
    """Equal metrics (measured times aside) and trajectories, bit for bit."""
    assert len(batched) == len(one_by_one)
    for a, b in zip(batched, one_by_one, strict=True):
        assert (a.controller, a.kind, a.scenario, a.seed, a.training_seed) == (
            b.controller,
            b.kind,
            b.scenario,
            b.seed,
            b.training_seed,
        )
        keys = {k for k in a.metrics if not k.startswith(TIMINGS)}
        assert keys == {k for k in b.metrics if not k.startswith(TIMINGS)}
        differ = [k for k in keys if not _same(a.metrics[k], b.metrics[k])]
        assert not differ, (a.controller, a.seed, differ)
        assert a.trajectory.keys() == b.trajectory.keys()
        for key, values in a.trajectory.items():
            np.testing.assert_array_equal(values, b.trajectory[key], err_msg=key)


def _one_by_one(name: str, scenarios: list, seeds: list[int], training_seed=None) -> list:
    results = []
    for scenario, seed in zip(scenarios, seeds, strict=True):
        policy, mode = make_controller(name, training_seed=training_seed)
        results.append(run_episode(policy, scenario, seed, mode))
    return results


@pytest.mark.parametrize("name", SHIPPED)
def test_batched_learned_evaluation_equals_one_episode_at_a_time(name: str) -> None:
    """Three seeds on each of two scenarios, each seed its own trial variant (the episodes
    end at different steps, so rows move up in the batch): the lockstep run with one network
    forward per step equals ``run_episode`` one by one, bit for bit."""
    pytest.importorskip("stable_baselines3")
    seeds = [EVAL_SEED_OFFSET + i for i in range(3)]
    trained = training_seeds(name)[-1]
    for scenario in ("rudder_aging", "current_shift"):
        trials = _trials(scenario, len(seeds))
        batched = evaluate_batch(name, trials, seeds, training_seed=trained)
        _assert_same_episodes(batched, _one_by_one(name, trials, seeds, trained))
        assert {r.training_seed for r in batched} == {trained}
        assert len({r.metrics["ace"] for r in batched}) == len(seeds)  # the trials differ
        assert len({r.metrics["steps"] for r in batched}) == len(seeds)  # and end apart


def test_batched_recurrent_evaluation_spans_several_forward_chunks() -> None:
    """More episodes than one forward's rows (BATCH_ROWS): LSTM states stay with their
    episodes across chunks, as episodes end and the rows shift."""
    pytest.importorskip("sb3_contrib")
    from shipgym_baselines.learned.policy import BATCH_ROWS

    n = BATCH_ROWS + 2
    seeds = [EVAL_SEED_OFFSET + i for i in range(n)]
    base = load_scenario("nominal")
    trials = [
        base.with_overrides({"initial_state": {"y": 0.2 * i}, "time_limit": 40.0 + 2.0 * i})
        for i in range(n)
    ]
    batched = evaluate_batch("recurrent_ppo", trials, seeds)
    _assert_same_episodes(batched, _one_by_one("recurrent_ppo", trials, seeds))
    assert len({r.metrics["steps"] for r in batched}) > 1


def test_batched_evaluation_runs_classical_controllers_one_by_one() -> None:
    """A classical controller (by name or as an instance) gives what ``evaluate`` gives, one
    scenario for all seeds or one per seed."""
    seeds = [EVAL_SEED_OFFSET, EVAL_SEED_OFFSET + 1]
    _assert_same_episodes(
        evaluate_batch("pid_los", "rudder_aging", seeds), evaluate("pid_los", "rudder_aging", seeds)
    )
    trials = _trials("nominal", 2)
    expected = [evaluate("pid_los", t, [s])[0] for t, s in zip(trials, seeds, strict=True)]
    _assert_same_episodes(evaluate_batch(PIDLOS(), trials, seeds), expected)
    assert all(r.training_seed is None for r in expected)
    with pytest.raises(ValueError, match="2 scenarios for 3 seeds"):
        evaluate_batch("pid_los", trials, [*seeds, 3])
    with pytest.raises(ControllerError, match="'pid_los' has no training seeds"):
        evaluate_batch("pid_los", "nominal", seeds, training_seed=0)


class _ClockedZero(ZeroRudder):
    """A zero-rudder BatchPolicy (one ``act_batch`` call for all live episodes)."""

    name = "clocked_zero"

    def reset_batch(self, contexts: list) -> None:
        pass

    def act_batch(self, obs: np.ndarray, episodes: list[int]) -> np.ndarray:
        return np.zeros((len(obs), 1), dtype=np.float32)


def test_batched_compute_time_divides_each_forward_among_the_live_envs() -> None:
    """The loop's clock reads 1 s more at every call, so each ``act_batch`` takes 1 s: while
    two episodes are live each step costs each 500 ms; once the short one has ended, the
    long one pays the whole second."""
    ticks = iter(range(10**6))
    long = load_scenario("nominal")
    short = long.with_overrides({"time_limit": 20.0})
    with evaluation.act_clock(lambda: float(next(ticks))):
        a, b = evaluate_batch(_ClockedZero(), [long, short], [0, 0])
    n_long, n_short = len(a.trajectory["t"]) - 1, len(b.trajectory["t"]) - 1
    assert n_short < n_long
    assert (b.metrics["compute_ms"], b.metrics["compute_ms_max"]) == (500.0, 500.0)
    assert a.metrics["compute_ms_max"] == 1000.0
    expected = (500.0 * n_short + 1000.0 * (n_long - n_short)) / n_long
    assert a.metrics["compute_ms"] == pytest.approx(expected, rel=1e-12)
