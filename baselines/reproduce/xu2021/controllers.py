"""Xu et al. (2021) §5.2: the four controllers, and a wrapper recording what each used."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from shipgym.angles import wrap_angle
from shipgym_baselines.classical.l1_backstepping import AdaptiveBackstepping, L1Backstepping
from shipgym_baselines.classical.pid import PIDTVVF

L1 = "l1_backstepping"
L1_ADAPTIVE = "l1_backstepping_adaptive_filter"
AB = "adaptive_backstepping"
PID = "pid_tvvf"


#: label -> factory (the papers' designs, never the tuned settings)
CONTROLLERS: dict[str, Callable[[], Any]] = {
    L1: lambda: L1Backstepping(preset="paper"),
    L1_ADAPTIVE: lambda: L1Backstepping(preset="paper", filter_placement="adaptive"),
    AB: lambda: AdaptiveBackstepping(preset="paper"),
    PID: lambda: PIDTVVF(preset="paper"),
}
L1_VARIANTS = (L1, L1_ADAPTIVE)


class Recorded:
    """A policy wrapper logging, at each act, t, the heading error to the controller's own
    reference ψ − ψd [rad] and the bias estimate b̂ [rad/s] (NaN for the PID)."""

    def __init__(self, policy: Any, label: str) -> None:
        self.inner, self.label = policy, label
        self.name, self.kind = policy.name, policy.kind
        self.log: dict[str, list[float]] = {"t": [], "ref_error": [], "b_hat": []}

    def reset(self, context: Any, seed: int | None = None) -> None:
        self.inner.reset(context, seed)
        self.log = {k: [] for k in self.log}

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        action = self.inner.act(obs, info)
        p = self.inner
        if isinstance(p, L1Backstepping):
            ref_error, b_hat = p.history["z1"][-1], p.history["b"][-1]
        else:  # the PID's reference from the frame it just used
            f = p.tracker.frame
            ref_error = float(
                wrap_angle(info["heading"] - p.desired_heading(f.cross_track, f.path_angle))
            )
            b_hat = math.nan
        self.log["t"].append(float(info["t"]))
        self.log["ref_error"].append(float(ref_error))
        self.log["b_hat"].append(float(b_hat))
        return action

    def episode_stats(self) -> dict[str, Any]:
        stats = getattr(self.inner, "episode_stats", None)
        return stats() if stats is not None else {}
