"""The batched env equals N single envs."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import shipgym  # noqa: F401
from shipgym.envs.vector import ShipPathFollowVectorEnv
from shipgym.scenarios.loader import Scenario, load_scenario, scenario_from_dict

N = 4


def sync_twin(
    scenario: str | Scenario, mode: str, randomize: bool = False
) -> gym.vector.SyncVectorEnv:
    return gym.vector.SyncVectorEnv(
        [
            lambda: gym.make(
                "ShipPathFollow-v0", scenario=scenario, action_mode=mode, randomize=randomize
            )
            for _ in range(N)
        ]
    )


def assert_twins_equal(
    scenario: str | Scenario, mode: str, steps: int, seed: int = 3, min_episodes: int = N
) -> None:
    """Same seeds and actions into the batched env and N single envs under SyncVectorEnv:
    observations, rewards, terminations, every info key and every episode metric equal bit
    for bit at every step, through episode ends and NEXT_STEP autoresets."""
    batched = ShipPathFollowVectorEnv(N, scenario, action_mode=mode)
    single = sync_twin(scenario, mode)
    obs_b, info_b = batched.reset(seed=seed)
    obs_s, info_s = single.reset(seed=seed)
    np.testing.assert_array_equal(obs_b, obs_s)
    rng = np.random.default_rng(seed)
    episodes = 0
    n_act = batched.single_action_space.shape[0]
    for _ in range(steps):
        action = rng.uniform(-1, 1, (N, n_act)).astype(np.float32)
        out_b, out_s = batched.step(action), single.step(action)
        for got, want in zip(out_b[:4], out_s[:4], strict=True):
            np.testing.assert_array_equal(got, want)
        info_b, info_s = out_b[4], out_s[4]
        assert set(info_b) == set(info_s) - {"samples", "_samples"}
        for key in info_b:
            if key == "position":
                want = np.array([np.asarray(p, dtype=float) for p in info_s[key]])
                np.testing.assert_array_equal(info_b[key], want)
            elif key == "episode_metrics":
                metrics_b, metrics_s = info_b[key], info_s[key]
                assert set(metrics_b) == set(metrics_s)
                for name in metrics_s:  # SyncVectorEnv's layout and dtypes
                    assert metrics_b[name].dtype == metrics_s[name].dtype, name
                    np.testing.assert_array_equal(metrics_b[name], metrics_s[name], err_msg=name)
            else:
                np.testing.assert_array_equal(info_b[key], info_s[key], err_msg=key)
        episodes += int(np.sum(out_b[2] | out_b[3]))
    assert episodes >= min_episodes  # episodes ended and were reset along the way


@pytest.mark.parametrize("scenario", ["nominal", "rudder_aging", "maneuverability_change"])
def test_batched_env_equals_single_envs_bit_for_bit(scenario: str) -> None:
    """Rudder mode on polylines; the noisy Case 3 included (per-env random streams in the
    single env's order)."""
    assert_twins_equal(scenario, "rudder", 300)


def with_law(scenario: str, law: str, time_limit: float | None = None) -> Scenario:
    """A catalogue scenario with another guidance law and time limit."""
    overrides: dict = {"guidance": {"law": law}}
    if time_limit is not None:
        overrides["time_limit"] = time_limit
    return load_scenario(scenario).with_overrides(overrides, name=f"{scenario}_{law}")


LAWS = ["los", "lookahead_los", "vf", "tvvf"]


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("scenario", ["nominal", "rudder_aging_smooth"])
def test_guidance_mode_equal_bit_for_bit_for_every_law_and_path_type(
    law: str, scenario: str
) -> None:
    """Every guidance law on a polyline and on a PCHIP curve: the law table, the autopilot
    and the tracker run on arrays exactly as on floats (libm's asin/atan/atan2/pow mapped
    over the elements: shipgym.numerics)."""
    assert_twins_equal(with_law(scenario, law, time_limit=60.0), "guidance", 400)


@pytest.mark.parametrize("scenario", ["rudder_aging_smooth", "osaka_curved"])
def test_rudder_mode_equal_bit_for_bit_on_pchip_paths(scenario: str) -> None:
    """The vectorised closest-point projection on PCHIP curves (two ships, two routes)."""
    assert_twins_equal(with_law(scenario, "los", time_limit=40.0), "rudder", 250)


def test_reset_mask_and_step_before_reset() -> None:
    env = ShipPathFollowVectorEnv(3, "nominal")
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.zeros((3, 1), dtype=np.float32))
    env.reset(seed=0)
    for _ in range(5):
        env.step(np.full((3, 1), 0.5, dtype=np.float32))
    moved = env._state.x.copy()
    env.reset(options={"reset_mask": np.array([False, True, False])})
    np.testing.assert_array_equal(env._state.x[[0, 2]], moved[[0, 2]])
    np.testing.assert_array_equal(env._state.x[1], env.scenario.initial_state())


