"""Tests for shipgym.paths: angles, straight-leg paths, PCHIP paths and waypoint switching."""

from __future__ import annotations

import math
from dataclasses import astuple

import numpy as np
import pytest

from shipgym.angles import wrap_angle
from shipgym.paths import (
    LegFrame,
    PchipPath,
    WaypointPath,
    acceptance_circle_reached,
    advance_leg,
    along_track_reached,
    segment_frame,
)

# --------------------------------------------------------------------------------------------
# wrap_angle
# --------------------------------------------------------------------------------------------


def test_wrap_angle_float_range_and_values() -> None:
    assert wrap_angle(0.0) == 0.0
    assert wrap_angle(math.pi) == -math.pi  # half-open interval [−π, π)
    assert wrap_angle(-math.pi) == -math.pi
    assert wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
    # Edge cases where float modulo rounds (a + π) mod 2π up to exactly 2π.
    for a in (np.nextafter(-math.pi, -4.0), np.nextafter(math.pi, 4.0), -1e-17, 3 * math.pi):
        assert -math.pi <= wrap_angle(float(a)) < math.pi
        assert -math.pi <= wrap_angle(np.array([a]))[0] < math.pi
    assert isinstance(wrap_angle(1.0), float)


def test_wrap_angle_array_matches_float() -> None:
    a = np.random.default_rng(0).uniform(-50, 50, 1000)
    w = wrap_angle(a)
    assert isinstance(w, np.ndarray)
    assert np.all((w >= -math.pi) & (w < math.pi))
    assert np.allclose(np.sin(w), np.sin(a)) and np.allclose(np.cos(w), np.cos(a))
    assert np.allclose(w, [wrap_angle(float(v)) for v in a])


# --------------------------------------------------------------------------------------------
# Cross-track sign convention
# --------------------------------------------------------------------------------------------


def test_cross_track_positive_left_of_path() -> None:
    # Leg pointing +x: "left" in an x-right / y-up plot is +y.
    assert segment_frame(5.0, 1.0, (0.0, 0.0), (10.0, 0.0)).cross_track == pytest.approx(1.0)
    # Leg pointing +y: left is −x.
    assert segment_frame(-2.0, 3.0, (0.0, 0.0), (0.0, 10.0)).cross_track == pytest.approx(2.0)
    # Leg pointing −x: left is −y.
    assert segment_frame(5.0, -1.0, (10.0, 0.0), (0.0, 0.0)).cross_track == pytest.approx(1.0)


def test_cross_track_rate_matches_liu_eq7() -> None:
    """ė = u sin(ψ − ψp) along a straight-line motion (finite difference)."""
    rng = np.random.default_rng(1)
    dt = 1e-3
    for _ in range(50):
        p0 = rng.uniform(-100, 100, 2)
        chi = rng.uniform(-math.pi, math.pi)
        path = WaypointPath(
            [p0, p0 + rng.uniform(5, 50) * np.array([math.cos(chi), math.sin(chi)])]
        )
        psi, u = rng.uniform(-math.pi, math.pi), rng.uniform(0.5, 10.0)
        x0, y0 = rng.uniform(-100, 100, 2)
        vx, vy = u * math.cos(psi), u * math.sin(psi)
        e_plus = path.leg_frame(x0 + vx * dt, y0 + vy * dt, 0).cross_track
        e_minus = path.leg_frame(x0 - vx * dt, y0 - vy * dt, 0).cross_track
        e_dot = (e_plus - e_minus) / (2 * dt)
        assert e_dot == pytest.approx(u * math.sin(psi - path.leg_angle(0)), abs=1e-6)


# --------------------------------------------------------------------------------------------
# WaypointPath
# --------------------------------------------------------------------------------------------


def test_waypoint_path_attributes() -> None:
    path = WaypointPath([(0, 0), (3, 4), (3, 10)])
    assert path.n_legs == 2
    assert np.allclose(path.leg_lengths, [5.0, 6.0])
    assert np.allclose(path.cumulative_length, [0.0, 5.0, 11.0])
    assert path.length == pytest.approx(11.0)
    assert path.waypoints.dtype == np.float64 and path.waypoints.shape == (3, 2)
    with pytest.raises(ValueError):
        path.waypoints[0, 0] = 1.0  # read-only


def test_waypoint_path_copies_input() -> None:
    wp = np.array([[0.0, 0.0], [1.0, 0.0]])
    path = WaypointPath(wp)
    wp[1, 0] = 5.0
    assert path.waypoints[1, 0] == 1.0


