"""Smooth projection operator (Xu, Oliveira & Guedes Soares 2021 eqs. (24)–(25))."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym_baselines.classical.adaptive.projection import projection

LO, HI, EPS = 0.1, 10.0, 0.1
CENTRE, W0 = 0.5 * (LO + HI), 0.5 * (HI - LO) / math.sqrt(1 + EPS)


def test_projection_is_the_plain_gradient_deep_inside_the_set() -> None:
    """f(θ) ≤ 0 on the inner interval [c ± w0]: Proj(θ, y) = y exactly, either direction."""
    rng = np.random.default_rng(1)
    thetas, ys = rng.uniform(CENTRE - W0, CENTRE + W0, 500), rng.normal(0, 5, 500)
    for theta, y in zip(thetas, ys, strict=True):
        assert projection(theta, y, LO, HI, EPS) == y


def test_projection_stops_outward_updates_at_the_bounds_and_passes_inward_ones() -> None:
    assert projection(HI, 3.0, LO, HI, EPS) == pytest.approx(0.0, abs=1e-12)  # f = 1
    assert projection(LO, -3.0, LO, HI, EPS) == pytest.approx(0.0, abs=1e-12)
    assert projection(HI, -3.0, LO, HI, EPS) == -3.0  # inwards: untouched
    assert projection(LO, 3.0, LO, HI, EPS) == 3.0
    # halfway through the boundary layer an outward update is scaled by 1 − f
    theta = CENTRE + W0 * math.sqrt(1 + 0.5 * EPS)  # f = 0.5
    assert projection(theta, 2.0, LO, HI, EPS) == pytest.approx(1.0)


def test_projection_never_increases_the_lyapunov_term_for_an_inner_truth() -> None:
    """(θ − θ*)(Proj(θ, y) − y) ≤ 0 for θ* in the inner set (Lavretsky & Wise §11.4)."""
    rng = np.random.default_rng(0)
    for _ in range(2000):
        theta, star, y = rng.uniform(LO, HI), rng.uniform(CENTRE - W0, CENTRE + W0), rng.normal()
        assert (theta - star) * (projection(theta, y, LO, HI, EPS) - y) <= 1e-12


@pytest.mark.parametrize("start", [LO, 0.5, CENTRE, 9.5, HI])
def test_estimates_driven_by_a_large_update_stay_inside_the_bounds(start: float) -> None:
    """θ' = γ·Proj(θ, y(t)) with |γy| up to 10³ per second pushing both ways (RK4,
    dt = 1 ms): θ never leaves [lo, hi] (to rounding: the bounds are equilibria, approached
    from inside) and reaches the boundary layer on both sides."""
    dt, gamma = 1e-3, 50.0

    def rate(theta: float, t: float) -> float:
        return gamma * projection(theta, 20.0 * math.sin(0.5 * t), LO, HI, EPS)

    theta, history = start, []
    for k in range(40_000):
        t = k * dt
        k1 = rate(theta, t)
        k2 = rate(theta + 0.5 * dt * k1, t + 0.5 * dt)
        k3 = rate(theta + 0.5 * dt * k2, t + 0.5 * dt)
        k4 = rate(theta + dt * k3, t + dt)
        theta += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        history.append(theta)
    h = np.array(history)
    assert LO - 1e-12 <= h.min() and h.max() <= HI + 1e-12
    assert h.min() < CENTRE - W0 and h.max() > CENTRE + W0
