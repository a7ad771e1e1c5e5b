"""Tests of the public env contract (docs/environment.md): conformance, seeding, vectorisation,
pickling, bad actions, info, observation bounds, reward, termination and rendering."""

from __future__ import annotations

import math
import pickle
import warnings
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env

import shipgym  # registers the environments
from shipgym.envs import core
from shipgym.scenarios.loader import load_scenario

ENV_IDS = sorted(k for k in gym.registry if k.startswith("ShipPathFollow"))
MODES = ("rudder", "guidance")
NOISY = "maneuverability_change"  # nomoto2 scenario with heading noise and outliers
INFO_FLOATS = (
    "t",
    "cross_track_error",
    "heading_error",
    "heading",
    "yaw_rate",
    "rudder_angle",
    "rudder_command",
)
SAMPLE_KEYS = {"t", "psi", "r", "delta", "delta_c", "e"}

#: (env id, action mode, scenario or None for the id's default)
CASES = [(i, m, None) for i in ENV_IDS for m in MODES]
NOISY_CASES = [("ShipPathFollow-v0", m, NOISY) for m in MODES]


def case_id(case: tuple) -> str:
    return "-".join(str(c) for c in case if c is not None)


def make(env_id: str, mode: str, scenario: str | None = None, **kwargs: Any) -> gym.Env:
    if scenario is not None:
        kwargs["scenario"] = scenario
    return gym.make(env_id, action_mode=mode, **kwargs)


def rollout(env: gym.Env, seed: int, actions: list[np.ndarray]) -> list[tuple]:
    obs, info = env.reset(seed=seed)
    out: list[tuple] = [(obs, info)]
    for a in actions:
        step = env.step(a)
        out.append(step)
        if step[2] or step[3]:
            break
    return out


def assert_same(a: Any, b: Any, path: str = "") -> None:
    """Bit-for-bit equality of nested obs/info structures (wall-clock timings excluded)."""
    if isinstance(a, dict):
        assert a.keys() == b.keys(), path
        for k in a:
            if k.startswith("compute_ms"):
                continue
            assert_same(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, np.ndarray | tuple | list):
        assert np.array_equal(np.asarray(a), np.asarray(b)), path
        if isinstance(a, np.ndarray):
            assert a.dtype == b.dtype, path
    else:
        assert type(a) is type(b) and a == b, path


def seeded_actions(space: gym.spaces.Box, n: int, seed: int) -> list[np.ndarray]:
    space = gym.spaces.Box(space.low, space.high, dtype=space.dtype)
    space.seed(seed)
    return [space.sample() for _ in range(n)]


# --------------------------------------------------------------------------------------------
# Conformance
# --------------------------------------------------------------------------------------------


def test_registered_ids() -> None:
    assert "ShipPathFollow-v0" in ENV_IDS
    env = gym.make("ShipPathFollow-v0")
    assert env.unwrapped.scenario.name == "rudder_aging"  # the -v0 default
    assert env.unwrapped.model.name == "nomoto2"
    assert env.unwrapped.action_mode == "rudder"


@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_gymnasium_check_env_no_warnings(case: tuple) -> None:
    env = make(*case)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        gym_check_env(env.unwrapped)
    assert [str(w.message) for w in caught] == []


@pytest.mark.parametrize("case", CASES + NOISY_CASES, ids=case_id)
def test_gymnasium_check_env_without_render_no_warnings(case: tuple) -> None:
    env = make(*case)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        gym_check_env(env.unwrapped, skip_render_check=True)
    assert [str(w.message) for w in caught] == []


@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_sb3_check_env_no_warnings(case: tuple) -> None:
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    env = make(*case)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sb3_check_env(env, warn=True)
    assert [str(w.message) for w in caught] == []


@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_spaces(case: tuple) -> None:
    env = make(*case)
    a, o = env.action_space, env.observation_space
    assert isinstance(a, gym.spaces.Box) and a.dtype == np.float32
    assert np.all(a.low == -1.0) and np.all(a.high == 1.0)
    assert a.shape == ((1,) if case[1] == "rudder" else (2,))
    assert isinstance(o, gym.spaces.Box) and o.dtype == np.float32
    assert np.all(np.isfinite(o.low)) and np.all(np.isfinite(o.high))


