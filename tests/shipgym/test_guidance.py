"""Tests for shipgym.guidance: LOS (Liu et al. 2019), look-ahead LOS (Xu & Guedes Soares 2020)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from shipgym.angles import wrap_angle
from shipgym.guidance import (
    lookahead_los_heading,
    los_heading,
    los_point,
    los_radius,
    los_relative_heading,
)
from shipgym.paths import segment_frame

# --------------------------------------------------------------------------------------------
# Hand-computed LOS case: leg (0,0)→(10,0), ship at (2, 1), L = 1
# --------------------------------------------------------------------------------------------


def test_los_hand_case() -> None:
    radius = los_radius(1.0, 1.0)
    assert radius == 3.0
    assert los_relative_heading(1.0, radius) == pytest.approx(-math.asin(1.0 / 3.0))
    x_los, y_los = los_point(2.0, 1.0, (0.0, 0.0), (10.0, 0.0), radius)
    assert x_los == pytest.approx(2.0 + math.sqrt(8.0))
    assert y_los == pytest.approx(0.0, abs=1e-15)
    psi_d, r, e = los_heading(2.0, 1.0, (0.0, 0.0), (10.0, 0.0), 1.0)
    assert (r, e) == (3.0, 1.0)
    assert psi_d == pytest.approx(-math.asin(1.0 / 3.0))
    assert psi_d == pytest.approx(math.atan2(y_los - 1.0, x_los - 2.0))


def test_los_radius_switch_at_3L() -> None:
    L = 2.0
    assert los_radius(0.0, L) == 6.0
    assert los_radius(6.0, L) == 6.0  # |e| = 3L still uses 3L
    assert los_radius(-6.0, L) == 6.0
    assert los_radius(6.5, L) == 8.5  # |e| + L beyond
    assert los_radius(-6.5, L) == 8.5  # magnitude of e, not e
    assert los_radius(5.0, L, n=2.0) == 7.0
    # R_LOS > |e| always, so eq. (9) has a real solution.
    for e in np.linspace(-50, 50, 101):
        assert los_radius(float(e), L) > abs(e) or abs(e) == 3 * L
    with pytest.raises(ValueError, match="ship_length"):
        los_radius(1.0, 0.0)


def test_los_relative_heading_sign_and_domain() -> None:
    assert los_relative_heading(0.0, 3.0) == 0.0
    assert los_relative_heading(1.5, 3.0) == pytest.approx(-math.pi / 6)  # left → steer right
    assert los_relative_heading(-1.5, 3.0) == pytest.approx(math.pi / 6)
    assert los_relative_heading(3.0, 3.0) == pytest.approx(-math.pi / 2)
    with pytest.raises(ValueError, match="radius"):
        los_relative_heading(3.1, 3.0)


def test_los_point_raises_without_intersection() -> None:
    with pytest.raises(ValueError, match="no LOS point"):
        los_point(2.0, 4.0, (0.0, 0.0), (10.0, 0.0), 3.0)
    with pytest.raises(ValueError, match="zero-length"):
        los_point(2.0, 1.0, (1.0, 1.0), (1.0, 1.0), 3.0)


def test_los_point_tangent_circle() -> None:
    # |e| = R: the circle touches the line at the foot of the perpendicular.
    assert los_point(4.0, 3.0, (0.0, 0.0), (10.0, 0.0), 3.0) == pytest.approx((4.0, 0.0))


def test_los_point_picks_intersection_closer_to_p_end() -> None:
    # Ship beyond P_{n+1}: the intersection closer to P_{n+1} is the backward one (eq. (6) text).
    x_los, _ = los_point(12.0, 1.0, (0.0, 0.0), (10.0, 0.0), 3.0)
    assert x_los == pytest.approx(12.0 - math.sqrt(8.0))
    # Before P_{n+1}: the forward one.
    x_los, _ = los_point(8.0, 1.0, (0.0, 0.0), (10.0, 0.0), 3.0)
    assert x_los == pytest.approx(8.0 + math.sqrt(8.0))


def test_los_point_bearing_equals_closed_form_property() -> None:
    """Bearing ship → los_point equals ψp + ψ̃_LOS (eqs. (5), (6), (9)) for random poses."""
    rng = np.random.default_rng(12345)
    for _ in range(200):
        p0 = rng.uniform(-500, 500, 2)
        chi = rng.uniform(-math.pi, math.pi)
        leg_len = rng.uniform(10, 300)
        p1 = p0 + leg_len * np.array([math.cos(chi), math.sin(chi)])
        ship_length = rng.uniform(0.5, 20.0)
        along = rng.uniform(-50.0, leg_len)  # before the end of the leg
        e = rng.uniform(-8.0, 8.0) * ship_length
        x = p0[0] + along * math.cos(chi) - e * math.sin(chi)
        y = p0[1] + along * math.sin(chi) + e * math.cos(chi)
        x, y = float(x), float(y)

        psi_d, radius, e_out = los_heading(x, y, p0, p1, ship_length)
        assert e_out == pytest.approx(e, abs=1e-9)
        assert radius == pytest.approx(los_radius(e, ship_length), rel=1e-12)
        closed_form = wrap_angle(chi + los_relative_heading(e_out, radius))
        assert psi_d == pytest.approx(closed_form, abs=1e-12)

        xl, yl = los_point(x, y, p0, p1, radius)
        assert math.hypot(xl - x, yl - y) == pytest.approx(radius, rel=1e-9)  # eq. (5)
        assert abs(segment_frame(xl, yl, p0, p1).cross_track) < 1e-8  # eq. (6)
        bearing = math.atan2(yl - y, xl - x)
        assert abs(wrap_angle(bearing - closed_form)) < 1e-9


def test_los_heading_accepts_numpy_points_and_returns_floats() -> None:
    out = los_heading(1.0, -2.0, np.array([0.0, 0.0]), np.array([0.0, 10.0]), 1.0)
    assert all(type(v) is float for v in out)
    psi_d, _, e = out
    assert e == pytest.approx(-1.0)  # right of an upward leg
    assert psi_d == pytest.approx(math.pi / 2 + math.asin(1.0 / 3.0))  # steer left, back to it


def test_los_guidance_converges_on_kinematic_ship() -> None:
    """With ψ = ψ_LOS, ė = −u e / R_LOS (eqs. (7), (9)): |e| decreases monotonically to 0."""
    u, dt, L = 1.0, 0.05, 1.0
    x, y = 0.0, -10.0
    es = []
    for _ in range(1200):
        psi, _, e = los_heading(x, y, (0.0, 0.0), (2000.0, 0.0), L)
        es.append(abs(e))
        x += u * math.cos(psi) * dt
        y += u * math.sin(psi) * dt
    assert all(b <= a + 1e-12 for a, b in itertools.pairwise(es))
    assert es[-1] < 1e-3


# --------------------------------------------------------------------------------------------
# Look-ahead LOS
# --------------------------------------------------------------------------------------------


def test_lookahead_los_xu_eq6() -> None:
    assert lookahead_los_heading(0.0, 0.7, 5.0) == pytest.approx(0.7)
    assert lookahead_los_heading(5.0, 0.0, 5.0) == pytest.approx(-math.pi / 4)  # left → right
    assert lookahead_los_heading(-5.0, 0.0, 5.0) == pytest.approx(math.pi / 4)
    assert lookahead_los_heading(0.0, 0.0, 5.0, sideslip=0.1) == pytest.approx(-0.1)
    # Wrapped: χf near π plus a left correction goes past π.
    out = lookahead_los_heading(-5.0, math.pi - 0.1, 5.0)
    assert out == pytest.approx(math.pi - 0.1 + math.pi / 4 - 2 * math.pi)
    assert -math.pi <= out < math.pi
    with pytest.raises(ValueError, match="lookahead"):
        lookahead_los_heading(1.0, 0.0, 0.0)


def test_lookahead_matches_los_with_equal_lookahead_for_small_error() -> None:
    # With Δ = sqrt(R² − e²) (the LOS point's along-track distance) both laws agree.
    e, radius = 1.0, 3.0
    delta = math.sqrt(radius**2 - e**2)
    assert lookahead_los_heading(e, 0.3, delta) == pytest.approx(
        0.3 + los_relative_heading(e, radius)
    )
