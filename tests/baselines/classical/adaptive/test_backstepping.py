"""Backstepping law (Xu, Oliveira & Guedes Soares 2021 eqs. (27)–(35))."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from shipgym_baselines.classical.adaptive.backstepping import backstepping_rudder
from shipgym_baselines.classical.adaptive.design_model import NonlinearNomoto
from shipgym_baselines.classical.adaptive.settings import Gains, L1BacksteppingSettings

MODEL = NonlinearNomoto(K=0.506, T=1.4483, a2=0.0081)


def test_backstepping_error_system_is_the_designed_linear_one() -> None:
    """Plant = design model, exact estimates, δ applied continuously: z1, z2 obey
    ż1 = −K1·z1 + z2, T·ż2 = −c·z1 − K2·z2 (eqs. (30), (35)) for a moving reference."""
    gains = Gains.transfer(L1BacksteppingSettings(), 0.95, 0.8, "m")
    b = 0.02

    def reference(t: float) -> tuple[float, float, float]:
        return 0.3 * math.sin(0.2 * t), 0.06 * math.cos(0.2 * t), -0.012 * math.sin(0.2 * t)

    def closed_loop(t: float, x: np.ndarray) -> list[float]:
        delta, _, _ = backstepping_rudder(MODEL, gains, x[0], x[1], reference(t), (1, 1, b))
        return [x[1], (MODEL.K * delta + b - MODEL.damping(x[1]) * x[1]) / MODEL.T]

    t = np.linspace(0.0, 20.0, 201)
    sol = solve_ivp(closed_loop, (0, 20), [0.2, 0.0], t_eval=t, rtol=1e-10, atol=1e-12)
    z = np.array(
        [
            backstepping_rudder(MODEL, gains, p, r, reference(tt), (1, 1, b))[1:]
            for tt, p, r in zip(t, sol.y[0], sol.y[1], strict=True)
        ]
    )
    a = np.array([[-gains.K1, 1.0], [-gains.z1_weight / MODEL.T, -gains.K2 / MODEL.T]])
    lin = solve_ivp(lambda _, x: a @ x, (0, 20), z[0], t_eval=t, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(z, lin.y.T, atol=1e-6)


def test_heading_error_is_wrapped() -> None:
    """ψ = π − 0.1, ψd = −π + 0.1: z1 = −0.2, not 2π − 0.2."""
    gains = Gains.transfer(L1BacksteppingSettings(), 0.95, 0.8, "m")
    _, z1, _ = backstepping_rudder(
        MODEL, gains, math.pi - 0.1, 0.0, (-math.pi + 0.1, 0.0, 0.0), (1, 1, 0)
    )
    assert z1 == pytest.approx(-0.2, abs=1e-12)
