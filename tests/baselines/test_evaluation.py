"""The evaluation loop: what a policy sees and what the loop measures (SPEC §8–9)."""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np
import pytest

from baselines.classical.pid import PIDLOS
from baselines.classical.reference import ZeroRudder
from baselines.evaluation import compute_time_metrics, evaluate, run_episode

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