# --------------------------------------------------------------------------------------------
# Seeding
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("case", CASES + NOISY_CASES, ids=case_id)
def test_reset_seed_is_bit_for_bit_reproducible(case: tuple) -> None:
    env_a, env_b = make(*case), make(*case)
    actions = seeded_actions(env_a.action_space, 50, seed=11)
    a = rollout(env_a, 7, actions)
    b = rollout(env_b, 7, actions)
    assert len(a) == len(b) > 1
    for sa, sb in zip(a, b, strict=True):
        assert len(sa) == len(sb)
        for x, y in zip(sa, sb, strict=True):
            assert_same(x, y)
    # the same env, reset again with the same seed after an episode, repeats it too
    again = rollout(env_a, 7, actions)
    for sa, sb in zip(a, again, strict=True):
        for x, y in zip(sa, sb, strict=True):
            assert_same(x, y)


@pytest.mark.parametrize("mode", MODES)
def test_different_seeds_give_different_noise(mode: str) -> None:
    # the fixed scenario: two seeds differ in their noise only
    env_a = make("ShipPathFollow-v0", mode, NOISY, randomize=False)
    env_b = make("ShipPathFollow-v0", mode, NOISY, randomize=False)
    _, info_a = env_a.reset(seed=0)
    _, info_b = env_b.reset(seed=1)
    assert info_a["heading"] != info_b["heading"]
    action = np.zeros(env_a.action_space.shape, dtype=np.float32)
    info_a = env_a.step(action)[4]
    info_b = env_b.step(action)[4]
    assert np.all(info_a["samples"]["psi"] != info_b["samples"]["psi"])
    # noise is drawn fresh for every fine sample: no two samples share the same offset
    true_a = np.diff(info_a["samples"]["psi"] - info_b["samples"]["psi"])
    assert np.all(true_a != 0)
    if mode == "rudder":
        # in rudder mode the noise only touches measurements, never the plant
        assert info_a["position"] == info_b["position"]
        np.testing.assert_array_equal(info_a["samples"]["delta"], info_b["samples"]["delta"])


def test_heading_noise_has_the_configured_size() -> None:
    env = make("ShipPathFollow-v0", "rudder", NOISY)
    env.reset(seed=0)
    # the twin: same scenario with ideal sensors
    data = load_scenario(NOISY).config.model_dump()
    data["sensors"] = {}
    twin = gym.make("ShipPathFollow-v0", scenario=data)
    twin.reset(seed=0)
    diffs = []
    for _ in range(20):
        a = np.array([0.1], dtype=np.float32)
        diffs.append(env.step(a)[4]["samples"]["psi"] - twin.step(a)[4]["samples"]["psi"])
    d = np.concatenate(diffs)
    inliers = d[np.abs(d) < math.radians(3.0)]  # drop outliers (5–15°)
    assert len(inliers) > 0.95 * len(d)
    assert np.std(inliers) == pytest.approx(math.radians(0.2), rel=0.1)


# --------------------------------------------------------------------------------------------
# Vectorisation
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("mode", MODES)
def test_make_vec_sync_and_async(env_id: str, mode: str) -> None:
    results = {}
    for vmode in ("sync", "async"):
        envs = gym.make_vec(env_id, num_envs=2, vectorization_mode=vmode, action_mode=mode)
        try:
            obs, _ = envs.reset(seed=[3, 4])
            assert obs.shape == (2, *envs.single_observation_space.shape)
            assert obs.dtype == np.float32
            assert envs.single_observation_space.shape == (9,)
            envs.action_space.seed(5)
            steps = [obs]
            for _ in range(5):
                obs, rew, term, trunc, _ = envs.step(envs.action_space.sample())
                assert obs.shape == (2, 9) and rew.shape == (2,)
                assert term.shape == (2,) and trunc.shape == (2,)
                assert term.dtype == np.bool_ and trunc.dtype == np.bool_
                assert np.all(np.isfinite(rew))
                assert np.all(envs.single_observation_space.low <= obs)
                assert np.all(obs <= envs.single_observation_space.high)
                steps.append((obs, rew))
            results[vmode] = steps
        finally:
            envs.close()
    # sync and async vectorisation run the same simulation
    for s, a in zip(results["sync"], results["async"], strict=True):
        if isinstance(s, tuple):
            np.testing.assert_array_equal(s[0], a[0])
            np.testing.assert_array_equal(s[1], a[1])
        else:
            np.testing.assert_array_equal(s, a)


