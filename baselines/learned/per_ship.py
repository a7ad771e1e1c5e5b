"""Per-ship discount in physical time and per-ship reward normalisation (training options).

One γ per control step means a different horizon in seconds on every ship (γ = 0.99 is
≈ 100 control steps: 50 s on nomoto2, 100 s on Mariner).  ``env.gamma_seconds = τ`` [s]
gives each ship γ = exp(−Ts/τ) (:func:`ship_gamma`), the same horizon τ in time.
``env.normalize_per_ship`` scales each ship's rewards by its own running return standard
deviation (:class:`VecNormalizePerShip`) instead of one scale over all ships, whose episode
returns differ by orders of magnitude.  Both need the per-ship batched envs
(``vec_env: batched`` on a distribution), whose env order gives each env's ship.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from stable_baselines3.common.running_mean_std import RunningMeanStd
from stable_baselines3.common.vec_env.base_vec_env import VecEnvWrapper


def ship_gamma(control_period: float, tau: float) -> float:
    """γ = exp(−Ts/τ) for control period Ts [s] and horizon τ [s]: a reward t seconds ahead
    is weighted exp(−t/τ) on every ship."""
    if not (control_period > 0 and tau > 0):
        raise ValueError(f"need Ts > 0 and tau > 0, got Ts={control_period}, tau={tau}")
    return math.exp(-control_period / tau)


def env_gammas(ship_envs: list[Any], tau: float) -> np.ndarray:
    """(n_envs,) γ of each env of the concatenated ship envs (each with ``num_envs`` and its
    ship's ``control_period`` in ``_k0``)."""
    return np.concatenate(
        [np.full(env.num_envs, ship_gamma(env._k0.control_period, tau)) for env in ship_envs]
    )


def ship_groups(ship_envs: list[Any]) -> np.ndarray:
    """(n_envs,) ship index of each env of the concatenated ship envs."""
    return np.concatenate([np.full(env.num_envs, k) for k, env in enumerate(ship_envs)])


class VecNormalizePerShip(VecEnvWrapper):
    """Reward normalisation as SB3's VecNormalize (reward / std of the discounted return,
    clipped), with one running return statistic per ship and each env's own γ."""

    def __init__(
        self,
        venv: Any,
        groups: np.ndarray,
        gammas: np.ndarray | float,
        clip_reward: float = 10.0,
        epsilon: float = 1e-8,
    ) -> None:
        super().__init__(venv)
        self.groups = np.asarray(groups, dtype=np.int64)
        if self.groups.shape != (venv.num_envs,):
            raise ValueError(f"groups must have shape ({venv.num_envs},)")
        self.gammas = np.broadcast_to(np.asarray(gammas, dtype=float), (venv.num_envs,)).copy()
        self.ret_rms = [RunningMeanStd(shape=()) for _ in range(int(self.groups.max()) + 1)]
        self.returns = np.zeros(venv.num_envs)
        self.clip_reward, self.epsilon = clip_reward, epsilon
        self.training = True

    def reset(self) -> np.ndarray:
        self.returns[:] = 0.0
        return self.venv.reset()

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        obs, rewards, dones, infos = self.venv.step_wait()
        self.returns = self.returns * self.gammas + rewards
        if self.training:
            for k, rms in enumerate(self.ret_rms):
                rms.update(self.returns[self.groups == k])
        scale = np.sqrt(np.array([rms.var for rms in self.ret_rms])[self.groups] + self.epsilon)
        normalized = np.clip(rewards / scale, -self.clip_reward, self.clip_reward)
        self.returns[dones] = 0.0
        return obs, normalized.astype(np.float32), dones, infos
