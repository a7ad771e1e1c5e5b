"""The evaluation trials env: given trials as rows, each row the single env's episode of its
trial and seed, bit for bit: observations, rewards, ends and every ``info`` key (issue 18)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from shipgym.envs.eval_trials import EvaluationTrialsVectorEnv, LockstepError, lockstep_problem
from shipgym.envs.path_follow import ShipPathFollowEnv
from shipgym.scenarios import Scenario, load_scenario

SEEDS = [10_000, 10_001, 10_002]


def _variants(name: str) -> list[Scenario]:
    """Three trials of ``name``: the start moved, the time limits apart (rows end apart)."""
    base = load_scenario(name)
    start, limit = base.config.initial_state, base.config.time_limit
    return [
        base.with_overrides(
            {
                "initial_state": {"y": start.y + 3.0 * i, "heading_deg": 4.0 * i},
                "time_limit": limit * (1.0 - 0.2 * i),
            }
        )
        for i in range(len(SEEDS))
    ]


def _assert_same(a: Any, b: Any, where: str) -> None:
    """Equal bit for bit: dicts key by key, arrays entry by entry, NaN equal to NaN."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), (where, a.keys(), b)
        for key in a:
            _assert_same(a[key], b[key], f"{where}.{key}")
    elif isinstance(a, np.ndarray | tuple | list):
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b), err_msg=where)
    elif isinstance(a, float) and np.isnan(a):
        assert isinstance(b, float) and np.isnan(b), where
    else:
        assert a == b, (where, a, b)


# heldout:8: nomoto2 with a parameter jump, a constant current and noisy heading sensors;
# heldout:6: the 3-DOF Mariner with a parameter jump, a current shift and noisy sensors
@pytest.mark.parametrize("name", ["heldout:8", "heldout:6"])
@pytest.mark.parametrize("mode", ["rudder", "guidance"])
def test_each_row_is_the_single_env_episode_of_its_trial(name: str, mode: str) -> None:
    trials = _variants(name)
    env = EvaluationTrialsVectorEnv(trials, SEEDS, action_mode=mode)
    singles = [ShipPathFollowEnv(t, action_mode=mode) for t in trials]
    obs, info = env.reset()
    for i, single in enumerate(singles):
        o, inf = single.reset(seed=SEEDS[i])
        np.testing.assert_array_equal(obs[i], o)
        _assert_same(info["rows"][i], inf, f"reset row {i}")
    rng = np.random.default_rng(1)
    width = env.single_action_space.shape[0]
    ends = [0] * len(SEEDS)
    step = 0
    while not env.finished.all():
        step += 1
        # small actions around a steady course so that rows reach their goal or time limit
        action = (0.15 * rng.standard_normal((len(SEEDS), width))).astype(np.float32)
        live = ~env.finished
        obs, rew, term, trunc, info = env.step(action)
        for i, single in enumerate(singles):
            if not live[i]:
                assert info["rows"][i] is None and rew[i] == 0.0 and not (term[i] or trunc[i])
                continue
            o, r, te, tr, inf = single.step(action[i])
            np.testing.assert_array_equal(obs[i], o)
            assert (rew[i], term[i], trunc[i]) == (r, te, tr)
            _assert_same(info["rows"][i], inf, f"step {step} row {i}")
            if te or tr:
                assert "episode_metrics" in info["rows"][i]
                ends[i] = step
    assert len(set(ends)) == len(SEEDS)  # the rows ended at different steps


def test_rows_of_different_ships_or_step_constants_are_refused() -> None:
    nomoto, mariner = load_scenario("rudder_aging"), load_scenario("mariner_rudder_aging")
    assert lockstep_problem([nomoto, nomoto]) is None
    assert "ship model" in lockstep_problem([nomoto, mariner])
    slower = nomoto.with_overrides({"control_period": 2 * nomoto.control_period})
    assert "control_period" in lockstep_problem([nomoto, slower])
    with pytest.raises(LockstepError, match="trial 1"):
        EvaluationTrialsVectorEnv([nomoto, mariner], [0, 1])
    with pytest.raises(ValueError, match="2 scenarios for 1 seeds"):
        EvaluationTrialsVectorEnv([nomoto, nomoto], [0])


def test_rows_without_samples_step_the_same() -> None:
    """``samples=False`` (a policy that reads observations only): the same observations,
    rewards, ends and infos bit for bit, without the ``samples`` key."""
    trials = _variants("rudder_aging")
    with_s = EvaluationTrialsVectorEnv(trials, SEEDS)
    without = EvaluationTrialsVectorEnv(trials, SEEDS, samples=False)
    obs_a, info_a = with_s.reset()
    obs_b, info_b = without.reset()
    np.testing.assert_array_equal(obs_a, obs_b)
    rng = np.random.default_rng(0)
    for _ in range(40):
        action = rng.uniform(-1.0, 1.0, size=with_s.action_space.shape)
        *out_a, info_a = with_s.step(action)
        *out_b, info_b = without.step(action)
        for a, b in zip(out_a, out_b, strict=True):
            np.testing.assert_array_equal(a, b)
        for row_a, row_b in zip(info_a["rows"], info_b["rows"], strict=True):
            if row_a is None:
                assert row_b is None
                continue
            assert "samples" in row_a and "samples" not in row_b
            _assert_same({k: v for k, v in row_a.items() if k != "samples"}, row_b, "info")
