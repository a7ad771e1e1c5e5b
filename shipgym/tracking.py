"""Where the ship is relative to the path: active leg, cross-track error, look-ahead info.

One tracker for both path types and for one ship or N: the single env, the batched env and
the controllers that keep their own bookkeeping from measured positions all use
:class:`PathTracker`.  Its pure functions (:func:`shipgym.paths.advance_legs`,
:func:`polyline_frame`, :func:`curve_frame`) are written once for floats and arrays (``xp`` of
:mod:`shipgym.numerics`), so one ship and the matching ship of a batch get the same bits.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from shipgym.angles import wrap_angle
from shipgym.numerics import ARRAY, SCALAR
from shipgym.paths import (
    CurvePoint,
    LegTable,
    PchipPath,
    WaypointPath,
    advance_legs,
    along_track,
    cross_track,
)

SWITCHING_RULES = ("circle", "along_track")


@dataclasses.dataclass(slots=True)
class TrackFrame:
    """Ship relative to the path at one instant (SI units; floats, or arrays over N ships)."""

    cross_track: Any  # e [m], signed (positive left of the path)
    path_angle: Any  # ψp [rad] of the active leg / curve tangent
    along_track: Any  # progress along the active leg [m] (polyline) or arc length s (curve)
    leg: Any  # active leg (polyline) or waypoint interval (curve)
    angle_change_next: Any  # path-angle change to the next leg [rad]
    distance_to_next: Any  # distance to the next waypoint [m]
    at_goal: Any  # final waypoint reached


def polyline_frame(x: Any, y: Any, leg: Any, table: LegTable, radius: float, xp: Any) -> TrackFrame:
    """Frame of position(s) (x, y) [m] on the active leg(s) (Borkowski 2018 eq. (25)).

    The goal counts as reached on the last leg inside the acceptance circle of the final
    waypoint or once abeam of it.
    """
    if xp.batched:  # the active legs' constants in one gather
        x0, y0, x1, y1, c, s, length, angle, change = table.matrix.take(leg, axis=1)
    else:
        tab = table.lists
        x0, y0, x1, y1 = tab["x0"][leg], tab["y0"][leg], tab["x1"][leg], tab["y1"][leg]
        c, s, length = tab["c"][leg], tab["s"][leg], tab["length"][leg]
        angle, change = tab["angle"][leg], tab["change"][leg]
    rx, ry = x - x0, y - y0
    along = along_track(rx, ry, c, s)
    gx, gy = x - table.goal[0], y - table.goal[1]
    nx, ny = x - x1, y - y1
    at_goal = (leg == table.last_leg) & ((xp.sqrt(gx * gx + gy * gy) <= radius) | (along >= length))
    return TrackFrame(
        cross_track(rx, ry, c, s),
        angle,
        along,
        leg,
        change,
        xp.sqrt(nx * nx + ny * ny),
        at_goal,
    )


def curve_frame(x: Any, y: Any, point: CurvePoint, path: PchipPath, radius: float, xp: Any):
    """Frame of position(s) (x, y) [m] at their closest point(s) on a PCHIP curve.

    ``leg`` is the waypoint interval holding the closest point; the goal counts as reached
    inside the acceptance circle of the final waypoint or at the end of the curve.
    """
    arc = path.waypoint_arc_lengths if xp.batched else path.waypoint_arc_lengths_list
    angles = path.waypoint_angles if xp.batched else path.waypoint_angles_list
    last = len(arc) - 2
    leg = xp.clip_index(xp.searchsorted_right(arc, point.s) - 1, 0, last)
    s_next = arc[leg + 1]
    gx, gy = x - path.end[0], y - path.end[1]
    at_goal = (xp.sqrt(gx * gx + gy * gy) <= radius) | (point.s >= path.length - 1e-9)
    return TrackFrame(
        point.cross_track,
        point.angle,
        point.s,
        leg,
        wrap_angle(angles[leg + 1] - point.angle),
        s_next - point.s,
        at_goal,
    )


def _select(mask: np.ndarray, new: Any, old: Any) -> Any:
    """Field by field: ``new`` where ``mask``, else ``old`` (dataclasses of arrays)."""
    if np.asarray(mask).all():
        return new
    return type(new)(
        *(
            np.where(mask, getattr(new, f.name), getattr(old, f.name))
            for f in dataclasses.fields(new)
        )
    )


def _item(record: Any, i: int) -> Any:
    """Entry i of a dataclass of arrays, as a dataclass of Python scalars."""
    return type(record)(*(getattr(record, f.name)[i].item() for f in dataclasses.fields(record)))


class PathTracker:
    """Active-leg bookkeeping with the scenario's waypoint switching rule, for one ship
    (``batch=None``: floats) or N ships (``batch=N``: arrays, updates masked per ship).

    For a polyline, the active leg switches by acceptance circle (Liu et al. 2019 eq. (13))
    or along-track distance (Borkowski 2018 eq. (27)) and the cross-track error is taken to
    the active leg, as in Liu et al. (2019).  For a PCHIP curve, the closest point is
    searched within 4 acceptance radii of arc length around the previous one
    (:meth:`shipgym.paths.PchipPath.follow`; globally at reset).
    """

    def __init__(
        self,
        path: WaypointPath | PchipPath,
        acceptance_radius: float,
        switching: str = "circle",
        batch: int | None = None,
    ) -> None:
        if switching not in SWITCHING_RULES:
            raise ValueError(f"unknown switching rule {switching!r}; use one of {SWITCHING_RULES}")
        self.path = path
        self.radius = float(acceptance_radius)
        self.switching = switching
        self.is_curve = isinstance(path, PchipPath)
        self.batch = batch
        self.xp = SCALAR if batch is None else ARRAY
        zero = 0 if batch is None else np.zeros(batch, dtype=np.int64)
        if self.is_curve:
            self._window = 4.0 * self.radius  # arc length searched around the last point [m]
            self.point: CurvePoint | None = None
        else:
            self._legs = path.legs
        self.leg = zero
        self.frame: TrackFrame | None = None

    @property
    def s(self) -> Any:
        """Arc length [m] of the closest point (curves only)."""
        return self.point.s

    def reset(self, x: Any, y: Any, mask: Any = None) -> TrackFrame:
        """Start (the masked ships) at the first leg / the globally closest curve point."""
        if self.is_curve:
            return self._curve(x, y, None, mask)
        self.leg = self._masked(
            mask, 0 if self.batch is None else np.zeros_like(self.leg), self.leg
        )
        return self.update(x, y, mask)

    def update(self, x: Any, y: Any, mask: Any = None) -> TrackFrame:
        """Frame at position(s) (x, y) [m]; with ``mask`` only the masked ships move on."""
        if self.is_curve:
            return self._curve(x, y, self._window, mask)
        xp = self.xp
        leg = advance_legs(x, y, self.leg, self._legs, self.radius, self.switching, xp)
        self.leg = self._masked(mask, leg, self.leg)
        return self._store(polyline_frame(x, y, self.leg, self._legs, self.radius, xp), mask)

    def ship(self, i: int) -> PathTracker:
        """Ship i of a batched tracker as a one-ship tracker in its state (frame, leg and
        closest point, as Python floats, ints and bools): its updates go on with the bits
        the batched tracker would give it."""
        one = PathTracker(self.path, self.radius, self.switching)
        if self.frame is not None:
            one.frame = _item(self.frame, i)
            one.leg = one.frame.leg
        if self.is_curve and self.point is not None:
            one.point = _item(self.point, i)
        return one

    def _curve(self, x: Any, y: Any, window: float | None, mask: Any) -> TrackFrame:
        hint = 0.0 if window is None else self.point.s
        point = self.path.follow(x, y, hint, window, self.xp)
        if mask is not None and self.point is not None:
            point = _select(mask, point, self.point)
        self.point = point
        frame = curve_frame(x, y, point, self.path, self.radius, self.xp)
        self.leg = frame.leg
        return self._store(frame, mask)

    def _masked(self, mask: Any, new: Any, old: Any) -> Any:
        return new if mask is None or np.asarray(mask).all() else np.where(mask, new, old)

    def _store(self, frame: TrackFrame, mask: Any) -> TrackFrame:
        if mask is not None and self.frame is not None:
            frame = _select(mask, frame, self.frame)
        self.frame = frame
        return frame

    def origin(self) -> tuple[Any, Any]:
        """The point [m] of the path the current frame is measured from: the active leg's
        start (polyline) or the closest point (curve); floats, or arrays over the ships."""
        if self.is_curve:
            return self.point.x, self.point.y
        tab = self._legs.arrays if self.batch is not None else self._legs.lists
        return tab["x0"][self.leg], tab["y0"][self.leg]

    def cross_track_of(self, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
        """Cross-track errors [m] of sample positions relative to the current frame: of one
        ship (xs, ys of shape (n,)), or of N ships (shape (N, n): row i relative to ship i's
        frame).

        Exact for a polyline (the active leg); for a curve, relative to the tangent line at
        the current closest point (accurate over one control period of travel).  The unit
        direction is libm's cos / sin of the path angle for one ship and for N alike (the
        same bits per ship).
        """
        angle = self.frame.path_angle
        x0, y0 = self.origin()
        if self.batch is None:
            return cross_track(xs - x0, ys - y0, math.cos(angle), math.sin(angle))
        angles = angle.tolist()
        c = np.fromiter(map(math.cos, angles), np.float64, len(angles))[:, None]
        s = np.fromiter(map(math.sin, angles), np.float64, len(angles))[:, None]
        return cross_track(xs - x0[:, None], ys - y0[:, None], c, s)
