"""The registered ids follow Gymnasium's seeding: ``reset(seed=…)`` draws the trial (the
default suite's ``randomize:`` ranges) from the env's ``np_random``; ``randomize=False`` is
the fixed scenario of the class; every spec states ``max_episode_steps``; ``gym.make_vec``
seeds its envs' trials apart.  (Gymnasium's ``check_env``, which checks that a seed's
reset is reproducible, runs on every id with its registered defaults in
``test_path_follow.py``.)"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import shipgym
from shipgym.envs import core
from shipgym.envs.path_follow import ShipPathFollowEnv
from shipgym.scenarios.loader import build_scenario, load_scenario
from shipgym.scenarios.sampling import load_distribution
from shipgym.scenarios.trials import env_randomization

SHIP_IDS = sorted(shipgym.ENV_IDS)
ALL_IDS = sorted(k for k in gym.registry if k.startswith("ShipPathFollow"))
STEPS = 40


def actions(n: int = STEPS) -> np.ndarray:
    return (0.6 * np.sin(0.3 * np.arange(n)))[:, None].astype(np.float32)


def rollout(env: gym.Env, seed: int | None) -> tuple[np.ndarray, list[float]]:
    """The first observation and the rewards of ``STEPS`` fixed actions."""
    obs, _ = env.reset(seed=seed)
    rewards = []
    for a in actions():
        _, r, terminated, truncated, _ = env.step(a)
        rewards.append(r)
        if terminated or truncated:
            break
    return obs, rewards


def start(env: gym.Env) -> tuple[float, float, float]:
    s = env.unwrapped.scenario.config.initial_state
    return s.x, s.y, s.heading_deg


def test_the_ids_draw_the_default_suites_ranges() -> None:
    from shipgym_baselines.suite import load_suite

    assert env_randomization() == load_suite("default").randomize
    for env_id in SHIP_IDS:
        assert gym.spec(env_id).kwargs["randomize"] is True


@pytest.mark.parametrize("env_id", SHIP_IDS)
def test_a_seed_is_one_trial_and_seeds_are_different_trials(env_id: str) -> None:
    env = gym.make(env_id)
    first, starts = [], []
    for seed in (0, 1, 2):
        first.append(rollout(env, seed))
        starts.append(start(env))
    for seed, (obs, rewards) in zip((0, 1, 2), first, strict=True):
        again_obs, again_rewards = rollout(gym.make(env_id), seed)
        assert np.array_equal(obs, again_obs) and rewards == again_rewards
    assert len(set(starts)) == 3  # three trials
    assert not np.array_equal(first[0][0], first[1][0])
    base = env.unwrapped.base_scenario
    assert base.name == shipgym.ENV_IDS[env_id] and env.unwrapped.scenario.name == base.name


def test_unseeded_resets_continue_the_stream() -> None:
    env = gym.make("ShipPathFollow-v0")
    env.reset(seed=5)
    trials = [start(env)]
    for _ in range(3):
        env.reset()
        trials.append(start(env))
    assert len(set(trials)) == 4
    again = gym.make("ShipPathFollow-v0")
    again.reset(seed=5)
    again.reset()
    assert start(again) == trials[1]


@pytest.mark.parametrize("env_id", SHIP_IDS)
def test_randomize_false_is_the_fixed_scenario_of_the_class(env_id: str) -> None:
    fixed = gym.make(env_id, randomize=False)
    direct = ShipPathFollowEnv(shipgym.ENV_IDS[env_id])
    for seed in (0, 1):
        obs, rewards = rollout(fixed, seed)
        obs_d, rewards_d = rollout(direct, seed)
        assert np.array_equal(obs, obs_d) and rewards == rewards_d
        assert fixed.unwrapped.scenario is fixed.unwrapped.base_scenario


def test_randomize_must_be_a_bool() -> None:
    with pytest.raises(ValueError, match="randomize"):
        ShipPathFollowEnv("nominal", randomize="yes")


@pytest.mark.parametrize("env_id", ALL_IDS)
def test_every_spec_states_the_episode_length_of_its_scenario(env_id: str) -> None:
    """The id's default scenario's ceil(time_limit / Ts) control periods, which the env's
    own truncation counts; the randomised env: its distribution's longest episode."""
    spec = gym.spec(env_id)
    assert spec.max_episode_steps == shipgym.MAX_EPISODE_STEPS[env_id]
    if env_id in shipgym.ENV_IDS:
        sc = load_scenario(shipgym.ENV_IDS[env_id])
        steps = core.StepConstants.of(sc).max_steps
        assert steps == round(sc.config.time_limit / sc.control_period)
        assert spec.max_episode_steps == steps == gym.make(env_id).unwrapped._k.max_steps
    else:
        assert spec.max_episode_steps == load_distribution("train").max_episode_steps()


