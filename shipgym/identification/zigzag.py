"""2nd-order Nomoto model from a zig-zag manoeuvre (Xu & Guedes Soares 2020 §5.2).

Eq. (27): T1T2·r̈ + (T1 + T2)·ṙ + r = K·δ + K·T3·δ̇ (+ a constant bias, which absorbs d0).
Euler-discretised at the sampling step h, with x_k = [r_k, ṙ_k, δ_k, δ̇_k] and
y_k = ṙ_{k+1}:

    ṙ_{k+1} = (1 − h·S/P)·ṙ_k − (h/P)·r_k + (h·K/P)·δ_k + (h·K·T3/P)·δ̇_k + h·d0/P

with P = T1·T2, S = T1 + T2.  LS-SVM with a linear kernel and C = 2544 (Luo et al. 2016, as
the paper) gives w; then P = −h/w_r, S = (1 − w_ṙ)·P/h, K = w_δ·P/h, T3 = w_δ̇/w_δ,
d0 = b·P/h and T1 > T2 are the roots of s² − S·s + P = 0.  Derivatives are forward
differences of the sampled r and δ.  The same pipeline gives every model-based controller
its nominal model on ships without a closed-form Nomoto model.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

from shipgym.identification.errors import IdentificationError, check_sampling_step
from shipgym.identification.lssvm import lssvm_primal
from shipgym.identification.nomoto import time_constants
from shipgym.manoeuvres import ManoeuvreLog, zigzag
from shipgym.models.base import ShipModel
from shipgym.models.nomoto2 import Nomoto2Params, nomoto2_first_order

#: regularisation factor of Xu & Guedes Soares (2020) §5.2
C_ZIGZAG = 2544.0


@dataclasses.dataclass(frozen=True)
class NomotoFit:
    """2nd-order Nomoto parameters identified from a manoeuvre (SI, rad)."""

    K: float  # [1/s]
    T1: float  # [s]
    T2: float  # [s]
    T3: float  # [s]
    d0: float  # [rad/s]

    def first_order(self) -> tuple[float, float]:
        """Nomoto's approximation K, T = T1 + T2 − T3."""
        return nomoto2_first_order(self.K, self.T1, self.T2, self.T3)

    def as_nomoto2(self, base: Nomoto2Params | None = None, beta: float = 0.0) -> Nomoto2Params:
        """The fit as a nomoto2 parameter record (servo, speed, length from ``base``)."""
        base = base if base is not None else Nomoto2Params()
        return base.replace(K=self.K, T1=self.T1, T2=self.T2, T3=self.T3, d0=self.d0, beta=beta)


def fit_nomoto_zigzag(r: np.ndarray, delta: np.ndarray, h: float, C: float = C_ZIGZAG) -> NomotoFit:
    """Fit eq. (27) to yaw rate r [rad/s] and rudder angle δ [rad] sampled at h [s]."""
    h = check_sampling_step(h)
    r = np.asarray(r, dtype=float)
    delta = np.asarray(delta, dtype=float)
    if r.shape != delta.shape or r.ndim != 1:
        raise IdentificationError("r and delta must be 1-D arrays of equal length")
    if r.shape[0] < 10:
        raise IdentificationError(f"too few samples for a zig-zag fit: {r.shape[0]} < 10")
    if np.ptp(delta) == 0.0:
        raise IdentificationError("the rudder angle is constant: the zig-zag excites nothing")
    r_dot = np.diff(r) / h
    d_dot = np.diff(delta) / h
    n = r.shape[0] - 2
    x = np.column_stack([r[:n], r_dot[:n], delta[:n], d_dot[:n]])
    y = r_dot[1 : n + 1]
    sol = lssvm_primal(x, y, C)
    w_r, w_rdot, w_d, w_ddot = sol.theta
    if not w_r < 0:
        raise IdentificationError(f"w_r = {w_r:.3g} ≥ 0: T1·T2 would not be positive")
    P = -h / w_r
    S = (1.0 - w_rdot) * P / h
    if w_d == 0:
        raise IdentificationError("K = 0: the rudder has no effect in the data")
    t1, t2 = time_constants(S, P)
    return NomotoFit(
        K=float(w_d * P / h),
        T1=t1,
        T2=t2,
        T3=float(w_ddot / w_d),
        d0=float(sol.bias * P / h),
    )


def zigzag_nomoto(
    model: ShipModel, rudder_deg: float = 20.0, C: float = C_ZIGZAG
) -> tuple[NomotoFit, ManoeuvreLog]:
    """Run a rudder_deg/rudder_deg zig-zag on ``model`` and fit the 2nd-order Nomoto model."""
    log, _ = zigzag(model, rudder_deg)
    return fit_nomoto_zigzag(log.r, log.delta, log.h, C), log


@functools.lru_cache(maxsize=64)
def _cached_fit(cls: type, variant: str | None, params: tuple[float, ...], rudder_deg: float):
    model = cls(cls.params_type.from_vector(params), variant)
    fit, log = zigzag_nomoto(model, rudder_deg)
    return fit, servo_time_constant(log)


def servo_time_constant(log: ManoeuvreLog) -> float:
    """Least-squares Tc [s] of δ̇ = (δc − δ)/Tc from a manoeuvre log (an effective value
    when the real steering gear is rate-limited)."""
    d_dot = np.diff(log.delta) / log.h
    gap = log.delta_c[:-1] - log.delta[:-1]
    denom = float(d_dot @ d_dot)
    if denom == 0.0:
        raise IdentificationError("the rudder never moves: no servo time constant")
    return float(gap @ d_dot) / denom


def ship_nomoto(model: ShipModel, rudder_deg: float = 20.0) -> tuple[NomotoFit, float]:
    """The ship's 2nd-order Nomoto model and servo Tc [s] from its 20/20 zig-zag.

    This is the one pipeline that gives model-based controllers their nominal model on
    ships without a closed-form Nomoto model (Xu & Guedes Soares 2020 §5.2):
    computed from the model's own simulation, never typed in, cached per process for each
    (model, variant, parameters).
    """
    return _cached_fit(
        type(model), model.variant, tuple(model.params.to_vector().tolist()), float(rudder_deg)
    )
