"""The path tracker: one ship (floats) and N ships (arrays) with the same bits; frames."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym.paths import PchipPath, WaypointPath
from shipgym.tracking import PathTracker

SQUARE = [(0.0, 0.0), (20.0, 0.0), (20.0, 20.0), (0.0, 20.0)]


def test_polyline_frame_on_a_known_geometry() -> None:
    tracker = PathTracker(WaypointPath(SQUARE), acceptance_radius=2.0)
    f = tracker.reset(5.0, 1.0)
    assert (f.leg, f.cross_track, f.along_track, f.path_angle) == (0, 1.0, 5.0, 0.0)
    assert f.angle_change_next == pytest.approx(math.pi / 2)
    assert f.distance_to_next == pytest.approx(math.hypot(15.0, 1.0))
    f = tracker.update(19.0, 0.5)  # inside the acceptance circle of (20, 0): next leg
    assert f.leg == 1 and f.path_angle == pytest.approx(math.pi / 2)
    assert f.cross_track == pytest.approx(1.0)  # left of the upward leg is −x
    f = tracker.update(19.5, 19.0)  # inside the circle of (20, 20): the last leg
    assert f.leg == 2 and not f.at_goal
    f = tracker.update(0.5, 20.2)  # inside the circle of the last waypoint: goal
    assert f.leg == 2 and f.at_goal


def test_along_track_switching_skips_to_the_next_leg_before_the_waypoint() -> None:
    tracker = PathTracker(WaypointPath(SQUARE), 2.0, switching="along_track")
    tracker.reset(0.0, 0.0)
    assert tracker.update(18.5, -5.0).leg == 1  # 1.5 m along-track to go < R, 5 m off
    circle = PathTracker(WaypointPath(SQUARE), 2.0, switching="circle")
    circle.reset(0.0, 0.0)
    assert circle.update(18.5, -5.0).leg == 0  # outside the acceptance circle


def test_unknown_switching_rule_is_named() -> None:
    with pytest.raises(ValueError, match="'sideways'"):
        PathTracker(WaypointPath(SQUARE), 2.0, switching="sideways")


def trajectory(path, n: int = 400) -> np.ndarray:
    """Points near the path, moving along it (what a ship does), for N = 5 ships."""
    s = np.linspace(0.0, path.length, n)[:, None] + np.arange(5)[None, :] * 0.7
    pts = path.point(np.clip(s, 0.0, path.length).ravel()).reshape(n, 5, 2)
    offset = 1.5 * np.sin(np.linspace(0, 9, n))[:, None] * np.array([1, -1, 0.5, 2, -0.2])
    return pts + offset[..., None] * np.array([0.3, 0.9])


@pytest.mark.parametrize("path_type", ["waypoints", "pchip"])
@pytest.mark.parametrize("switching", ["circle", "along_track"])
def test_batched_tracker_equals_one_tracker_per_ship_bit_for_bit(
    path_type: str, switching: str
) -> None:
    route = [(0.0, 0.0), (30.0, 5.0), (45.0, 30.0), (20.0, 50.0), (-5.0, 45.0)]
    path = PchipPath(route) if path_type == "pchip" else WaypointPath(route)
    pts = trajectory(path)
    batch = PathTracker(path, 3.0, switching, batch=5)
    singles = [PathTracker(path, 3.0, switching) for _ in range(5)]
    rng = np.random.default_rng(0)
    for step, p in enumerate(pts):
        mask = None if step == 0 else rng.random(5) < 0.8  # some ships hold their frame
        if step == 0:
            got = batch.reset(p[:, 0].copy(), p[:, 1].copy())
            want = [t.reset(float(x), float(y)) for t, (x, y) in zip(singles, p, strict=True)]
        else:
            got = batch.update(p[:, 0].copy(), p[:, 1].copy(), mask)
            want = [
                t.update(float(x), float(y)) if m else t.frame
                for t, (x, y), m in zip(singles, p, mask, strict=True)
            ]
        for name in ("cross_track", "path_angle", "along_track", "leg", "at_goal"):
            np.testing.assert_array_equal(
                getattr(got, name), [getattr(w, name) for w in want], err_msg=name
            )
        np.testing.assert_array_equal(got.angle_change_next, [w.angle_change_next for w in want])
        np.testing.assert_array_equal(got.distance_to_next, [w.distance_to_next for w in want])
    assert max(t.frame.leg for t in singles) >= 3  # the ships went round the route


def test_curve_tracking_finds_the_closest_point_of_a_dense_search() -> None:
    """Along a ship-like track, the tracked closest point equals the nearest of 200,000
    points of the curve (to their spacing), with the signed distance as cross-track."""
    theta = np.linspace(0.0, math.pi, 13)
    path = PchipPath(np.c_[50 * np.cos(theta), 50 * np.sin(theta)])
    s_dense = np.linspace(0.0, path.length, 200_001)
    dense = path.point(s_dense)
    tracker = PathTracker(path, 2.0)
    tracker.reset(50.0, 0.0)
    for angle in np.linspace(0.05, 3.0, 40):
        r = 50.0 + 3.0 * math.sin(5 * angle)
        x, y = r * math.cos(angle), r * math.sin(angle)
        f = tracker.update(x, y)
        d = np.hypot(dense[:, 0] - x, dense[:, 1] - y)
        j = int(np.argmin(d))
        assert f.along_track == pytest.approx(s_dense[j], abs=2e-3)
        assert abs(f.cross_track) == pytest.approx(d[j], abs=1e-6)
        if abs(r - 50.0) > 0.5:  # clearly inside (left of the anticlockwise path) or outside
            assert math.copysign(1.0, f.cross_track) == (1.0 if r < 50.0 else -1.0)


def test_samples_cross_track_is_relative_to_the_frame() -> None:
    tracker = PathTracker(WaypointPath(SQUARE), 2.0)
    tracker.reset(5.0, 1.0)
    e = tracker.cross_track_of(np.array([5.0, 6.0, 7.0]), np.array([1.0, -2.0, 0.5]))
    np.testing.assert_array_equal(e, [1.0, -2.0, 0.5])