# --------------------------------------------------------------------------------------------
# Pickling
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("case", CASES + NOISY_CASES, ids=case_id)
def test_pickled_env_continues_identically(case: tuple) -> None:
    env = make(*case)
    actions = seeded_actions(env.action_space, 15, seed=2)
    env.reset(seed=4)
    for a in actions[:5]:
        env.step(a)
    clone = pickle.loads(pickle.dumps(env))
    for a in actions[5:]:
        for x, y in zip(env.step(a), clone.step(a), strict=True):
            assert_same(x, y)


# --------------------------------------------------------------------------------------------
# Bad actions
# --------------------------------------------------------------------------------------------


def bad_actions(mode: str) -> list[list[float]]:
    if mode == "rudder":
        return [[math.nan], [math.inf], [-math.inf]]
    return [[math.nan, 0.0], [0.0, math.inf], [-math.inf, math.nan]]


@pytest.mark.parametrize("case", CASES + NOISY_CASES, ids=case_id)
def test_non_finite_action_raises_and_leaves_state_unchanged(case: tuple) -> None:
    env, twin = make(*case), make(*case)
    actions = seeded_actions(env.action_space, 8, seed=9)
    env.reset(seed=1)
    twin.reset(seed=1)
    for a in actions[:3]:
        env.step(a)
        twin.step(a)
    for bad in bad_actions(case[1]):
        with pytest.raises(ValueError, match="action"):
            env.step(np.array(bad, dtype=np.float32))
        with pytest.raises(ValueError, match="action"):
            env.step(bad)  # a plain list too
    for a in actions[3:]:
        for x, y in zip(env.step(a), twin.step(a), strict=True):
            assert_same(x, y)


@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_wrong_action_shape_raises(case: tuple) -> None:
    env = make(*case)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action"):
        env.step(np.zeros(3, dtype=np.float32))


@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_out_of_range_actions_are_clipped(case: tuple) -> None:
    mode = case[1]
    big = [5.0] if mode == "rudder" else [5.0, -7.0]
    edge = [1.0] if mode == "rudder" else [1.0, -1.0]
    env, twin = make(*case), make(*case)
    env.reset(seed=0)
    twin.reset(seed=0)
    for k in range(6):
        sign = 1.0 if k % 3 else -1.0
        a = np.array(big, dtype=np.float32) * sign
        b = np.array(edge, dtype=np.float32) * sign
        step_a, step_b = env.step(a), twin.step(b)
        for x, y in zip(step_a, step_b, strict=True):
            assert_same(x, y)
        if mode == "rudder":
            assert step_a[4]["rudder_command"] == sign * env.unwrapped.model.rudder_limit


def test_step_before_reset_raises() -> None:
    env = gym.make("ShipPathFollow-v0").unwrapped
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.zeros(1, dtype=np.float32))


# --------------------------------------------------------------------------------------------
# info
# --------------------------------------------------------------------------------------------


