"""The true plant at one instant: what only the privileged ``oracle`` reference may read.

No controller sees any of this (the controller context holds the nominal model, ``info``
the measurements).  The evaluation loop hands it, through one explicit channel, to the
built-in ``oracle`` reference alone (``shipgym_baselines.privileged``), so that the leaderboard can
say what is achievable on a scenario when the plant is known.

* ``params``: the true parameters acting now (after every jump so far; never the future
  schedule).
* ``state``: the true plant state (SI, rad).
* the disturbance forecast :meth:`PlantTruth.disturbance_forecast`: the deterministic part
  of the disturbances (the mean current, with a scheduled two-phase switch, and the yaw
  bias that follows it) at future times, plus the present stochastic deviation (current
  fluctuation, wave load) held constant over the horizon.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from shipgym.models.base import ParameterRecord


@dataclasses.dataclass(frozen=True)
class PlantTruth:
    """The true plant at time ``t`` [s] (module doc)."""

    t: float
    state: np.ndarray  # (n_x,) true state, SI / rad
    params: ParameterRecord  # the true parameters acting at t
    disturbance_now: np.ndarray  # (n_w,) disturbances acting at t
    mean_disturbance: Callable[[np.ndarray], np.ndarray]  # times (k,) [s] -> (k, n_w)

    def disturbance_forecast(self, times: np.ndarray) -> np.ndarray:
        """(k, n_w) disturbances at ``times`` [s]: the deterministic mean there plus the
        present stochastic deviation, held."""
        times = np.asarray(times, dtype=float)
        deviation = self.disturbance_now - self.mean_disturbance(np.array([self.t]))[0]
        return self.mean_disturbance(times) + deviation[None, :]
