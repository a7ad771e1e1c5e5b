"""Where the ship is relative to the path: active leg, cross-track error, look-ahead info.

One tracker for both path types, used by the env (and by any controller that wants the
same bookkeeping from measured positions).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from shipgym.paths import PchipPath, WaypointPath, advance_leg, segment_frame, wrap_angle


@dataclasses.dataclass(slots=True)
class TrackFrame:
    """Ship relative to the path at one instant (SI units)."""

    cross_track: float  # e [m], signed (positive left of the path)
    path_angle: float  # ψp [rad] of the active leg / curve tangent
    along_track: float  # progress along the active leg [m] (polyline) or arc length s (curve)
    leg: int  # active leg (polyline) or waypoint interval (curve)
    angle_change_next: float  # path-angle change to the next leg [rad]
    distance_to_next: float  # distance to the next waypoint [m]
    at_goal: bool  # final waypoint reached


class PathTracker:
    """Active-leg bookkeeping with the waypoint switching rule of the scenario.

    For a polyline, the active leg switches by acceptance circle (Liu et al. 2019 eq. (13))
    or along-track distance (Borkowski 2018 eq. (27)) and the cross-track error is taken to
    the active leg, as in Liu et al. (2019).  For a PCHIP curve, the closest point is
    searched in a window around the previous arc length.  The goal counts as reached on
    the last leg when the ship is inside the acceptance circle of the final waypoint or has
    passed abeam of it.
    """

    def __init__(
        self, path: WaypointPath | PchipPath, acceptance_radius: float, switching: str = "circle"
    ) -> None:
        self.path = path
        self.radius = float(acceptance_radius)
        self.switching = switching
        self.is_curve = isinstance(path, PchipPath)
        self.leg = 0
        self.s = 0.0
        self._wp = [(float(p[0]), float(p[1])) for p in path.waypoints]
        self.frame: TrackFrame | None = None

    def reset(self, x: float, y: float) -> TrackFrame:
        self.leg = 0
        self.s = 0.0
        if self.is_curve:
            self.s = self.path.project(x, y)[0]
        return self.update(x, y)

    def update(self, x: float, y: float) -> TrackFrame:
        wp = self._wp
        last_wp = wp[-1]
        # sqrt of squares (not hypot): the batched env computes the same, bit for bit
        gx, gy = x - last_wp[0], y - last_wp[1]
        dist_goal = math.sqrt(gx * gx + gy * gy)
        if self.is_curve:
            path: PchipPath = self.path
            s, e, angle, _ = path.project(x, y, s_hint=self.s, window=4.0 * self.radius)
            self.s = s
            leg = path.segment_index(s)
            s_next = float(path.waypoint_arc_lengths[leg + 1])
            change = float(wrap_angle(path.angle(s_next) - angle))
            self.leg = leg
            at_goal = dist_goal <= self.radius or s >= path.length - 1e-9
            self.frame = TrackFrame(e, angle, s, leg, change, s_next - s, at_goal)
            return self.frame
        self.leg = advance_leg(self.path, x, y, self.leg, self.radius, self.switching)
        leg = self.leg
        f = segment_frame(x, y, wp[leg], wp[leg + 1])
        last = leg == len(wp) - 2
        at_goal = last and (dist_goal <= self.radius or f.along_track >= f.leg_length)
        nxt = wp[leg + 1]
        self.frame = TrackFrame(
            f.cross_track,
            f.path_angle,
            f.along_track,
            leg,
            self.path.next_leg_angle_change(leg),
            math.sqrt((x - nxt[0]) * (x - nxt[0]) + (y - nxt[1]) * (y - nxt[1])),
            at_goal,
        )
        return self.frame

    def cross_track_of(self, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
        """Cross-track errors [m] of sample positions relative to the current frame.

        Exact for a polyline (the active leg); for a curve, relative to the tangent line at
        the current closest point (accurate over one control period of travel).
        """
        f = self.frame
        if self.is_curve:
            c = self.path.point(self.s)
            x0, y0 = float(c[0]), float(c[1])
        else:
            x0, y0 = self._wp[self.leg]
        return -(xs - x0) * math.sin(f.path_angle) + (ys - y0) * math.cos(f.path_angle)