def check_info_types(info: dict[str, Any], samples_expected: bool = True) -> None:
    for key in INFO_FLOATS:
        assert key in info, key
        assert isinstance(info[key], float) and not isinstance(info[key], bool), key
        assert math.isfinite(info[key]), key
    pos = info["position"]
    assert len(pos) == 2 and all(isinstance(v, float) for v in pos)
    assert isinstance(info["waypoint_index"], int) and not isinstance(info["waypoint_index"], bool)
    assert info["waypoint_index"] >= 0
    if not samples_expected:
        assert "samples" not in info  # reset: no period integrated yet
        return
    samples = info["samples"]
    assert isinstance(samples, dict) and set(samples) == SAMPLE_KEYS
    lengths = {k: np.shape(v) for k, v in samples.items()}
    assert all(isinstance(v, np.ndarray) and v.ndim == 1 for v in samples.values())
    assert len(set(lengths.values())) == 1, lengths


#: the randomized env has no ``samples`` (their number differs between ships): test_learned.py
SAMPLE_CASES = [c for c in CASES if c[0] != shipgym.RANDOMIZED_ENV_ID] + NOISY_CASES


@pytest.mark.parametrize("case", SAMPLE_CASES, ids=case_id)
def test_info_keys_and_types(case: tuple) -> None:
    env = make(*case)
    inner = env.unwrapped
    h = inner.scenario.fine_step
    n_sub = round(inner.scenario.control_period / h)
    if inner.model.name == "nomoto2":
        assert (h, n_sub) == (0.01, 50)
    _, info = env.reset(seed=0)
    check_info_types(info, samples_expected=False)
    assert info["t"] == 0.0
    assert "episode_metrics" not in info
    actions = seeded_actions(env.action_space, 40, seed=3)
    prev = info
    for k, a in enumerate(actions, start=1):
        _, _, terminated, truncated, info = env.step(a)
        check_info_types(info)
        s = info["samples"]
        assert len(s["t"]) == n_sub
        assert info["t"] == pytest.approx(k * inner.scenario.control_period, abs=1e-12)
        # samples at the substep starts: t0, t0 + h, ..., t0 + Ts - h
        assert s["t"][0] == pytest.approx(prev["t"], abs=1e-12)
        assert s["t"][-1] == pytest.approx(info["t"] - h, abs=1e-12)
        np.testing.assert_allclose(np.diff(s["t"]), h, rtol=0, atol=1e-12)
        np.testing.assert_array_equal(s["delta_c"], info["rudder_command"])
        # the first sample is the previous step's measurement (measured once per instant)
        assert s["psi"][0] == prev["heading"]
        assert s["r"][0] == prev["yaw_rate"]
        assert s["delta"][0] == prev["rudder_angle"]
        if info["waypoint_index"] == prev["waypoint_index"]:
            assert s["e"][0] == pytest.approx(prev["cross_track_error"], abs=1e-9)
        prev = info
        if case[1] == "rudder":
            assert info["rudder_command"] == pytest.approx(
                float(a[0]) * inner.model.rudder_limit, rel=1e-7
            )
        assert ("episode_metrics" in info) == (terminated or truncated)
        if terminated or truncated:
            break


@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_zero_rudder_episode_ends_with_reason_and_metrics(case: tuple) -> None:
    env = make(case[0], "rudder")
    inner = env.unwrapped
    _, info = env.reset(seed=0)
    rewards, errors = [], []
    max_steps = math.ceil(inner.scenario.config.time_limit / inner.scenario.control_period - 1e-9)
    for _ in range(max_steps):
        _, reward, terminated, truncated, info = env.step(np.zeros(1, dtype=np.float32))
        assert isinstance(reward, float)
        assert type(terminated) is bool and type(truncated) is bool
        rewards.append(reward)
        errors.append(info["cross_track_error"])
        if terminated or truncated:
            break
        assert "episode_metrics" not in info and "termination_reason" not in info
    assert terminated or truncated
    assert not (terminated and truncated)
    reason = info["termination_reason"]
    assert reason in ("corridor", "time_limit")
    assert (reason == "corridor") == terminated
    e_max = inner.scenario.max_cross_track
    if reason == "corridor":
        assert abs(errors[-1]) > e_max
        assert all(abs(e) <= e_max for e in errors[:-1])
    else:
        assert len(rewards) == max_steps
    m = info["episode_metrics"]
    for key in ("ace", "ace_L", "t_c", "return", "success", "max_abs_cross_track", "steps"):
        assert key in m, key
    assert m["steps"] == len(rewards)
    assert m["success"] is False
    assert m["return"] == pytest.approx(sum(rewards), rel=1e-12)
    assert m["max_abs_cross_track"] == pytest.approx(max(abs(e) for e in errors), rel=1e-12)
    assert m["ace_L"] == pytest.approx(m["ace"] / inner.scenario.ship_length, rel=1e-12)
    # a new episode starts clean
    _, info = env.reset(seed=0)
    assert info["t"] == 0.0 and "episode_metrics" not in info


