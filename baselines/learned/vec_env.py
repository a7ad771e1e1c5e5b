"""stable-baselines3 ``VecEnv`` over the batched :class:`ShipPathFollowVectorEnv`.

SB3 does not accept Gymnasium vector envs: this adapter exposes the batched env
through SB3's interface, with SB3's same-step autoreset (the terminal observation goes to
``info["terminal_observation"]``, truncation to ``info["TimeLimit.truncated"]``) and one
``info`` dict per ship with the keys a single env gives (``termination_reason`` and
``episode_metrics`` at episode ends, so ``VecMonitor(info_keywords=...)`` works; ``position``
as an (x, y) tuple; no ``samples``).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from stable_baselines3.common.vec_env.base_vec_env import VecEnv

from shipgym.envs.vector import ShipPathFollowVectorEnv


def sb3_step(env: Any, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, list]:
    """One step of a batched env (``reset_finished`` after an episode end) in SB3's terms:
    (observations, rewards, dones, per-env infos with ``terminal_observation`` and
    ``TimeLimit.truncated``); the envs that ended are reset at once, as SB3 expects."""
    obs, rewards, terminated, truncated, info = env.step(actions)
    dones = terminated | truncated
    infos = per_env_infos(info, env.num_envs)
    for i in np.flatnonzero(dones):
        infos[i]["terminal_observation"] = obs[i].copy()
        infos[i]["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
    if np.any(dones):
        obs, _ = env.reset_finished()
    return obs, rewards, dones, infos


def per_env_infos(info: dict[str, Any], n: int) -> list[dict[str, Any]]:
    """A Gymnasium vector ``info`` (arrays with ``_key`` masks) as n per-env dicts."""
    infos: list[dict[str, Any]] = [{} for _ in range(n)]
    for key, value in info.items():
        if key.startswith("_"):
            continue
        mask = info.get(f"_{key}")
        rows = range(n) if mask is None else np.flatnonzero(mask).tolist()
        if isinstance(value, dict):
            nested = per_env_infos(value, n)
            for i in rows:
                infos[i][key] = nested[i]
        elif key == "position":
            for i, (x, y) in zip(rows, value[list(rows)].tolist(), strict=True):
                infos[i][key] = (x, y)
        else:
            column = value.tolist() if isinstance(value, np.ndarray) else list(value)
            for i in rows:
                infos[i][key] = column[i]
    return infos


class SB3BatchedVecEnv(VecEnv):
    """All N ships in one call, as an SB3 VecEnv."""

    def __init__(self, env: ShipPathFollowVectorEnv) -> None:
        self.env = env
        env.episode_metrics = False  # SB3 does not read them; saves ≈ 0.2 ms per episode
        super().__init__(env.num_envs, env.single_observation_space, env.single_action_space)
        self._actions: np.ndarray | None = None
        self._seed: int | None = None

    def reset(self) -> np.ndarray:
        obs, _ = self.env.reset(seed=self._seed)
        self._seed = None
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions, dtype=np.float32).reshape(self.env.action_space.shape)

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        obs, rewards, dones, infos = sb3_step(self.env, self._actions)
        return obs, rewards.astype(np.float32), dones, infos

    def seed(self, seed: int | None = None) -> list[int | None]:
        self._seed = seed
        return [None if seed is None else seed + i for i in range(self.num_envs)]

    def close(self) -> None:
        return None

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        """Attributes are shared by all ships of the batched env."""
        return [getattr(self.env, attr_name)] * len(self._indices(indices))

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        self._all(indices, "set_attr")
        setattr(self.env, attr_name, value)

    def env_method(self, method_name: str, *args: Any, indices: Any = None, **kwargs: Any) -> list:
        self._all(indices, "env_method")
        return [getattr(self.env, method_name)(*args, **kwargs)] * self.num_envs

    def _all(self, indices: Any, what: str) -> None:
        if sorted(self._indices(indices)) != list(range(self.num_envs)):
            raise ValueError(f"{what}: the batched env acts on all ships at once, not on {indices}")

    def env_is_wrapped(self, wrapper_class: type, indices: Any = None) -> list[bool]:
        return [False] * len(self._indices(indices))

    def _indices(self, indices: Any) -> list[int]:
        if indices is None:
            return list(range(self.num_envs))
        return [indices] if isinstance(indices, int) else list(indices)


class SB3ShipsVecEnv(VecEnv):
    """Several Gymnasium vector envs (e.g. one
    :class:`~shipgym.envs.ship_batch.ShipTrialsVectorEnv` per ship) as one SB3 VecEnv:
    their envs concatenated in order, each stepped in one call, with SB3's same-step
    autoreset (as :class:`SB3BatchedVecEnv`).  ``seed(s)``: env g of the whole gets s + g."""

    def __init__(self, envs: list[Any]) -> None:
        if not envs:
            raise ValueError("SB3ShipsVecEnv needs at least one vector env")
        self.envs = list(envs)
        first = self.envs[0]
        for env in self.envs[1:]:
            if (
                env.single_observation_space != first.single_observation_space
                or env.single_action_space != first.single_action_space
            ):
                raise ValueError("the vector envs must share observation and action spaces")
        self._sizes = [env.num_envs for env in self.envs]
        self._bounds = np.cumsum([0, *self._sizes])
        super().__init__(
            int(self._bounds[-1]), first.single_observation_space, first.single_action_space
        )
        self._actions: np.ndarray | None = None
        self._seed: int | None = None

    def reset(self) -> np.ndarray:
        obs = []
        for env, start in zip(self.envs, self._bounds[:-1], strict=False):
            seed = None if self._seed is None else self._seed + int(start)
            obs.append(env.reset(seed=seed)[0])
        self._seed = None
        return np.concatenate(obs)

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions, dtype=np.float32).reshape(
            (self.num_envs, *self.action_space.shape)
        )

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        all_obs, all_rewards, all_dones, all_infos = [], [], [], []
        for env, lo, hi in zip(self.envs, self._bounds[:-1], self._bounds[1:], strict=False):
            obs, rewards, dones, infos = sb3_step(env, self._actions[lo:hi])
            all_obs.append(obs)
            all_rewards.append(rewards)
            all_dones.append(dones)
            all_infos.extend(infos)
        return (
            np.concatenate(all_obs),
            np.concatenate(all_rewards).astype(np.float32),
            np.concatenate(all_dones),
            all_infos,
        )

    def seed(self, seed: int | None = None) -> list[int | None]:
        self._seed = seed
        return [None if seed is None else seed + i for i in range(self.num_envs)]

    def close(self) -> None:
        for env in self.envs:
            env.close()

    def _owners(self, indices: Any) -> list[Any]:
        idx = range(self.num_envs) if indices is None else indices
        idx = [idx] if isinstance(idx, int) else list(idx)
        return [self.envs[int(np.searchsorted(self._bounds, i, side="right")) - 1] for i in idx]

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        """An attribute of the vector env each env belongs to."""
        return [getattr(env, attr_name) for env in self._owners(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        if indices is not None:
            raise ValueError("set_attr: the ship envs act on all their envs at once")
        for env in self.envs:
            setattr(env, attr_name, value)

    def env_method(self, method_name: str, *args: Any, indices: Any = None, **kwargs: Any) -> list:
        if indices is not None:
            raise ValueError("env_method: the ship envs act on all their envs at once")
        return [getattr(env, method_name)(*args, **kwargs) for env in self.envs]

    def env_is_wrapped(self, wrapper_class: type, indices: Any = None) -> list[bool]:
        return [False] * len(self._owners(indices))
