"""The backstepping law (35) linearised on its design model: PD gains and closed-loop poles.

With exact estimates, a constant reference and H(r) ≈ 1 (linearised at r = 0), eq. (35) of
Xu, Oliveira & Guedes Soares (2021) is the PD law δ = −(Kp·z1 + Kd·r) with
Kp = (c + K1K2)/K, Kd = (K2 + T·K1 − 1)/K, on the plant K/(s(Ts + 1)), optionally with the
low-pass filter C(s) of eq. (39) in series (:mod:`.lowpass`).
"""

from __future__ import annotations

import numpy as np

from shipgym_baselines.classical.adaptive.design_model import NonlinearNomoto
from shipgym_baselines.classical.adaptive.lowpass import low_pass_transfer_function
from shipgym_baselines.classical.adaptive.settings import Gains


def linearised_pd_gains(model: NonlinearNomoto, gains: Gains) -> tuple[float, float]:
    """(Kp [rad/rad], Kd [rad·s/rad]) of eq. (35) linearised (module doc)."""
    kp = (gains.z1_weight + gains.K1 * gains.K2) / model.K
    kd = (gains.K2 + model.T * gains.K1 - 1.0) / model.K
    return kp, kd


def linearised_closed_loop_poles(
    model: NonlinearNomoto,
    gains: Gains,
    filter_frequency: float | None = None,
    filter_damping: float = 1.0,
) -> np.ndarray:
    """Closed-loop poles [1/s] of the law (35) on its design model, linearised at r = 0.

    The loop T·ψ̈ + ψ̇ = K·C(s)δ, δ = −(Kp·z1 + Kd·r) (:func:`linearised_pd_gains`) has the
    characteristic polynomial s(Ts + 1)·D(s) + K·N(s)(Kd·s + Kp) with C = N/D (C ≡ 1 when
    ``filter_frequency`` is None; the poles are then those of the designed error system
    ż1 = −K1z1 + z2, Tż2 = −c·z1 − K2z2).
    """
    K, T = model.K, model.T
    kp, kd = linearised_pd_gains(model, gains)
    num, den = np.array([1.0]), np.array([1.0])
    if filter_frequency is not None:
        num, den = low_pass_transfer_function(filter_frequency, filter_damping)
    poly = np.polyadd(np.polymul([T, 1.0, 0.0], den), K * np.polymul(num, [kd, kp]))
    return np.roots(poly)