@pytest.mark.parametrize("mode", MODES)
def test_non_finite_plant_terminates_with_a_reason(mode: str) -> None:
    """An extreme jump (β < 0 makes r + βr³ blow up) ends the episode, never NaN silently."""
    env = gym.make(
        "ShipPathFollow-v0", scenario=diverging_scenario(2.0), action_mode=mode, randomize=False
    )
    obs, _ = env.reset(seed=0)
    a = np.ones(env.action_space.shape, dtype=np.float32)
    for _ in range(40):
        obs, reward, terminated, truncated, info = env.step(a)
        assert env.observation_space.contains(obs) and not np.any(np.isnan(obs))
        assert math.isfinite(reward)
        assert all(math.isfinite(info[k]) for k in INFO_FLOATS)
        if terminated or truncated:
            break
    assert terminated and not truncated
    assert info["termination_reason"] == "non_finite_state"
    assert info["t"] > 2.0
    assert "episode_metrics" in info


def diverging_scenario(event_time: float | None) -> dict[str, Any]:
    """nominal with β = −1000, K = 50 (from t = 0, or from an event): the plant blows up."""
    data = load_scenario("nominal").config.model_dump()
    blow_up = {"beta": -1000.0, "K": 50.0}
    if event_time is None:
        data["ship"]["params"].update(blow_up)
    else:
        data["events"] = [{"time": event_time, "params": blow_up}]
    return data


def test_non_finite_terminal_step_is_counted_in_the_metrics() -> None:
    env = gym.make("ShipPathFollow-v0", scenario=diverging_scenario(2.0))
    env.reset(seed=0)
    rewards = []
    while True:
        _, reward, terminated, truncated, info = env.step(np.ones(1, dtype=np.float32))
        rewards.append(reward)
        if terminated or truncated:
            break
    assert info["termination_reason"] == "non_finite_state"
    m = info["episode_metrics"]
    assert m["steps"] == len(rewards)
    assert m["return"] == pytest.approx(sum(rewards), rel=1e-12)


def test_non_finite_on_the_first_step_still_reports_episode_metrics() -> None:
    env = gym.make("ShipPathFollow-v0", scenario=diverging_scenario(None))
    env.reset(seed=0)
    _, reward, terminated, _, info = env.step(np.ones(1, dtype=np.float32))
    assert terminated and info["termination_reason"] == "non_finite_state"
    assert "episode_metrics" in info  # on the last step of an episode
    assert info["episode_metrics"]["return"] == pytest.approx(reward, rel=1e-12)


# --------------------------------------------------------------------------------------------
# Observation
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("case", CASES + NOISY_CASES, ids=case_id)
def test_observation_in_space_for_a_whole_episode(case: tuple) -> None:
    env = make(*case)
    space = env.observation_space
    obs, _ = env.reset(seed=5)
    assert obs.dtype == np.float32 and space.contains(obs)
    sc = env.unwrapped.scenario
    n_steps = math.ceil(sc.config.time_limit / sc.control_period) + 1
    actions = seeded_actions(env.action_space, n_steps, seed=6)
    done = False
    for a in actions:
        obs, reward, terminated, truncated, _ = env.step(a)
        assert obs.dtype == np.float32 and obs.shape == space.shape
        assert not np.any(np.isnan(obs))
        assert space.contains(obs)
        assert math.isfinite(reward)
        if terminated or truncated:
            done = True
            break
    assert done  # more steps than the time limit allows