def test_make_vec_uses_the_batched_env_and_rejects_bad_actions() -> None:
    env = gym.make_vec("ShipPathFollow-v0", num_envs=3, vectorization_mode="vector_entry_point")
    assert isinstance(env.unwrapped, ShipPathFollowVectorEnv)
    obs, _ = env.reset(seed=0)
    assert obs.shape == (3, 9) and obs.dtype == np.float32
    before = env.unwrapped._state.x.copy()
    bad = np.zeros((3, 1), dtype=np.float32)
    bad[1, 0] = np.nan
    with pytest.raises(ValueError, match=r"envs \[1\]"):
        env.step(bad)
    np.testing.assert_array_equal(env.unwrapped._state.x, before)


def test_sb3_adapter_trains_ppo_and_autoresets_same_step() -> None:
    """The SB3 VecEnv adapter: terminal observation in info, new episode's obs returned."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env.base_vec_env import VecEnv

    from shipgym_baselines.learned.vec_env import SB3BatchedVecEnv

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
    """Nominal with a saturating Gauss–Markov current, waves and heading noise."""
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


@pytest.mark.parametrize("randomize", [False, True])
def test_batched_env_equals_single_envs_with_stochastic_disturbances(randomize: bool) -> None:
    """Gauss–Markov current (hitting its bounds), waves and sensor noise: each env's noise is
    drawn from its generator in the single env's order, the processes advance over all
    ships at once; equal bit for bit, disturbance blocks included, through autoresets.  With
    ``randomize`` each env's trial has its own current (its own processes)."""
    scenario = stochastic_disturbance_scenario()
    batched = ShipPathFollowVectorEnv(N, scenario, randomize=randomize)
    single = sync_twin(scenario, "rudder", randomize)
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


def test_make_vec_takes_max_episode_steps_like_the_time_limit_wrapper() -> None:
    env = gym.make_vec("ShipPathFollow-v0", num_envs=3, max_episode_steps=50)
    env.reset(seed=0)
    for step in range(1, 51):
        _, _, terminated, truncated, info = env.step(np.zeros((3, 1), dtype=np.float32))
        assert not terminated.any()
        assert truncated.all() == (step == 50)
    assert list(info["termination_reason"]) == ["time_limit"] * 3
    assert (info["episode_metrics"]["steps"] == 50).all()
    with pytest.raises(ValueError, match="max_episode_steps"):
        ShipPathFollowVectorEnv(2, "nominal", max_episode_steps=0)


def test_sb3_adapter_gives_each_env_the_single_env_info_keys() -> None:
    from stable_baselines3.common.vec_env import VecMonitor

    from shipgym_baselines.learned.vec_env import SB3BatchedVecEnv

    env = VecMonitor(
        SB3BatchedVecEnv(ShipPathFollowVectorEnv(N, "nominal")),
        info_keywords=("termination_reason",),
    )
    env.seed(0)
    env.reset()
    single = gym.make("ShipPathFollow-v0", scenario="nominal", randomize=False)
    _, single_info = single.reset(seed=0)
    for _ in range(400):
        env.step_async(np.ones((N, 1), dtype=np.float32))
        _, _, dones, infos = env.step_wait()
        assert set(infos[0]) >= set(single_info) - {"samples"}
        assert isinstance(infos[0]["position"], tuple)
        if dones.any():
            i = int(np.flatnonzero(dones)[0])
            reason = infos[i]["termination_reason"]
            assert reason in ("goal", "corridor", "time_limit")
            assert infos[i]["episode"]["termination_reason"] == reason  # VecMonitor's record
            break
    else:
        pytest.fail("no episode ended")
