"""The envs pass the clients' own checks: Gymnasium's
``check_environments_match`` with ``info_comparison="equivalence"`` (no wall-clock number in
``info``), ``gym.make_vec`` in the default batched mode with ``max_episode_steps``, the
batched ``episode_metrics`` dtypes of ``SyncVectorEnv``, and the module-qualified id
``shipgym:ShipPathFollow-v0`` in a fresh spawn process.  (``check_env`` of Gymnasium and SB3
on every id: ``test_path_follow.py``; SB3's ``VecMonitor(info_keywords=…)``:
``test_vector.py``.)"""

from __future__ import annotations

import multiprocessing

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import data_equivalence
from gymnasium.utils.env_match import check_environments_match

import shipgym
from shipgym.envs.vector import ShipPathFollowVectorEnv
from shipgym.scenarios.loader import Scenario, load_scenario
from tests.shipgym.envs.spawn_worker import make_and_step

SHIP_IDS = sorted(shipgym.ENV_IDS)
ALL_IDS = sorted(k for k in gym.registry if k.startswith("ShipPathFollow"))


def short_scenario(env_id: str) -> Scenario:
    """The id's default scenario cut to ≈ 20 control periods (past its first change), so
    that episodes end, and ``episode_metrics`` is compared, within a short check."""
    sc = load_scenario(shipgym.ENV_IDS[env_id])
    limit = max(20, (sc.change_time or 0.0) / sc.control_period + 6) * sc.control_period
    return sc.with_overrides({"time_limit": float(limit)})


def test_two_default_envs_match_with_equivalent_infos() -> None:
    """The issue's check, literally: two ``gym.make("ShipPathFollow-v0")`` over more steps
    than an episode lasts (180 at most), so the last info with ``episode_metrics`` counts."""
    check_environments_match(
        gym.make("ShipPathFollow-v0"),
        gym.make("ShipPathFollow-v0"),
        num_steps=200,
        seed=0,
        info_comparison="equivalence",
    )


@pytest.mark.parametrize("mode", ["rudder", "guidance"])
@pytest.mark.parametrize("env_id", SHIP_IDS)
def test_envs_match_through_episode_ends(env_id: str, mode: str) -> None:
    """Every ship and action mode, several short episodes (resets included)."""
    sc = short_scenario(env_id)
    envs = [gym.make(env_id, scenario=sc, action_mode=mode) for _ in range(2)]
    steps = round(sc.config.time_limit / sc.control_period)
    check_environments_match(*envs, num_steps=3 * steps, seed=1, info_comparison="equivalence")


def test_randomized_envs_match() -> None:
    envs = [gym.make(shipgym.RANDOMIZED_ENV_ID) for _ in range(2)]
    check_environments_match(*envs, num_steps=60, seed=2, info_comparison="equivalence")


@pytest.mark.parametrize("env_id", SHIP_IDS)
def test_every_info_key_is_the_same_in_a_second_run(env_id: str) -> None:
    """Each key, the last step's ``episode_metrics`` too: no clock and no hidden state."""
    sc = short_scenario(env_id)
    runs = []
    for _ in range(2):
        env = gym.make(env_id, scenario=sc)
        env.action_space.seed(5)
        infos = [env.reset(seed=5)[1]]
        while True:
            *_, terminated, truncated, info = env.step(env.action_space.sample())
            infos.append(info)
            if terminated or truncated:
                break
        runs.append(infos)
    first, second = runs
    assert len(first) == len(second)
    assert "episode_metrics" in first[-1]
    assert not any(k.startswith("compute_ms") for k in first[-1]["episode_metrics"])
    for a, b in zip(first, second, strict=True):
        assert a.keys() == b.keys()
        for key in a:
            assert data_equivalence(a[key], b[key]), key


@pytest.mark.parametrize("env_id", SHIP_IDS)
def test_make_vec_default_mode_takes_max_episode_steps(env_id: str) -> None:
    envs = gym.make_vec(env_id, num_envs=3, max_episode_steps=50)
    assert isinstance(envs.unwrapped, ShipPathFollowVectorEnv)
    envs.reset(seed=0)
    action = np.zeros(envs.action_space.shape, dtype=np.float32)
    for step in range(1, 51):
        _, _, terminated, truncated, info = envs.step(action)
        assert not terminated.any()  # zero rudder stays in every corridor for 50 steps
        assert truncated.all() == (step == 50)
    assert list(info["termination_reason"]) == ["time_limit"] * 3
    assert (info["episode_metrics"]["steps"] == 50).all()
    envs.close()


def test_batched_episode_metrics_have_sync_vector_env_dtypes() -> None:
    """``steps`` int64 and ``success`` bool in both, and every other metric's dtype equal."""
    sc = short_scenario("ShipPathFollow-v0")
    metrics = {}
    for mode in ("vector_entry_point", "sync"):
        envs = gym.make_vec("ShipPathFollow-v0", num_envs=2, vectorization_mode=mode, scenario=sc)
        envs.reset(seed=0)
        while True:
            *_, terminated, truncated, info = envs.step(np.zeros((2, 1), dtype=np.float32))
            if (terminated | truncated).all():
                break
        metrics[mode] = info["episode_metrics"]
        envs.close()
    batched, sync = metrics["vector_entry_point"], metrics["sync"]
    assert batched["steps"].dtype == sync["steps"].dtype == np.int64
    assert batched["success"].dtype == sync["success"].dtype == np.bool_
    assert batched.keys() == sync.keys()
    for key in sync:
        assert batched[key].dtype == sync[key].dtype, key


def test_the_module_qualified_id_works_in_a_fresh_spawn_process() -> None:
    """A spawned worker has not imported shipgym: the bare id is unknown there, the
    ``shipgym:`` form imports the package and gives the same episode as here."""
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        with pytest.raises(gym.error.NameNotFound):
            pool.apply(make_and_step, ("ShipPathFollow-v0", 0))
        remote = pool.apply(make_and_step, ("shipgym:ShipPathFollow-v0", 0))
    assert remote["imported_before"] is False
    env = gym.make("ShipPathFollow-v0")
    obs, _ = env.reset(seed=0)
    next_obs, reward, *_ = env.step(np.zeros(1, dtype=np.float32))
    np.testing.assert_array_equal(remote["obs"], obs)
    np.testing.assert_array_equal(remote["next_obs"], next_obs)
    assert remote["reward"] == reward