def test_observation_entries_match_the_documented_layout() -> None:
    env = gym.make("ShipPathFollow-v0", scenario="nominal")
    inner = env.unwrapped
    obs, info = env.reset(seed=0)
    for _ in range(10):
        obs, _, _, _, info = env.step(np.array([0.3], dtype=np.float32))
    L, u0, dmax = inner.scenario.ship_length, inner.model.nominal_speed, inner.model.rudder_limit
    e_max = inner.scenario.max_cross_track
    expected = [
        info["cross_track_error"] / e_max,
        math.sin(info["heading_error"]),
        math.cos(info["heading_error"]),
        info["yaw_rate"] / (2 * u0 / L),
        info["rudder_angle"] / dmax,
        info["rudder_command"] / dmax,
    ]
    np.testing.assert_allclose(obs[:6], np.float32(expected), rtol=1e-6, atol=1e-7)
    assert obs[6] == pytest.approx(1.0, abs=1e-3)  # speed over ground / u0, no current


# --------------------------------------------------------------------------------------------
# Reward
# --------------------------------------------------------------------------------------------


def test_rudder_reward_matches_the_formula_on_nominal() -> None:
    env = gym.make("ShipPathFollow-v0", scenario="nominal", action_mode="rudder")
    inner = env.unwrapped
    cfg = inner.scenario.config.reward
    assert (cfg.heading_weight, cfg.rudder_weight, cfg.rudder_rate_weight) == (0.1, 0.01, 0.05)
    L, dmax = inner.scenario.ship_length, inner.model.rudder_limit
    _, info = env.reset(seed=0)
    prev_dc = info["rudder_command"]
    assert prev_dc == 0.0
    actions = seeded_actions(env.action_space, 60, seed=4)
    checked = 0
    for a in actions:
        a = 0.3 * a  # gentle, so the episode lasts
        _, reward, terminated, truncated, info = env.step(a)
        if terminated or truncated:
            break
        dc = info["rudder_command"]
        expected = -(
            abs(info["cross_track_error"]) / L
            + cfg.heading_weight * abs(info["heading_error"])
            + cfg.rudder_weight * (dc / dmax) ** 2
            + cfg.rudder_rate_weight * ((dc - prev_dc) / dmax) ** 2
        )
        assert reward == pytest.approx(expected, rel=1e-12, abs=1e-15)
        prev_dc = dc
        checked += 1
    assert checked == 60


def test_corridor_exit_penalty() -> None:
    """Leaving the corridor costs (e_max/L)·(steps left) on top of the per-step reward."""
    env = gym.make("ShipPathFollow-v0", scenario="nominal", action_mode="rudder")
    inner = env.unwrapped
    cfg = inner.scenario.config.reward
    L, dmax = inner.scenario.ship_length, inner.model.rudder_limit
    e_max = inner.scenario.max_cross_track
    max_steps = math.ceil(inner.scenario.config.time_limit / inner.scenario.control_period - 1e-9)
    env.reset(seed=0)
    a = np.zeros(1, dtype=np.float32)  # no rudder: the yaw bias d0 turns it out of the corridor
    k, prev_dc = 0, 0.0
    while True:
        k += 1
        _, reward, terminated, truncated, info = env.step(a)
        if terminated or truncated:
            break
        prev_dc = info["rudder_command"]
    assert terminated and info["termination_reason"] == "corridor"
    dc = info["rudder_command"]
    base = -(
        abs(info["cross_track_error"]) / L
        + cfg.heading_weight * abs(info["heading_error"])
        + cfg.rudder_weight * (dc / dmax) ** 2
        + cfg.rudder_rate_weight * ((dc - prev_dc) / dmax) ** 2
    )
    assert reward == pytest.approx(base - (e_max / L) * (max_steps - k), rel=1e-12)


