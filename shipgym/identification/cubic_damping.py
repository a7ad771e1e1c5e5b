"""Cubic yaw damping of a first-order Nomoto model from a zig-zag manoeuvre.

The model T·ṙ + H(r)·r = K·δ + b with H(r) = 1 + a2·r², i.e. T·ṙ + r + a2·r³ = K·δ + b
(Xu, Oliveira & Guedes Soares 2021 eq. (15), "positive nonlinear damping"), with K and T
held at values identified before (e.g. Nomoto's reduction of the 2nd-order fit of
:mod:`shipgym.identification.zigzag`): a2 ≥ 0 and the bias b are the bounded linear
least-squares solution (scipy ``lsq_linear``) of

    a2·r³ − b = K·δ − T·ṙ − r

over the log, ṙ by central differences (``numpy.gradient``).  a2 is weakly identified by a
zig-zag (|r| stays small); b is a nuisance bias that absorbs a constant yaw moment.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
from scipy.optimize import lsq_linear

from shipgym.identification.errors import check_sampling_step
from shipgym.manoeuvres import zigzag
from shipgym.models.base import ShipModel


@dataclasses.dataclass(frozen=True)
class CubicDampingFit:
    """a2 and b of T·ṙ + r + a2·r³ = K·δ + b (K, T given)."""

    a2: float  # cubic damping [s²] (r in rad/s), ≥ 0
    b: float  # yaw bias [rad/s]


def fit_cubic_damping(
    r: np.ndarray, delta: np.ndarray, h: float, K: float, T: float
) -> CubicDampingFit:
    """Fit a2 ≥ 0 and b to yaw rate r [rad/s] and rudder angle δ [rad] sampled at h [s].

    K [1/s] and T [s] are held fixed (module doc).
    """
    h = check_sampling_step(h)
    r = np.asarray(r, dtype=float)
    delta = np.asarray(delta, dtype=float)
    if r.shape != delta.shape or r.ndim != 1 or r.size < 3:
        raise ValueError("r and delta must be 1-D arrays of equal length ≥ 3")
    r_dot = np.gradient(r, h)
    regressors = np.column_stack([r**3, -np.ones_like(r)])
    target = K * delta - T * r_dot - r
    sol = lsq_linear(regressors, target, bounds=([0.0, -np.inf], [np.inf, np.inf]))
    return CubicDampingFit(a2=float(sol.x[0]), b=float(sol.x[1]))


def ship_cubic_damping(model: ShipModel, K: float, T: float, rudder_deg: float = 20.0) -> float:
    """a2 [s²] fitted to the ship's rudder_deg/rudder_deg zig-zag with K [1/s], T [s] fixed.

    Computed from the model's own simulation, cached per process for each (model, variant,
    parameters, K, T, rudder angle).
    """
    return _cached_a2(
        type(model), model.variant, tuple(model.params.to_vector().tolist()), K, T, rudder_deg
    )


@functools.lru_cache(maxsize=64)
def _cached_a2(
    cls: type,
    variant: str | None,
    params: tuple[float, ...],
    K: float,
    T: float,
    rudder_deg: float,
) -> float:
    model = cls(cls.params_type.from_vector(params), variant)
    log, _ = zigzag(model, rudder_deg)
    return fit_cubic_damping(log.r, log.delta, log.h, K, T).a2
