"""The batched env equals N single envs (SPEC §5 batched simulation)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import shipgym  # noqa: F401
from shipgym.envs.vector import ShipPathFollowVectorEnv
from shipgym.scenarios import Scenario, load_scenario
from shipgym.scenarios.loader import scenario_from_dict

N = 4


def sync_twin(scenario: str | Scenario, mode: str) -> gym.vector.SyncVectorEnv:
    return gym.vector.SyncVectorEnv(
        [
            lambda: gym.make("ShipPathFollow-v0", scenario=scenario, action_mode=mode)
            for _ in range(N)
        ]
    )


@pytest.mark.parametrize("scenario", ["nominal", "rudder_aging", "maneuverability_change"])
def test_batched_env_equals_single_envs_bit_for_bit(scenario: str) -> None:
    """Rudder mode, same seeds and actions, through episode ends and autoresets; the noisy
    Case 3 included (per-env random streams in the single env's order)."""
    batched = ShipPathFollowVectorEnv(N, scenario)
    single = sync_twin(scenario, "rudder")
    obs_b, _ = batched.reset(seed=3)
    obs_s, _ = single.reset(seed=3)
    np.testing.assert_array_equal(obs_b, obs_s)
    rng = np.random.default_rng(0)
    finished = 0
    for _ in range(300):
        action = rng.uniform(-1, 1, (N, 1)).astype(np.float32)
        out_b, out_s = batched.step(action), single.step(action)
        for got, want in zip(out_b[:4], out_s[:4], strict=True):
            np.testing.assert_array_equal(got, want)
        for key in ("t", "cross_track_error", "heading", "yaw_rate", "rudder_angle"):
            np.testing.assert_array_equal(out_b[4][key], out_s[4][key])
        positions = np.array([np.asarray(pos, dtype=float) for pos in out_s[4]["position"]])
        np.testing.assert_array_equal(out_b[4]["position"], positions)
        if "episode_metrics" in out_s[4]:
            for i in np.flatnonzero(out_s[4]["_episode_metrics"]):
                finished += 1
                for key in ("ace", "return", "steps", "max_abs_cross_track"):
                    got = out_b[4]["episode_metrics"][key][i]  # SyncVectorEnv's layout
                    assert got == out_s[4]["episode_metrics"][key][i]
    assert finished >= N  # episodes ended and were reset along the way


def nominal_with_law(law: str) -> Scenario:
    """The nominal scenario with another guidance law (vector-field laws, SPEC §3)."""
    data = load_scenario("nominal").config.model_dump()
    data["name"] = f"nominal_{law}"
    data["guidance"] = {"law": law}
    return scenario_from_dict(data)


@pytest.mark.parametrize("law", ["los", "vf", "tvvf"])
def test_guidance_mode_matches_to_rounding_through_autoresets(law: str) -> None:
    """Guidance mode uses numpy's arcsin/power (SIMD, last-ulp differences from libm); on a
    non-chaotic scenario the two stay equal to rounding through episode ends and resets."""
    scenario = "nominal" if law == "los" else nominal_with_law(law)
    batched = ShipPathFollowVectorEnv(N, scenario, action_mode="guidance")
    single = sync_twin(scenario, "guidance")
    assert batched.scenario.config.guidance.law == law
    batched.reset(seed=1)
    single.reset(seed=1)
    rng = np.random.default_rng(2)
    resets = 0
    for _ in range(600):
        action = rng.uniform(-1.0, 1.0, (N, 2)).astype(np.float32)
        out_b, out_s = batched.step(action), single.step(action)
        np.testing.assert_allclose(out_b[0], out_s[0], rtol=0, atol=1e-5)
        np.testing.assert_allclose(out_b[1], out_s[1], rtol=1e-7, atol=1e-9)
        np.testing.assert_array_equal(out_b[2], out_s[2])
        np.testing.assert_array_equal(out_b[3], out_s[3])
        resets += int(np.sum(out_b[2] | out_b[3]))
    assert resets >= N


def test_reset_mask_and_step_before_reset() -> None:
    env = ShipPathFollowVectorEnv(3, "nominal")
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.zeros((3, 1), dtype=np.float32))
    env.reset(seed=0)
    for _ in range(5):
        env.step(np.full((3, 1), 0.5, dtype=np.float32))
    moved = env._state.copy()
    env.reset(options={"reset_mask": np.array([False, True, False])})
    np.testing.assert_array_equal(env._state[[0, 2]], moved[[0, 2]])
    np.testing.assert_array_equal(env._state[1], env.scenario.initial_state())


