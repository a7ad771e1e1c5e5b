"""Continuous least squares for the 1st-order Nomoto model (Borkowski 2018 §3, §4).

Model ṙ = −a·r + c·δ (eq. (31)).  With the filters r_f = r/(1+s), δ_f = δ/(1+s) (eq. (32))
it becomes r = (1 − a)·r_f + c·δ_f (eq. (33)), i.e. x = Φᵀθ with Φ = [r_f, δ_f],
θ = [1 − a, c], x = r (eq. (34)).  The estimator of eq. (12)–(15):

    K̇ = Φ Φᵀ  (K(0) = K0 ≻ 0),     θ̇ = K⁻¹ Φ e,   e = x − Φᵀθ.

Discrete implementation (documented choice): the filters start at zero (the paper's zero
initial conditions) and are advanced exactly for a signal linear between samples
(first-order hold: r_f ← e^{−h}·r_f + b0·r_k + b1·r_{k+1}, b1 = 1 − (1 − e^{−h})/h,
b0 = (1 − e^{−h})/h − e^{−h}); a zero-order hold instead biases a, c by ≈ h/2 relative
(5 % at h = 0.1 s).  Then K ← K + Φ Φᵀ h and θ ← θ + h K⁻¹ Φ e (explicit Euler of
eq. (14)–(15)).  K0 sets how fast the first estimates move (small K0: trust data quickly).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from shipgym.identification.errors import IdentificationError, check_sampling_step


class ContinuousLeastSquares:
    """Streaming estimator of (a [1/s], c [1/s²]) in ṙ = −a·r + c·δ.

    ``update(r, delta)`` takes arrays of yaw rate [rad/s] and rudder angle [rad] sampled at
    h [s]; ``a`` and ``c`` are the current estimates.
    """

    def __init__(self, h: float, a0: float, c0: float, k0: float = 1e-4) -> None:
        h = check_sampling_step(h)
        if not k0 > 0:
            raise IdentificationError(f"need k0 > 0, got k0={k0}")
        self.h = h
        self.theta = np.array([1.0 - a0, c0])
        self.K = k0 * np.eye(2)
        self.r_f = 0.0
        self.delta_f = 0.0
        decay = math.exp(-h)  # filter 1/(1+s), time constant 1 s
        self._decay = decay
        self._b1 = 1.0 - (1.0 - decay) / h
        self._b0 = (1.0 - decay) / h - decay
        self._prev: tuple[float, float] | None = None
        self.history: list[tuple[float, float]] = []

    @property
    def a(self) -> float:
        return float(1.0 - self.theta[0])

    @property
    def c(self) -> float:
        return float(self.theta[1])

    def update(self, r: Any, delta: Any) -> None:
        r = np.atleast_1d(np.asarray(r, dtype=float))
        delta = np.atleast_1d(np.asarray(delta, dtype=float))
        if r.shape != delta.shape:
            raise ValueError("r and delta must have the same length")
        h, decay, b0, b1 = self.h, self._decay, self._b0, self._b1
        # the 2×2 recursion on floats (≈ 10× faster than numpy per sample): K symmetric
        k11, k12, k22 = float(self.K[0, 0]), float(self.K[0, 1]), float(self.K[1, 1])
        t0, t1 = float(self.theta[0]), float(self.theta[1])
        r_f, d_f = self.r_f, self.delta_f
        prev = self._prev
        for rk, dk in zip(r.tolist(), delta.tolist(), strict=True):
            if not (math.isfinite(rk) and math.isfinite(dk)):
                continue  # a dropped sample: skip it, keep the estimate
            if prev is None:  # first sample: filters start from zero
                prev = (rk, dk)
                continue
            rp, dp = prev
            prev = (rk, dk)
            r_f = decay * r_f + b0 * rp + b1 * rk  # eq. (32), first-order hold
            d_f = decay * d_f + b0 * dp + b1 * dk
            k11 += r_f * r_f * h  # eq. (14): K += Φ Φᵀ h
            k12 += r_f * d_f * h
            k22 += d_f * d_f * h
            e = rk - (r_f * t0 + d_f * t1)  # x − Φᵀθ, eq. (33)-(34)
            det = k11 * k22 - k12 * k12
            g0, g1 = r_f * e, d_f * e  # θ += h K⁻¹ Φ e, eq. (15), K⁻¹ in closed form
            t0 += h * (k22 * g0 - k12 * g1) / det
            t1 += h * (k11 * g1 - k12 * g0) / det
        self.r_f, self.delta_f, self._prev = r_f, d_f, prev
        self.K = np.array([[k11, k12], [k12, k22]])
        self.theta = np.array([t0, t1])
        self.history.append((self.a, self.c))
