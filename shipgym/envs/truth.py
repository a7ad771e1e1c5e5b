"""The true plant at one instant: what only the privileged references may read.

No controller sees any of this (the controller context holds the nominal model, ``info``
the measurements).  The evaluation loop hands it, through one explicit channel, to the
built-in references ``oracle`` and ``oracle_frozen`` alone (``shipgym_baselines.privileged``),
so that the leaderboard can say what is achievable on a scenario when the plant is known.

It is causal: the plant *now*, never its future.

* ``params``: the true parameters acting now (after every jump so far; never the
  schedule of jumps to come).
* ``state``: the true plant state (SI, rad).
* ``disturbance_now``: the disturbances acting now (the current, the wave load and the yaw
  bias); never the scheduled current ahead.
* ``wave_now``: the wave load's part of ``disturbance_now`` (zero without waves): a
  zero-mean load that oscillates with the sea's period (seconds), unlike the current.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from shipgym.models.base import ParameterRecord


@dataclasses.dataclass(frozen=True)
class PlantTruth:
    """The true plant at time ``t`` [s] (module doc)."""

    t: float
    state: np.ndarray  # (n_x,) true state, SI / rad
    params: ParameterRecord  # the true parameters acting at t
    disturbance_now: np.ndarray  # (n_w,) disturbances acting at t, model.disturbance_names
    wave_now: np.ndarray | None = None  # (n_w,) the wave load's part of it (None: no waves)

    @property
    def without_waves(self) -> np.ndarray:
        """(n_w,) the disturbances acting now less the wave load: the current and the yaw
        bias as they act now."""
        return (
            self.disturbance_now if self.wave_now is None else self.disturbance_now - self.wave_now
        )