def test_make_vec_uses_the_batched_env_and_rejects_bad_actions() -> None:
    env = gym.make_vec("ShipPathFollow-v0", num_envs=3, vectorization_mode="vector_entry_point")
    assert isinstance(env.unwrapped, ShipPathFollowVectorEnv)
    obs, _ = env.reset(seed=0)
    assert obs.shape == (3, 9) and obs.dtype == np.float32
    before = env.unwrapped._state.copy()
    bad = np.zeros((3, 1), dtype=np.float32)
    bad[1, 0] = np.nan
    with pytest.raises(ValueError, match=r"envs \[1\]"):
        env.step(bad)
    np.testing.assert_array_equal(env.unwrapped._state, before)


def test_pchip_scenarios_are_refused_with_a_clear_error() -> None:
    with pytest.raises(ValueError, match="waypoint paths only"):
        ShipPathFollowVectorEnv(2, "rudder_aging_smooth")


def test_sb3_adapter_trains_ppo_and_autoresets_same_step() -> None:
    """The SB3 VecEnv adapter: terminal observation in info, new episode's obs returned."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env.base_vec_env import VecEnv

    from baselines.learned.vec_env import SB3BatchedVecEnv

    env = SB3BatchedVecEnv(ShipPathFollowVectorEnv(N, "nominal"))
    assert isinstance(env, VecEnv)
    env.seed(0)
    obs = env.reset()
    # drive every ship out of its corridor with full rudder: episodes end, envs restart
    for _ in range(200):
        env.step_async(np.ones((N, 1), dtype=np.float32))
        obs, _, dones, infos = env.step_wait()
        if dones.any():
            i = int(np.flatnonzero(dones)[0])
            assert "terminal_observation" in infos[i]
            assert not np.array_equal(infos[i]["terminal_observation"], obs[i])
            break
    else:
        pytest.fail("no episode ended")
    model = PPO("MlpPolicy", env, n_steps=32, batch_size=64, n_epochs=1, seed=0, device="cpu")
    model.learn(256)
    assert model.num_timesteps >= 256


def stochastic_disturbance_scenario() -> Scenario:
    """Nominal with a saturating Gauss–Markov current, waves and heading noise (SPEC §4)."""
    data = load_scenario("nominal").config.model_dump()
    data["name"] = "nominal_stochastic_disturbances"
    data["time_limit"] = 15.0  # short episodes: autoresets re-draw the initial states
    data["sensors"] = {"heading_noise_deg": 0.2}
    data["disturbances"] = {
        "current": {
            "kind": "gauss_markov",
            "speed": 0.1,
            "direction_deg": 90.0,
            "mu": 0.1,
            "sigma": 0.03,
            "max_speed": 0.15,
            "direction_sigma_deg": 2.0,
            "direction_max_deviation_deg": 10.0,
        },
        "waves": {"wind_speed": 1.0, "gain": 1.0},
    }
    return scenario_from_dict(data)


def test_batched_env_equals_single_envs_with_stochastic_disturbances() -> None:
    """Gauss–Markov current (hitting its bounds), waves and sensor noise: each env's noise is
    drawn from its generator in the single env's order, the processes advance over all
    ships at once; equal bit for bit, disturbance blocks included, through autoresets."""
    scenario = stochastic_disturbance_scenario()
    batched = ShipPathFollowVectorEnv(N, scenario)
    single = sync_twin(scenario, "rudder")
    np.testing.assert_array_equal(batched.reset(seed=5)[0], single.reset(seed=5)[0])
    rng = np.random.default_rng(1)
    resets = 0
    for _ in range(100):
        action = rng.uniform(-1, 1, (N, 1)).astype(np.float32)
        out_b, out_s = batched.step(action), single.step(action)
        for got, want in zip(out_b[:4], out_s[:4], strict=True):
            np.testing.assert_array_equal(got, want)
        for i, env in enumerate(single.envs):
            np.testing.assert_array_equal(batched._w_block[i], env.unwrapped._w_block)
        resets += int(np.sum(out_b[2] | out_b[3]))
    assert resets >= N
    speed = np.hypot(batched._w_block[..., 0], batched._w_block[..., 1])
    assert np.ptp(batched._w_block[..., 2]) > 0 and speed.max() <= 0.15 + 1e-15
