"""Xu et al. (2021) §5: the true current of an episode, read from the env's own log.

After each episode the reproduction reads ``env.unwrapped.episode_disturbances()``: the
fine sample times ``"t"`` (h apart, the grid of ``info["samples"]["t"]``) and the value of
every disturbance the plant saw there.  It is read after the episode, never by a
controller (the policy sees only the measurements).
"""

from __future__ import annotations

from typing import Any

import numpy as np


class DisturbanceLog:
    """``after_episode`` hook of :func:`shipgym_baselines.evaluation.run_episode`: keeps, per
    episode, the disturbances the plant saw (name -> values at ``"t"`` [s])."""

    def __init__(self) -> None:
        self.episodes: list[dict[str, np.ndarray]] = []

    def read(self, env: Any) -> None:
        """Store ``env``'s (the unwrapped env's) disturbance log of the episode just run."""
        self.episodes.append(env.episode_disturbances())


def current_speed(disturbances: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """(t [s], current speed [m/s]) of a disturbance log (:class:`DisturbanceLog`)."""
    return disturbances["t"], np.hypot(disturbances["current_x"], disturbances["current_y"])