def test_the_distribution_bound_holds_for_its_draws() -> None:
    dist = load_distribution("train")
    bound = dist.max_episode_steps()
    longest = 0
    for k in range(150):
        config = dist.sample(np.random.default_rng(k))
        longest = max(longest, core.StepConstants.of(build_scenario(config)).max_steps)
    assert longest <= bound
    assert longest >= 0.6 * bound  # a bound, not far off


def test_the_time_limit_wrapper_and_the_env_truncate_at_the_same_step() -> None:
    """ShipPathFollow-v0 to its end under a rudder law that neither leaves the corridor nor
    reaches the goal: truncated at step 180, by both."""
    env = gym.make("ShipPathFollow-v0")
    obs, _ = env.reset(seed=0)
    steps, truncated, info = 0, False, {}
    while not truncated:
        action = np.clip([obs[1] + 3.0 * obs[0]], -1.0, 1.0).astype(np.float32)
        obs, _, terminated, truncated, info = env.step(action)
        assert not terminated
        steps += 1
    assert steps == env.spec.max_episode_steps == 180
    assert info["termination_reason"] == "time_limit"


@pytest.mark.parametrize("mode", ["vector_entry_point", "sync"])
def test_make_vec_seeds_its_envs_apart(mode: str) -> None:
    envs = gym.make_vec("ShipPathFollow-v0", num_envs=3, vectorization_mode=mode)
    obs, _ = envs.reset(seed=7)
    base = envs if mode == "vector_entry_point" else None
    trials = (
        base.trials if base is not None else [e.unwrapped.scenario for e in envs.unwrapped.envs]  # type: ignore[attr-defined]
    )
    starts = {t.config.initial_state.y for t in trials}
    assert len(starts) == 3 and len({tuple(o) for o in obs.tolist()}) == 3
    # env i is the single env seeded seed + i
    for i in range(3):
        single, _ = gym.make("ShipPathFollow-v0").reset(seed=7 + i)
        assert np.array_equal(obs[i], single)
    envs.close()


def test_the_batched_env_equals_sync_single_envs_with_trials() -> None:
    """The default make_vec (the batched env) draws each env's trial as the single env
    does: the same observations, rewards and ends as SyncVectorEnv, over episode ends
    (autoreset draws a new trial) and the jump."""
    sc = load_scenario("rudder_aging").with_overrides({"time_limit": 30.0})
    batched = gym.make_vec("ShipPathFollow-v0", num_envs=3, scenario=sc)
    sync = gym.make_vec("ShipPathFollow-v0", num_envs=3, scenario=sc, vectorization_mode="sync")
    assert batched.unwrapped.randomize
    a, b = batched.reset(seed=3), sync.reset(seed=3)
    assert np.array_equal(a[0], b[0])
    rng = np.random.default_rng(0)
    ends = 0
    for _ in range(150):
        act = rng.uniform(-1, 1, (3, 1)).astype(np.float32)
        sa, sb = batched.step(act), sync.step(act)
        for x, y in zip(sa[:4], sb[:4], strict=True):
            assert np.array_equal(x, y)
        if sa[2].any() or sa[3].any():
            ends += 1
            for key, value in sb[4]["episode_metrics"].items():
                assert np.array_equal(sa[4]["episode_metrics"][key], value, equal_nan=True), key
    assert ends >= 2


def test_make_vec_passes_randomize_false_through() -> None:
    envs = gym.make_vec("ShipPathFollow-v0", num_envs=2, randomize=False)
    envs.reset(seed=0)
    assert not envs.unwrapped.randomize
    assert all(t is envs.unwrapped.scenario for t in envs.unwrapped.trials)


@pytest.mark.parametrize("env_id", SHIP_IDS)
def test_gymnasium_check_env_with_trials(env_id: str) -> None:
    env = gym.make(env_id)
    assert env.unwrapped.randomize
    check_env(env.unwrapped, skip_render_check=True)