def _run_to_the_end(env: Any, action: np.ndarray) -> tuple[float, dict[str, Any]]:
    """(return, last info) of one episode with a constant action."""
    total = 0.0
    while True:
        _, reward, terminated, truncated, info = env.step(action)
        total += float(reward)
        if terminated or truncated:
            return total, info


@pytest.mark.parametrize(("mode", "reason"), [("guidance", "goal"), ("rudder", "corridor")])
def test_episode_cost_is_minus_the_return_without_the_goal_bonus(mode: str, reason: str) -> None:
    """A real episode: the env's autopilot (guidance mode, a = 0) reaches the goal, no rudder
    leaves the corridor; the metric ``cost`` is −(return − goal bonus if reached), ≥ 0."""
    env = gym.make("ShipPathFollow-v0", scenario="nominal", action_mode=mode)
    bonus = env.unwrapped.scenario.config.reward.goal_bonus
    env.reset(seed=0)
    total, info = _run_to_the_end(env, np.zeros(env.action_space.shape, dtype=np.float32))
    assert info["termination_reason"] == reason
    metrics = info["episode_metrics"]
    assert metrics["return"] == pytest.approx(total, rel=1e-12)
    reached = bonus if reason == "goal" else 0.0
    assert bonus > 0 and metrics["cost"] == pytest.approx(-(total - reached), rel=1e-12)
    assert metrics["cost"] > 0


# --------------------------------------------------------------------------------------------
# Rendering and constructor arguments
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_render_rgb_array(env_id: str) -> None:
    env = gym.make(env_id, render_mode="rgb_array")
    env.reset(seed=0)
    first = env.render()
    assert isinstance(first, np.ndarray) and first.dtype == np.uint8
    assert first.ndim == 3 and first.shape[2] == 3 and first.shape[0] > 50 and first.shape[1] > 50
    assert len(np.unique(first.reshape(-1, 3), axis=0)) > 10  # not blank
    assert np.mean(np.all(first == 255, axis=2)) < 0.99
    for _ in range(20):
        env.step(np.array([0.5], dtype=np.float32))
    second = env.render()
    assert second.shape == first.shape
    assert np.any(second != first)  # the ship moved, the title changed
    env.close()


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_bad_action_mode_raises_naming_it(env_id: str) -> None:
    with pytest.raises(ValueError, match="steering_wheel"):
        gym.make(env_id, action_mode="steering_wheel")


@pytest.mark.filterwarnings("ignore:.*render_mode.*:UserWarning")
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_bad_render_mode_raises_naming_it(env_id: str) -> None:
    with pytest.raises(ValueError, match="hologram"):
        gym.make(env_id, render_mode="hologram")


@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_a_none_action_is_refused_as_no_number(case: tuple) -> None:
    env = make(*case)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"action must be an array of shape \(\d,\), got None"):
        env.step(None)


# --------------------------------------------------------------------------------------------
# An episode abandoned (its controller failed)
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("steps", [0, 4])
def test_abandon_ends_the_episode_with_the_reason_and_the_corridor_penalty(steps: int) -> None:
    """One more step logged, the plant not moved, charged (e_max/L)·(steps left) as a
    non-finite state is; the return is the steps' rewards and that penalty."""
    env = make("ShipPathFollow-v0", "rudder", "rudder_aging")
    env.reset(seed=3)
    rewards = [env.step(np.array([0.2]))[1] for _ in range(steps)]
    base = env.unwrapped
    before = base.pose
    info = base.abandon("controller_error")
    k = core.StepConstants.of(base.scenario)
    penalty = (k.max_cross_track / k.ship_length) * (k.max_steps - steps)
    metrics = info["episode_metrics"]
    assert info["termination_reason"] == "controller_error"
    assert "samples" not in info and base.pose == before
    assert metrics["steps"] == steps + 1 and info["t"] == (steps + 1) * k.control_period
    assert metrics["return"] == pytest.approx(sum(rewards) - penalty, rel=1e-12)
    assert metrics["cost"] == pytest.approx(penalty - sum(rewards), rel=1e-12)
    assert not metrics["success"]
