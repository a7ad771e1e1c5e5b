"""History in the observation (``history_steps=K``): the last K control steps of
(measurements, applied rudder command) after the observation, the same numbers in every
env, zeros before the episode's start."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils import seeding

import shipgym
from shipgym.envs import core
from shipgym.envs.eval_trials import EvaluationTrialsVectorEnv
from shipgym.envs.path_follow import ShipPathFollowEnv
from shipgym.envs.randomized import ShipPathFollowRandomizedEnv
from shipgym.envs.ship_batch import ShipTrialsVectorEnv
from shipgym.envs.vector import ShipPathFollowVectorEnv
from shipgym.limits import MAX_HISTORY_STEPS
from shipgym.scenarios.loader import load_scenario
from shipgym.scenarios.sampling import train_scenario_seed

N = 3
#: the observation entries one history step repeats, and the applied command's entry
MEASURED = [core.OBS_NAMES.index(name) for name in core.HISTORY_MEASUREMENTS]
APPLIED = core.OBS_NAMES.index("last_rudder_command")


def _actions(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    """Random actions, some beyond [-1, 1] (the env clips them: the applied command)."""
    return rng.uniform(-1.3, 1.3, shape).astype(np.float32)


def _window(obs: np.ndarray, k: int) -> np.ndarray:
    """The history part of observations (..., width) as (..., K, HISTORY_WIDTH)."""
    return obs[..., obs.shape[-1] - k * core.HISTORY_WIDTH :].reshape(
        *obs.shape[:-1], k, core.HISTORY_WIDTH
    )


# ------------------------------------------------------------------------- (a) K = 0
@pytest.mark.filterwarnings("ignore:.*is out of date.*")
@pytest.mark.parametrize("env_id", sorted(shipgym.ENV_IDS))
def test_k0_observations_are_today_s_for_every_env_id(env_id: str) -> None:
    """``history_steps=0`` gives byte-identical observations and the same space as an env
    made without the argument; K > 0 keeps them as its first entries."""
    plain = gym.make(env_id)
    zero = gym.make(env_id, history_steps=0)
    more = gym.make(env_id, history_steps=2)
    assert zero.observation_space == plain.observation_space
    assert more.observation_space.shape == (len(core.OBS_NAMES) + 2 * core.HISTORY_WIDTH,)
    n_act = plain.action_space.shape
    rng = np.random.default_rng(1)
    outs = [env.reset(seed=5)[0] for env in (plain, zero, more)]
    for step in range(25):
        assert outs[1].dtype == outs[0].dtype and outs[1].tobytes() == outs[0].tobytes()
        np.testing.assert_array_equal(outs[2][: len(core.OBS_NAMES)], outs[0])
        assert more.observation_space.contains(outs[2]), step
        action = _actions(rng, n_act)
        outs = [env.step(action)[0] for env in (plain, zero, more)]


def test_k0_batched_randomized_and_training_envs_are_today_s() -> None:
    rng = np.random.default_rng(2)
    pairs = [
        (
            ShipPathFollowVectorEnv(N, "rudder_aging", context_features=True),
            ShipPathFollowVectorEnv(N, "rudder_aging", context_features=True, history_steps=0),
        ),
        (
            ShipTrialsVectorEnv(N, "train", ship=1),
            ShipTrialsVectorEnv(N, "train", 1, history_steps=0),
        ),
    ]
    for plain, zero in pairs:
        assert zero.single_observation_space == plain.single_observation_space
        a, b = plain.reset(seed=3)[0], zero.reset(seed=3)[0]
        for _ in range(15):
            assert a.tobytes() == b.tobytes()
            action = _actions(rng, plain.action_space.shape)
            a, b = plain.step(action)[0], zero.step(action)[0]
    plain = gym.make(shipgym.RANDOMIZED_ENV_ID)
    zero = gym.make(shipgym.RANDOMIZED_ENV_ID, history_steps=0)
    assert plain.reset(seed=4)[0].tobytes() == zero.reset(seed=4)[0].tobytes()
    for _ in range(10):
        action = _actions(rng, (1,))
        assert plain.step(action)[0].tobytes() == zero.step(action)[0].tobytes()


# ------------------------------------------------------------------------- (c) the window
@pytest.mark.parametrize("mode", ["rudder", "guidance"])
def test_window_holds_zeros_then_the_past_measurements_and_applied_commands(mode: str) -> None:
    """Step n's window, oldest first, holds for lags K … 1 the measured entries of the
    observation at step n − lag and the command applied during that step (info's
    ``rudder_command`` / δmax, the env's clipping or the autopilot's command); zeros where
    n − lag < 0; after ``reset`` all zeros again."""
    k = 5
    env = ShipPathFollowEnv(
        "rudder_aging", action_mode=mode, context_features=True, history_steps=k
    )
    limit = env.scenario.model.rudder_limit
    width = core.observation_size(True, k)
    assert env.observation_space.shape == (width,)
    assert core.observation_names(True, k)[-core.HISTORY_WIDTH :] == tuple(
        f"{name}_lag1" for name in core.HISTORY_STEP_NAMES
    )
    rng = np.random.default_rng(7)
    for episode in range(2):
        obs, info = env.reset(seed=episode)
        observations, applied = [obs], []
        for n in range(12):
            window = _window(obs, k)
            for lag in range(1, k + 1):
                row = window[k - lag]
                if n - lag < 0:
                    assert not row.any(), (n, lag)
                    continue
                past = observations[n - lag]
                np.testing.assert_array_equal(row[:-1], past[MEASURED])
                assert row[-1] == applied[n - lag]
            assert env.observation_space.contains(obs)
            obs, _, terminated, truncated, info = env.step(_actions(rng, env.action_space.shape))
            assert not (terminated or truncated)
            # the applied command, as the env reports it
            applied.append(np.float32(np.clip(info["rudder_command"] / limit, -1, 1)))
            assert applied[-1] == obs[APPLIED]
            observations.append(obs)
        if mode == "rudder":  # the clipped action, to float32 rounding
            assert np.abs(np.array(applied)).max() <= 1.0


# ------------------------------------------------------------------------- (b) single = batched
def test_batched_env_windows_equal_the_single_envs_through_autoreset_and_reset() -> None:
    """The batched env and N single envs (SyncVectorEnv, the same seeds, actions and time
    limit) give equal observations, windows included, at every step: through NEXT_STEP
    autoresets (the reset row's window is zeros) and an explicit masked ``reset``."""
    k, limit = 4, 9
    kwargs = {"scenario": "rudder_aging", "history_steps": k, "context_features": True}
    batched = ShipPathFollowVectorEnv(N, max_episode_steps=limit, **kwargs)
    single = gym.vector.SyncVectorEnv(
        [lambda: gym.make("ShipPathFollow-v0", max_episode_steps=limit, randomize=False, **kwargs)]
        * N
    )
    assert batched.single_observation_space == single.single_observation_space
    rng = np.random.default_rng(0)
    obs_b, _ = batched.reset(seed=3)
    obs_s, _ = single.reset(seed=3)
    restarted = 0
    for step in range(30):
        np.testing.assert_array_equal(obs_b, obs_s, err_msg=str(step))
        if step == 20:  # rows 0 and 2 start over; row 1 keeps its window
            mask = np.array([True, False, True])
            before = obs_b[1].copy()
            obs_b, _ = batched.reset(seed=50, options={"reset_mask": mask})
            obs_s, _ = single.reset(seed=50, options={"reset_mask": mask})
            np.testing.assert_array_equal(obs_b, obs_s)
            assert not _window(obs_b[mask], k).any()
            np.testing.assert_array_equal(obs_b[1], before)
        action = _actions(rng, batched.action_space.shape)
        obs_b, _, term_b, trunc_b, _ = batched.step(action)
        obs_s, _, term_s, trunc_s, _ = single.step(action)
        np.testing.assert_array_equal(term_b | trunc_b, term_s | trunc_s)
        restarted += int(np.sum(term_b | trunc_b))
    assert restarted >= N  # episodes ended and were autoreset along the way


def test_training_env_windows_equal_the_single_env_on_its_drawn_trials() -> None:
    """Each row of the per-ship training env has the window of a single env on its drawn
    trial reset with its episode seed, step by step, and a masked reset zeros only its
    rows' windows."""
    k = 3
    env = ShipTrialsVectorEnv(N, "train", ship="nomoto2", history_steps=k)
    obs, _ = env.reset(seed=5)
    singles = []
    for i in range(N):
        gen, _ = seeding.np_random(5 + i)  # env i's generator: scenario seed, episode seed
        train_scenario_seed(gen)
        single = ShipPathFollowEnv(env.trial_scenarios[i], history_steps=k)
        o, _ = single.reset(seed=int(gen.integers(0, 2**31 - 1)))
        np.testing.assert_array_equal(obs[i], o)
        singles.append(single)
    rng = np.random.default_rng(4)
    for step in range(15):
        action = _actions(rng, env.action_space.shape)
        obs, *_ = env.step(action)
        for i, single in enumerate(singles):
            np.testing.assert_array_equal(obs[i], single.step(action[i])[0], err_msg=str(step))
    assert _window(obs, k).any()
    obs, _ = env.reset(options={"reset_mask": np.array([False, True, False])})
    assert not _window(obs[1], k).any() and _window(obs[0], k).all(axis=-1).any()
    randomized = ShipPathFollowRandomizedEnv("train", history_steps=k)
    assert randomized.observation_space == env.single_observation_space
    obs, _ = randomized.reset(seed=1)
    assert obs.shape == (core.observation_size(False, k),) and not _window(obs, k).any()


def test_evaluation_rows_windows_equal_the_single_envs_on_the_same_trials() -> None:
    k = 6
    base = load_scenario("rudder_aging")
    trials = [
        base.with_overrides({"initial_state": {"y": 3.0 * i}, "time_limit": 20.0 + 10.0 * i})
        for i in range(N)
    ]
    seeds = [10_000 + i for i in range(N)]
    rows = EvaluationTrialsVectorEnv(trials, seeds, samples=False, row_infos="end", history_steps=k)
    singles = [ShipPathFollowEnv(sc, history_steps=k) for sc in trials]
    obs, _ = rows.reset()
    for i, single in enumerate(singles):
        np.testing.assert_array_equal(obs[i], single.reset(seed=seeds[i])[0])
    rng = np.random.default_rng(8)
    done = np.zeros(N, dtype=bool)
    while not done.all():
        action = _actions(rng, rows.action_space.shape)
        obs, _, term, trunc, _ = rows.step(action)
        for i in np.flatnonzero(~done):
            o, _, te, tr, _ = singles[i].step(action[i])
            np.testing.assert_array_equal(obs[i], o)
            assert (te or tr) == (term[i] or trunc[i])
        done |= term | trunc


def test_window_function_layout() -> None:
    """:func:`core.history_window` on rows: the oldest step dropped, the newest appended
    (the previous observation's measured entries, the new one's applied command)."""
    k = 2
    window = np.arange(2 * k * core.HISTORY_WIDTH, dtype=np.float32).reshape(2, -1)
    previous = np.arange(18, dtype=np.float32).reshape(2, 9) / 100
    current = previous + 0.5
    got = core.history_window(window, previous, current)
    np.testing.assert_array_equal(got[:, : core.HISTORY_WIDTH], window[:, core.HISTORY_WIDTH :])
    np.testing.assert_array_equal(got[:, core.HISTORY_WIDTH : -1], previous[:, MEASURED])
    np.testing.assert_array_equal(got[:, -1], current[:, APPLIED])
    low, high = core.observation_bounds(False, k)
    assert low.shape == high.shape == (core.observation_size(False, k),)
    np.testing.assert_array_equal(
        low[-core.HISTORY_WIDTH :], [*core.OBS_LOW[MEASURED], core.OBS_LOW[APPLIED]]
    )


# ------------------------------------------------------------------------- (d) bad K
BAD = [-1, 1.5, 2.0, "3", True, None, MAX_HISTORY_STEPS + 1, 10**6]


@pytest.mark.parametrize("bad", BAD)
def test_bad_history_steps_are_clear_early_errors(bad: object) -> None:
    with pytest.raises(ValueError, match="history_steps"):
        gym.make("ShipPathFollow-v0", history_steps=bad)
    with pytest.raises(ValueError, match="history_steps"):
        ShipPathFollowVectorEnv(2, "nominal", history_steps=bad)
    with pytest.raises(ValueError, match="history_steps"):
        gym.make(shipgym.RANDOMIZED_ENV_ID, history_steps=bad)
    with pytest.raises(ValueError, match="history_steps"):
        ShipTrialsVectorEnv(2, "train", history_steps=bad)
    with pytest.raises(ValueError, match="history_steps"):
        EvaluationTrialsVectorEnv(["nominal"], [0], history_steps=bad)


def test_numpy_ints_are_accepted() -> None:
    assert core.check_history_steps(np.int64(3)) == 3
    assert ShipPathFollowEnv("nominal", history_steps=np.int32(1)).history_steps == 1
