"""What a fresh process does with an env id: imports gymnasium only, never shipgym (so the
id alone must bring the package in).  Run in spawned workers by ``test_conformance``."""

from __future__ import annotations

import sys
from typing import Any

import gymnasium as gym
import numpy as np


def make_and_step(env_id: str, seed: int) -> dict[str, Any]:
    """Make ``env_id``, reset it with ``seed`` and take one zero-rudder step; returns the
    observations and whether shipgym was imported before ``gym.make``."""
    imported_before = "shipgym" in sys.modules
    env = gym.make(env_id)
    obs, _ = env.reset(seed=seed)
    next_obs, reward, *_ = env.step(np.zeros(env.action_space.shape, dtype=np.float32))
    env.close()
    return {"imported_before": imported_before, "obs": obs, "next_obs": next_obs, "reward": reward}
