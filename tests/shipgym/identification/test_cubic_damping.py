"""Cubic yaw damping of a first-order Nomoto model from a zig-zag (cubic_damping.py)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from shipgym.identification.cubic_damping import fit_cubic_damping, ship_cubic_damping
from shipgym.models.nomoto2 import Nomoto2, Nomoto2Params

K, T, H = 0.3, 4.0, 0.01  # [1/s], [s], [s]


def _first_order_log(a2: float, b: float) -> tuple[np.ndarray, np.ndarray]:
    """(r, δ) of T·ṙ + r + a2·r³ = K·δ + b under a smooth rudder, sampled at H."""
    t = np.arange(0.0, 120.0 + 1e-9, H)

    def rudder(tt: np.ndarray | float) -> np.ndarray:
        return 0.35 * np.sin(0.15 * tt) + 0.2 * np.sin(0.41 * tt)

    def rhs(tt: float, x: np.ndarray) -> list[float]:
        return [(K * float(rudder(tt)) + b - x[0] - a2 * x[0] ** 3) / T]

    sol = solve_ivp(rhs, (0.0, t[-1]), [0.0], t_eval=t, rtol=1e-11, atol=1e-13)
    return sol.y[0], rudder(t)


def test_fit_recovers_a2_and_the_bias_of_an_exact_first_order_model() -> None:
    r, delta = _first_order_log(a2=30.0, b=0.004)
    fit = fit_cubic_damping(r, delta, H, K, T)
    assert fit.a2 == pytest.approx(30.0, rel=1e-3)
    assert fit.b == pytest.approx(0.004, rel=1e-3)


def test_fit_keeps_a2_non_negative() -> None:
    """Data with a2 = −5 (negative damping): the bounded solution sits on a2 = 0 (to the
    solver's tolerance)."""
    r, delta = _first_order_log(a2=-5.0, b=0.0)
    assert 0.0 <= fit_cubic_damping(r, delta, H, K, T).a2 < 1e-6


def test_zigzag_fit_recovers_a2_of_a_first_order_ship() -> None:
    """A nomoto2 with T2 → 0, T3 = 0 is T1·ṙ + r + β·r³ = K·δ + d0: the zig-zag fit with
    the true K and T returns a2 = β (to 2 %; T2 = 5 ms leaves a 0.6 % bias)."""
    params = Nomoto2Params(T2=0.005, T3=0.0, beta=20.0, d0=0.01)
    a2 = ship_cubic_damping(Nomoto2(params), params.K, params.T1 + params.T2)
    assert a2 == pytest.approx(20.0, rel=0.02)


def test_mismatched_arrays_are_refused() -> None:
    with pytest.raises(ValueError, match="equal length"):
        fit_cubic_damping(np.zeros(10), np.zeros(9), H, K, T)
