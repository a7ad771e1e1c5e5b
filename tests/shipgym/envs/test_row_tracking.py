"""Row tracking of the batched trial envs: rows of one route are followed by one
batched PathTracker (or by one scalar tracker each below MIN_BATCHED_ROWS), and every row's
frame is its own scalar tracker's, bit for bit and in the single env's Python types."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from shipgym.envs import row_tracking
from shipgym.envs.row_tracking import RouteGroups, route_key
from shipgym.scenarios.loader import Scenario, load_scenario
from shipgym.tracking import PathTracker, TrackFrame

FIELDS = [f.name for f in dataclasses.fields(TrackFrame)]

#: a polyline route (circle switching) and a PCHIP curve
POLYLINE, CURVE = "mariner_rudder_aging", "blanke_current_shift_curved"


def _tracker(sc: Scenario) -> PathTracker:
    return PathTracker(sc.path, sc.acceptance_radius, sc.config.path.switching)


def _tracks(sc: Scenario, n: int, steps: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Positions (steps, n) [m] of n ships moving along the route at different speeds and
    lateral offsets (up to 3 L), the fastest ones to its end."""
    rng = np.random.default_rng(seed)
    speed = rng.uniform(0.8, 1.2, n)
    s = np.clip(np.linspace(0.0, 1.1 * sc.path.length, steps)[:, None] * speed, 0, None)
    s = np.minimum(s, sc.path.length)
    points = np.asarray(sc.path.point(s.ravel())).reshape(steps, n, 2)
    offset = rng.uniform(-3.0, 3.0, (steps, n)) * sc.ship_length
    offset[s >= sc.path.length] = 0.0  # at the final waypoint
    return points[..., 0] + offset * 0.3, points[..., 1] + offset


def _bits(value: object) -> bytes:
    return np.asarray(value, dtype=float).tobytes()


def _assert_rows_equal(groups: RouteGroups, refs: list[PathTracker], where: str) -> None:
    """Each row's frame (arrays and row_frame) is its scalar tracker's, bit for bit."""
    for i, ref in enumerate(refs):
        row = groups.row_frame(i)
        for name in FIELDS:
            mine, theirs = getattr(row, name), getattr(ref.frame, name)
            assert type(mine) is type(theirs), (where, i, name, type(mine), type(theirs))
            assert _bits(mine) == _bits(theirs), (where, i, name, mine, theirs)
            assert _bits(getattr(groups.frame, name)[i]) == _bits(theirs), (where, i, name)


@pytest.fixture(params=["batched", "per_row", "to_scalar"])
def batching(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    """Force every group onto one batched tracker, or onto scalar trackers per row, or onto
    a batched tracker that moves on to scalar trackers once fewer than 3 rows advance."""
    least = {"batched": 1, "per_row": 10**6, "to_scalar": 3}[request.param]
    monkeypatch.setattr(row_tracking, "MIN_BATCHED_ROWS", {"polyline": least, "curve": least})
    return request.param


@pytest.mark.parametrize("names", [(POLYLINE,), (CURVE,), (CURVE, POLYLINE)])
def test_route_groups_give_each_row_its_scalar_trackers_frame(
    names: tuple[str, ...], batching: str
) -> None:
    """Rows on one route, or on two routes (two groups, interleaved rows), some of them
    stopping (masked) before the others; the samples' cross-track errors too."""
    per_route = 4
    scenarios = [load_scenario(names[i % len(names)]) for i in range(per_route * len(names))]
    n = len(scenarios)
    xs = np.empty((200, n))
    ys = np.empty((200, n))
    for j, name in enumerate(names):
        cols = [i for i in range(n) if i % len(names) == j]
        xs[:, cols], ys[:, cols] = _tracks(load_scenario(name), len(cols), 200, seed=j)
    refs = [_tracker(sc) for sc in scenarios]
    for i, ref in enumerate(refs):
        ref.reset(float(xs[0, i]), float(ys[0, i]))
    groups = RouteGroups([_tracker(sc) for sc in scenarios], xs[0], ys[0])
    assert len(groups.groups) == len(names)
    assert groups.batched_rows == (0 if batching == "per_row" else n)
    _assert_rows_equal(groups, refs, "reset")
    stop = np.random.default_rng(7).integers(50, 260, n)  # rows end at different steps
    stop[0] = 200  # one row to the end
    rng = np.random.default_rng(3)
    for step in range(1, 200):
        advance = step < stop
        # samples of the period, relative to the frames before the update
        sample_x = xs[step][:, None] + rng.normal(0.0, 5.0, (n, 4))
        sample_y = ys[step][:, None] + rng.normal(0.0, 5.0, (n, 4))
        e = groups.cross_track_of(sample_x, sample_y)
        for i, ref in enumerate(refs):
            expected = ref.cross_track_of(sample_x[i], sample_y[i])
            assert e[i].tobytes() == expected.tobytes(), (step, i)
        for i in np.flatnonzero(advance):
            refs[i].update(float(xs[step, i]), float(ys[step, i]))
        groups.update(xs[step], ys[step], advance)
        _assert_rows_equal(groups, refs, f"step {step}")
        if batching == "to_scalar" and advance.sum() < 3 * len(names):
            assert groups.batched_rows < n  # a group went on with scalar trackers
    assert any(bool(groups.row_frame(i).at_goal) for i in range(n))  # the goal was reached


def test_route_key_groups_equal_routes_only() -> None:
    a, b = load_scenario(CURVE), load_scenario(CURVE)  # equal routes, distinct objects
    assert route_key(_tracker(a)) == route_key(_tracker(b))
    moved = a.with_overrides({"path": {"waypoints": [[0.0, 0.0], [500.0, 10.0], [900.0, 0.0]]}})
    polyline = a.with_overrides({"path": {"type": "waypoints"}})
    along = a.with_overrides({"path": {"switching": "along_track"}})
    wider = a.with_overrides({"path": {"acceptance_radius_L": 3.0}})
    keys = {route_key(_tracker(sc)) for sc in (a, moved, polyline, along, wider)}
    assert len(keys) == 5
