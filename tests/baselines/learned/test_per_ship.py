"""Per-ship batched training envs, discount in physical time and reward normalisation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym_baselines.learned.per_ship import VecNormalizePerShip, env_gammas, ship_gamma
from shipgym_baselines.training.agents import (
    AgentConfig,
    load_agent_config,
    make_ship_envs,
    make_training_env,
    ship_env_counts,
)


def test_ship_gamma_is_a_horizon_in_seconds() -> None:
    # τ/Ts steps of γ = exp(−Ts/τ) weigh e⁻¹, on any ship
    for ts, tau in ((0.5, 50.0), (1.0, 50.0), (0.1, 20.0)):
        g = ship_gamma(ts, tau)
        assert g ** (tau / ts) == pytest.approx(math.exp(-1))
    assert ship_gamma(0.5, 49.75) == pytest.approx(0.99, abs=1e-4)
    with pytest.raises(ValueError):
        ship_gamma(0.5, 0.0)


def test_ship_env_counts() -> None:
    assert ship_env_counts(8, 4) == [2, 2, 2, 2]
    with pytest.raises(ValueError, match="multiple of 4"):
        ship_env_counts(6, 4)
    data = load_agent_config("ppo").model_dump()
    data["env"].update(vec_env="batched", n_envs=6)
    with pytest.raises(ValueError, match="n_envs 6"):
        AgentConfig.model_validate(data)


def _batched_config(**env: object) -> AgentConfig:
    base = load_agent_config("ppo")
    data = base.model_dump()
    data["env"].update(vec_env="batched", **env)
    return AgentConfig.model_validate(data)


def test_batched_training_env_spans_the_ships_with_their_gammas() -> None:
    config = _batched_config(context_features=True)
    envs = make_ship_envs(config.env)
    assert [e.ship for e in envs] == ["nomoto2", "esso_osaka", "mariner", "blanke"]
    gammas = env_gammas(envs, 50.0)
    want = [math.exp(-e._k0.control_period / 50.0) for e in envs for _ in range(e.num_envs)]
    np.testing.assert_allclose(gammas, want)
    venv = make_training_env(config.env, seed=3)
    obs = venv.reset()
    assert obs.shape == (8, 16)
    # env g of the whole is seeded 3 + g: ship k's first env is env 2k
    assert envs[1].ship_index == 1
    inner = venv.venv
    assert [e.trial_scenarios[0].config.ship.model for e in inner.envs] == [e.ship for e in envs]
    for _ in range(5):
        obs, rewards, _dones, infos = venv.step(np.zeros((8, 1), dtype=np.float32))
    assert obs.shape == (8, 16) and rewards.shape == (8,) and len(infos) == 8


def test_per_ship_options_need_the_batched_ship_envs() -> None:
    base = load_agent_config("ppo").model_dump()
    base["env"].update(gamma_seconds=30.0)
    with pytest.raises(Exception, match="per ship"):
        AgentConfig.model_validate(base)
    sac = load_agent_config("sac").model_dump()
    sac["env"].update(vec_env="batched", gamma_seconds=30.0, n_envs=4)
    with pytest.raises(Exception, match="on-policy"):
        AgentConfig.model_validate(sac)
    assert _batched_config(gamma_seconds=30.0, normalize_per_ship=True).env.gamma_seconds == 30.0


class _Constant:
    """A 4-env VecEnv stand-in: ships 0 and 1, rewards 1 and 100 every step."""

    num_envs = 4
    observation_space = action_space = None
    render_mode = None

    def step_async(self, actions):
        pass

    def step_wait(self):
        r = np.array([1.0, 1.0, 100.0, 100.0], dtype=np.float32)
        return np.zeros((4, 1)), r, np.zeros(4, dtype=bool), [{}] * 4

    def reset(self):
        return np.zeros((4, 1))


def test_per_ship_normalisation_scales_each_ship_by_its_own_returns() -> None:
    import gymnasium as gym

    inner = _Constant()
    inner.observation_space = gym.spaces.Box(-1, 1, (1,))
    inner.action_space = gym.spaces.Box(-1, 1, (1,))
    venv = VecNormalizePerShip(inner, np.array([0, 0, 1, 1]), 0.9)
    venv.reset()
    for _ in range(200):
        _, r, _, _ = venv.step(np.zeros((4, 1)))
    # each ship's normalised reward is the same: the scale is the ship's own
    assert r[0] == pytest.approx(r[2], rel=1e-3)
    assert 0 < r[0] < 10
