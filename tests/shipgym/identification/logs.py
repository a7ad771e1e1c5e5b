"""Synthetic nomoto2 logs with known truth for the identification tests."""

from __future__ import annotations

import math

import numpy as np

from shipgym.disturbance_config import SensorConfig
from shipgym.disturbances import SensorModel
from shipgym.models.integrator import PeriodIntegrator
from shipgym.models.nomoto2 import Nomoto2, Nomoto2Params

#: the fine sampling step of the nomoto2 scenarios [s]
H = 0.01


def simulate(params: Nomoto2Params, h: float = H, duration: float = 60.0, seed: int = 0):
    """Noise-free log of nomoto2 under a persistently exciting command (eq. (45) + a sine):
    heading ψ, rudder δ and command δc [rad] at spacing h, from rest."""
    model = Nomoto2(params)
    n = round(0.5 / h)
    integ = PeriodIntegrator(model, h, n)
    rng = np.random.default_rng(seed)
    x = model.initial_state()
    p = np.tile(params.to_vector(), (n, 1))
    w = np.zeros((n, 3))
    psi, delta, delta_c = [x[2]], [x[5]], []
    for k in range(round(duration / 0.5)):
        u = math.radians(10.0 * math.sin(0.15 * k) + 5.0 * rng.normal())
        states = integ(x, u, w, p)[1:]  # drop the initial-state row
        x = states[-1]
        psi += list(states[:, 2])
        delta += list(states[:, 5])
        delta_c += [u] * n
    delta_c.append(delta_c[-1])
    return np.array(psi), np.array(delta), np.array(delta_c)


def measured_heading(psi: np.ndarray, seed: int) -> np.ndarray:
    """ψ through the sensor model of the Case 3 scenario (``maneuverability_change``):
    Gaussian noise σ = 0.2° and 5–15° outliers on 0.5 % of the samples."""
    sensor = SensorModel(
        SensorConfig(
            heading_noise_deg=0.2, outlier_probability=0.005, outlier_magnitude_deg=(5.0, 15.0)
        )
    )
    measured, _ = sensor.measure(psi, np.zeros_like(psi), np.random.default_rng(seed))
    return measured