def test_leg_frame_hand_cases() -> None:
    path = WaypointPath([(0, 0), (10, 0), (10, 10)])
    f = path.leg_frame(2.0, 1.0, 0)
    assert isinstance(f, LegFrame)
    assert (f.along_track, f.cross_track, f.path_angle, f.leg_length) == (2.0, 1.0, 0.0, 10.0)
    f = path.leg_frame(12.0, 4.0, 1)  # right of the upward leg
    assert f.along_track == pytest.approx(4.0)
    assert f.cross_track == pytest.approx(-2.0)
    assert f.path_angle == pytest.approx(math.pi / 2)
    # 45° leg: (1, 0) is 1/√2 along and 1/√2 to the right.
    f = WaypointPath([(0, 0), (1, 1)]).leg_frame(1.0, 0.0, 0)
    assert f.along_track == pytest.approx(math.sqrt(0.5))
    assert f.cross_track == pytest.approx(-math.sqrt(0.5))
    assert f.leg_length == pytest.approx(math.sqrt(2))
    with pytest.raises(IndexError):
        path.leg_frame(0.0, 0.0, 2)


def test_leg_frame_matches_segment_frame() -> None:
    path = WaypointPath([(1, 2), (-4, 7), (3, -1)])
    for leg in range(path.n_legs):
        a = path.leg_frame(0.3, -0.7, leg)
        b = segment_frame(0.3, -0.7, path.waypoints[leg], path.waypoints[leg + 1])
        assert astuple(a) == pytest.approx(astuple(b), rel=1e-12, abs=1e-12)


def test_point_and_angle_by_arc_length() -> None:
    path = WaypointPath([(0, 0), (10, 0), (10, 10)])
    assert np.allclose(path.point(0.0), [0, 0])
    assert np.allclose(path.point(4.0), [4, 0])
    assert np.allclose(path.point(10.0), [10, 0])
    assert np.allclose(path.point(13.0), [10, 3])
    assert np.allclose(path.point(25.0), [10, 10])  # clamped
    assert np.allclose(path.point([1.0, 15.0]), [[1, 0], [10, 5]])
    assert path.angle(5.0) == 0.0
    assert path.angle(10.0) == pytest.approx(math.pi / 2)  # outgoing leg at a waypoint
    assert path.angle(20.0) == pytest.approx(math.pi / 2)
    assert path.curvature(3.0) == 0.0
    assert np.all(path.curvature(np.linspace(0, 20, 5)) == 0.0)
    assert path.leg_index(9.9) == 0 and path.leg_index(10.0) == 1 and path.leg_index(20.0) == 1


def test_next_leg_angle_change() -> None:
    path = WaypointPath([(0, 0), (10, 0), (10, 10), (20, 0)])
    assert path.next_leg_angle_change(0) == pytest.approx(math.pi / 2)
    assert path.next_leg_angle_change(1) == pytest.approx(-3 * math.pi / 4)
    assert path.next_leg_angle_change(2) == 0.0
    # Wrapping: from heading ~+170° to ~−170° is a +20° turn, not −340°.
    p = WaypointPath([(0, 0), (-10, 10 * math.tan(math.radians(10))), (-20, 0)])
    assert p.next_leg_angle_change(0) == pytest.approx(math.radians(20))


def test_project_picks_nearest_leg() -> None:
    path = WaypointPath([(0, 0), (10, 0), (10, 10), (0, 10)])
    s, e, psi, c = path.project(9.0, 6.0)  # 1 m left of leg 1, 4 m from leg 2
    assert s == pytest.approx(16.0)
    assert e == pytest.approx(1.0)
    assert psi == pytest.approx(math.pi / 2)
    assert np.allclose(c, [10, 6])
    s, e, psi, c = path.project(4.0, 8.5)  # 1.5 m left of leg 2 (heading −x: left is −y)
    assert s == pytest.approx(26.0) and e == pytest.approx(1.5)
    assert psi == pytest.approx(-math.pi) and np.allclose(c, [4, 10])
    # Outside the outer corner at (10, 0): closest point is the waypoint, outgoing leg 1.
    s, e, psi, c = path.project(12.0, -1.0)
    assert s == pytest.approx(10.0) and np.allclose(c, [10, 0])
    assert psi == pytest.approx(math.pi / 2) and e == pytest.approx(-2.0)
    # Before the start: clamps to s = 0, cross-track relative to leg 0's line.
    s, e, _, c = path.project(-3.0, 2.0)
    assert s == 0.0 and e == pytest.approx(2.0) and np.allclose(c, [0, 0])


