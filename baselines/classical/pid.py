"""PID heading autopilot on LOS guidance (``pid_los``).

The heading reference is Liu et al. (2019) LOS (eq. (9), (12)) on the active leg, computed
from the measured position with the same path tracker the env uses; the autopilot is the
shared :class:`shipgym.autopilot.HeadingPID`, pole-placed on the nominal model's first-order
Nomoto approximation (ωn = 1 rad/s, ζ = 1 by default; the Vyshnegradsky tuning of
Xu & Guedes Soares (2020) comes with its own controller).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from shipgym.autopilot import HeadingPID, PIDGains
from shipgym.envs.context import ControllerContext
from shipgym.guidance import los_desired_heading


class PIDLOS:
    name = "pid_los"
    kind = "classical"

    def __init__(self, natural_frequency: float = 1.0, damping: float = 1.0) -> None:
        self.natural_frequency = natural_frequency
        self.damping = damping

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        if context.action_mode != "rudder":
            raise ValueError("pid_los drives the rudder; make the env with action_mode='rudder'")
        self.ctx = context
        K, T = context.nominal_model.first_order_nomoto()
        gains = PIDGains.from_nomoto(K, T, self.natural_frequency, self.damping)
        self.pid = HeadingPID(gains, context.rudder_limit)
        self.tracker = context.new_tracker()
        self._started = False

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        x, y = info["position"]
        frame = self.tracker.update(x, y) if self._started else self.tracker.reset(x, y)
        self._started = True
        desired = los_desired_heading(
            frame.cross_track, frame.path_angle, self.ctx.ship_length, self.ctx.los_radius_L
        )
        delta_c = self.pid.command(
            desired, info["heading"], info["yaw_rate"], self.ctx.control_period
        )
        return np.array([delta_c / self.ctx.rudder_limit], dtype=np.float32)
