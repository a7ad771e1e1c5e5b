"""Reference policies that bound the table from below: zero rudder and random rudder."""

from __future__ import annotations

from typing import Any

import numpy as np

from shipgym.envs.context import ControllerContext


class ZeroRudder:
    """Always commands zero (rudder mode) / the default guidance action."""

    name = "zero_rudder"
    kind = "reference"  # shown on every scenario, never ranked as a competitor

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        self._dim = 1 if context.action_mode == "rudder" else 2

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        return np.zeros(self._dim, dtype=np.float32)


class RandomRudder:
    """Uniform random action in [-1, 1], seeded per episode."""

    name = "random"
    kind = "reference"  # shown on every scenario, never ranked as a competitor

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        self._dim = 1 if context.action_mode == "rudder" else 2
        self._rng = np.random.default_rng(seed)

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        return self._rng.uniform(-1.0, 1.0, self._dim).astype(np.float32)