def test_project_matches_brute_force() -> None:
    rng = np.random.default_rng(2)
    path = WaypointPath(rng.uniform(-50, 50, (6, 2)))
    dense = path.point(np.linspace(0, path.length, 20001))
    for _ in range(50):
        x, y = rng.uniform(-60, 60, 2)
        s, _, _, c = path.project(x, y)
        d_min = np.min(np.hypot(dense[:, 0] - x, dense[:, 1] - y))
        assert math.hypot(c[0] - x, c[1] - y) <= d_min + 1e-9
        assert np.allclose(path.point(s), c)


@pytest.mark.parametrize(
    ("waypoints", "match"),
    [
        ([(0, 0)], "at least 2 waypoints"),
        (np.zeros((0, 2)), "at least 2 waypoints"),
        ([(0, 0), (1, np.nan)], "non-finite"),
        ([(0, 0), (np.inf, 1)], "non-finite"),
        ([(0, 0), (1, 1), (1, 1), (2, 0)], "identical"),
        ([(0, 0, 0), (1, 1, 1)], "shape"),
        ([0.0, 1.0, 2.0], "shape"),
    ],
)
@pytest.mark.parametrize("cls", [WaypointPath, PchipPath])
def test_bad_waypoints_raise(cls: type, waypoints: object, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        cls(waypoints)


# --------------------------------------------------------------------------------------------
# PchipPath
# --------------------------------------------------------------------------------------------

ROUTES = {
    "zigzag": [(0, 0), (40, 10), (80, -15), (120, 5), (160, 0)],
    "u_turn": [(0, 0), (50, 0), (80, 20), (50, 40), (0, 40)],  # x not monotone
    "loop": [(0, 0), (30, -10), (60, 20), (30, 50), (-10, 30), (5, 10)],
}


@pytest.fixture(scope="module", params=sorted(ROUTES))
def pchip(request: pytest.FixtureRequest) -> PchipPath:
    return PchipPath(ROUTES[request.param])


def test_pchip_passes_through_waypoints(pchip: PchipPath) -> None:
    pts = pchip.point(pchip.waypoint_arc_lengths)
    assert np.max(np.abs(pts - pchip.waypoints)) <= 1e-9
    assert pchip.waypoint_arc_lengths[0] == 0.0
    assert pchip.waypoint_arc_lengths[-1] == pytest.approx(pchip.length)
    assert np.all(np.diff(pchip.waypoint_arc_lengths) > 0)


def test_pchip_unit_speed_in_arc_length(pchip: PchipPath) -> None:
    h = 1e-4
    s = np.linspace(h, pchip.length - h, 400)
    d = (pchip.point(s + h) - pchip.point(s - h)) / (2 * h)
    assert np.max(np.abs(np.hypot(d[:, 0], d[:, 1]) - 1.0)) < 1e-6


def test_pchip_angle_and_curvature_consistent(pchip: PchipPath) -> None:
    # Tangent angle is the direction of dP/ds; curvature is dψ/ds (away from waypoints).
    h = 1e-4
    wl = pchip.waypoint_arc_lengths
    s = np.linspace(0.5, pchip.length - 0.5, 300)
    s = s[np.min(np.abs(s[:, None] - wl[None, :]), axis=1) > 0.1]
    d = pchip.point(s + h) - pchip.point(s - h)
    assert np.allclose(wrap_angle(np.arctan2(d[:, 1], d[:, 0]) - pchip.angle(s)), 0, atol=1e-6)
    dpsi = wrap_angle(pchip.angle(s + h) - pchip.angle(s - h)) / (2 * h)
    assert np.allclose(dpsi, pchip.curvature(s), atol=1e-4, rtol=1e-4)


def test_pchip_straight_line_arc_length() -> None:
    path = PchipPath([(0, 0), (3, 4), (9, 12), (12, 16)])  # collinear, uneven spacing
    assert path.length == pytest.approx(20.0, abs=1e-6)
    assert np.allclose(path.point(7.5), [4.5, 6.0], atol=1e-9)
    assert np.allclose(path.angle(np.linspace(0, 20, 11)), math.atan2(4, 3))
    assert np.allclose(path.curvature(np.linspace(0, 20, 11)), 0.0, atol=1e-12)
    two = PchipPath([(1, 1), (4, -3)])
    assert two.length == pytest.approx(5.0, abs=1e-6)


def test_pchip_axis_aligned_corner_degenerates_to_polyline() -> None:
    """Documented caveat: both PCHIP slopes vanish at an axis-aligned right-angle waypoint."""
    path = PchipPath([(0, 0), (10, 0), (10, 10)])
    assert path.length == pytest.approx(20.0, abs=1e-6)
    assert np.allclose(path.point(np.linspace(0, 10, 11))[:, 1], 0.0, atol=1e-12)
    assert path.angle(9.99) == pytest.approx(0.0, abs=1e-12)
    assert path.angle(10.0) == pytest.approx(math.pi / 2)  # outgoing tangent at the corner
    assert path.curvature(10.0) == 0.0
    s, e, psi, c = path.project(11.0, -1.0)
    assert s == pytest.approx(10.0, abs=1e-9) and np.allclose(c, [10, 0], atol=1e-9)
    assert psi == pytest.approx(math.pi / 2) and e == pytest.approx(-1.0, abs=1e-9)


def test_pchip_u_turn_works() -> None:
    path = PchipPath(ROUTES["u_turn"])
    s = np.linspace(0, path.length, 2001)
    p = path.point(s)
    assert p[:, 0].max() <= 80.0 + 1e-9  # x is not monotone, but stays within the data
    assert abs(wrap_angle(path.angle(path.length) - math.pi)) < 1e-9  # arrives heading −x
    # The turn is to the left (counter-clockwise): total heading change ≈ +π, curvature ≥ 0.
    psi = np.unwrap(path.angle(s))
    assert psi[-1] - psi[0] == pytest.approx(math.pi, abs=1e-6)
    assert np.all(path.curvature(s) >= -1e-9)


def test_pchip_shape_preserving_on_monotone_staircase() -> None:
    wp = [(0, 0), (10, 1), (20, 9), (30, 10), (40, 18), (50, 18.5)]
    path = PchipPath(wp)
    p = path.point(np.linspace(0, path.length, 4001))
    assert p[:, 1].min() >= 0.0 - 1e-12 and p[:, 1].max() <= 18.5 + 1e-12
    assert np.all(np.diff(p[:, 1]) >= -1e-12)  # monotone data → monotone curve
    assert np.all(np.diff(p[:, 0]) >= -1e-12)


def test_pchip_project_matches_brute_force(pchip: PchipPath) -> None:
    rng = np.random.default_rng(3)
    s_dense = np.linspace(0, pchip.length, 40001)
    dense = pchip.point(s_dense)
    lo, hi = pchip.waypoints.min(axis=0) - 15, pchip.waypoints.max(axis=0) + 15
    for _ in range(25):
        x, y = rng.uniform(lo, hi)
        s, e, psi, c = pchip.project(x, y)
        dist = np.hypot(dense[:, 0] - x, dense[:, 1] - y)
        k = int(np.argmin(dist))
        d = math.hypot(c[0] - x, c[1] - y)
        assert d <= dist[k] + 1e-9
        assert d >= dist[k] - 1e-3
        assert np.allclose(pchip.point(s), c, atol=1e-6)
        assert psi == pytest.approx(pchip.angle(s), abs=1e-6)
        if 0.0 < s < pchip.length:  # interior closest point: |e| is the distance
            assert abs(e) == pytest.approx(d, abs=1e-6)


def test_pchip_project_sign_matches_straight_leg_convention() -> None:
    # A straight PCHIP path must agree exactly with the straight-leg frame.
    wp = [(0, 0), (20, 10), (40, 20)]
    curve, poly = PchipPath(wp), WaypointPath(wp)
    rng = np.random.default_rng(4)
    for _ in range(20):
        x, y = rng.uniform(0, 40), rng.uniform(-10, 30)
        s, e, psi, _ = curve.project(x, y)
        s2, e2, psi2, _ = poly.project(x, y)
        assert (s, e, psi) == pytest.approx((s2, e2, psi2), abs=1e-7)
    # On a curved path: points displaced to the left of the tangent have e > 0.
    path = PchipPath(ROUTES["zigzag"])
    for s0 in np.linspace(5, path.length - 5, 20):
        p, psi = path.point(s0), path.angle(s0)
        normal = np.array([-math.sin(psi), math.cos(psi)])
        for side in (1.0, -1.0):
            q = p + side * 0.5 * normal
            s, e, _, _ = path.project(*q)
            assert s == pytest.approx(s0, abs=1e-4)
            assert e == pytest.approx(side * 0.5, abs=1e-6)


def test_pchip_project_window_restricts_search() -> None:
    # The loop passes near its start at the end; a hint keeps the projection local.
    path = PchipPath([(0, 0), (100, 0), (100, 100), (0, 100), (0, 2)])
    s_glob, *_ = path.project(1.0, 1.0)
    assert s_glob == pytest.approx(0.0, abs=1.5)
    s_loc, _, _, c_loc = path.project(1.0, 1.0, s_hint=path.length - 5.0, window=10.0)
    assert s_loc > path.length - 15.0
    assert c_loc[0] == pytest.approx(0.0, abs=1e-6)
    # A window around the hint bounds the result even when the true minimum lies outside:
    # to the window's grid points and the grid cell beyond them (64 cells per segment).
    cell = float(np.max(np.diff(path.waypoint_arc_lengths))) / 64
    s_w, *_ = path.project(50.0, -5.0, s_hint=150.0, window=20.0)
    assert 130.0 - 2 * cell <= s_w <= 170.0 + 2 * cell
    assert s_w < 140.0  # the true minimum (s ≈ 50) is far outside


def test_pchip_accessors_are_read_only() -> None:
    path = PchipPath(ROUTES["zigzag"])
    with pytest.raises(ValueError):
        path.waypoints[0, 0] = 3.0
    with pytest.raises(ValueError):
        path.waypoint_arc_lengths[0] = 3.0
    assert path.segment_index(0.0) == 0
    assert path.segment_index(path.waypoint_arc_lengths[2]) == 2
    assert path.segment_index(path.length) == 3


# --------------------------------------------------------------------------------------------
# Waypoint switching
# --------------------------------------------------------------------------------------------


def test_acceptance_circle_liu_eq13() -> None:
    assert acceptance_circle_reached(8.0, 0.0, (10.0, 0.0), 2.0)  # on the circle
    assert acceptance_circle_reached(9.0, 1.0, (10.0, 0.0), 2.0)
    assert not acceptance_circle_reached(8.0, 1.0, (10.0, 0.0), 2.0)


def test_along_track_borkowski_eq27() -> None:
    frame = LegFrame(along_track=8.5, cross_track=50.0, path_angle=0.0, leg_length=10.0)
    assert along_track_reached(frame, 2.0)  # 1.5 m to go, even far off the track
    assert not along_track_reached(frame, 1.5)  # strict inequality
    assert along_track_reached(LegFrame(12.0, 0.0, 0.0, 10.0), 0.1)  # past the waypoint


def test_advance_leg_circle_rule() -> None:
    path = WaypointPath([(0, 0), (10, 0), (11, 0), (12, 0), (30, 0)])
    assert advance_leg(path, 5.0, 0.0, 0, 2.0) == 0
    assert advance_leg(path, 8.5, 0.5, 0, 2.0) == 1
    # Within 2 m of waypoints 1, 2 and 3 at once: skip to leg 3.
    assert advance_leg(path, 10.5, 0.0, 0, 2.0) == 3
    # Reaching the final waypoint keeps the last leg.
    assert advance_leg(path, 30.0, 0.0, 3, 2.0) == 3
    assert advance_leg(path, 30.0, 0.0, 0, 100.0) == 3
    # A ship that misses the circle does not switch.
    assert advance_leg(path, 10.0, 5.0, 0, 2.0, rule="circle") == 0


def test_advance_leg_along_track_rule() -> None:
    path = WaypointPath([(0, 0), (10, 0), (10, 1), (10, 2), (10, 30)])
    assert advance_leg(path, 5.0, 0.0, 0, 2.0, rule="along_track") == 0
    # Far off track but past the along-track threshold: switches (unlike the circle rule).
    assert advance_leg(path, 9.0, 5.0, 0, 2.0, rule="along_track") == 3
    assert advance_leg(path, 9.0, 5.0, 0, 2.0, rule="circle") == 0
    assert advance_leg(path, 8.5, -3.0, 0, 2.0, rule="along_track") == 1
    assert advance_leg(path, 10.0, 40.0, 0, 2.0, rule="along_track") == 3
    with pytest.raises(ValueError, match="rule"):
        advance_leg(path, 0.0, 0.0, 0, 2.0, rule="nearest")  # type: ignore[arg-type]
    with pytest.raises(IndexError):
        advance_leg(path, 0.0, 0.0, 4, 2.0)
