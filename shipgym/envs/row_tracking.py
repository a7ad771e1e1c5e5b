"""Path tracking of the rows of the batched trial envs (:mod:`shipgym.envs.trial_rows`).

Two bookkeepings with one interface; both give row i the frame of its single env's tracker,
bit for bit (tested), as arrays over the rows (:attr:`frame`) and, where one row's frame is
read (its ``info``, the guidance-mode command), as the single env's Python types
(:meth:`row_frame`: float, int leg, bool ``at_goal``):

* :class:`RouteGroups` (the evaluation env, whose rows are all installed at reset): rows
  whose trials follow the same route (:func:`route_key`: trials of one scenario move the
  start, not the waypoints) are tracked by ONE batched
  :class:`~shipgym.tracking.PathTracker` (``batch=n``, masked to the advancing rows) when
  the group has at least :data:`MIN_BATCHED_ROWS` rows, else by one scalar tracker each (a
  batched group moves on to scalar trackers, :meth:`PathTracker.ship`, once fewer of its
  rows advance: the rows that ended cost nothing then);
* :class:`RowTrackers` (the training env, whose rows draw a new trial, a new route, at each
  autoreset): one scalar tracker per row.

A batched tracker costs a fixed ≈ 20 µs (polyline) / ≈ 240 µs (PCHIP curve) of CPU per
update whatever the number of rows; a scalar one ≈ 2 µs / ≈ 20 µs per row (numpy's per-call
overhead against Python floats; measured with ``time.process_time`` on whole
evaluation episodes): the batched curve tracker pays off from about 16 rows, the polyline
one from about 10.
"""

from __future__ import annotations

import dataclasses
import operator
from typing import Any

import numpy as np

from shipgym.tracking import PathTracker, TrackFrame

#: a TrackFrame's fields as a tuple, in declaration order
_FRAME_ROW = operator.attrgetter(*(f.name for f in dataclasses.fields(TrackFrame)))
#: the fewest rows of one route a batched tracker follows (fewer: one scalar tracker each),
#: by path kind (the measured break-even, module doc)
MIN_BATCHED_ROWS = {"polyline": 10, "curve": 16}

#: the dtype of each TrackFrame field over rows (leg: index, at_goal: flag)
_FIELD_DTYPES = tuple(
    np.int64 if f.name == "leg" else bool if f.name == "at_goal" else np.float64
    for f in dataclasses.fields(TrackFrame)
)


def _kind(tracker: PathTracker) -> str:
    """The :data:`MIN_BATCHED_ROWS` key of a tracker's path."""
    return "curve" if tracker.is_curve else "polyline"


def route_key(tracker: PathTracker) -> tuple[Any, ...]:
    """What two trackers must share to be tracked as rows of one batched tracker: the path
    class, its waypoints (bit for bit) and PCHIP grid, the acceptance radius [m] and the
    switching rule."""
    path = tracker.path
    return (
        type(path),
        path.waypoints.shape,
        path.waypoints.tobytes(),
        getattr(path, "samples_per_segment", None),
        tracker.radius,
        tracker.switching,
    )


class RouteGroups:
    """The rows' tracking by route: one batched tracker per group of rows with the same
    route, or one scalar tracker per row of a small group (module doc), started at the
    positions (x, y) [m] of all rows."""

    def __init__(self, trackers: list[PathTracker], x: np.ndarray, y: np.ndarray) -> None:
        rows_of: dict[tuple[Any, ...], list[int]] = {}
        for i, tracker in enumerate(trackers):
            rows_of.setdefault(route_key(tracker), []).append(i)
        self.n = len(trackers)
        #: one group holding every row in order: its frame is the rows' frame as it is
        self._whole = len(rows_of) == 1
        #: per group: its rows (indices, ascending) and its tracking (batched or per row)
        self.groups: list[tuple[np.ndarray, PathTracker | RowTrackers]] = []
        for members in rows_of.values():
            rows = np.array(members)
            xs, ys = self._take(x, rows), self._take(y, rows)
            first = trackers[members[0]]
            if len(members) >= MIN_BATCHED_ROWS[_kind(first)]:
                tracking = PathTracker(first.path, first.radius, first.switching, len(members))
                tracking.reset(xs, ys)
            else:
                tracking = RowTrackers(len(members))
                positions = zip(members, xs.tolist(), ys.tolist(), strict=True)
                for j, (i, x_j, y_j) in enumerate(positions):
                    tracking.install(j, trackers[i], x_j, y_j)
            self.groups.append((rows, tracking))
        #: per row: the scalar trackers holding it and its index there (None: batched)
        self._scalar: list[tuple[RowTrackers, int] | None] = [None] * self.n
        for rows, tracking in self.groups:
            if isinstance(tracking, RowTrackers):
                for j, i in enumerate(rows.tolist()):
                    self._scalar[i] = (tracking, j)
        self._gather()

    def _take(self, a: np.ndarray, rows: np.ndarray) -> np.ndarray:
        return a if self._whole else a[rows]

    def update(self, x: np.ndarray, y: np.ndarray, advance: np.ndarray | None = None) -> TrackFrame:
        """Move on the ``advance`` rows (None: all) to positions (x, y) [m] (arrays over all
        rows); returns the rows' frame."""
        for g, (rows, tracker) in enumerate(self.groups):  # PathTracker(batch) or RowTrackers
            mask = None if advance is None else self._take(advance, rows)
            moving = len(rows) if mask is None else int(mask.sum())
            if not moving:
                continue
            if isinstance(tracker, PathTracker) and moving < MIN_BATCHED_ROWS[_kind(tracker)]:
                tracker = self._to_scalar(g)
            tracker.update(self._take(x, rows), self._take(y, rows), mask)
        self._gather()
        return self.frame

    def _to_scalar(self, g: int) -> RowTrackers:
        """Group g's batched tracker as one scalar tracker per row, in the same state."""
        rows, batched = self.groups[g]
        scalar = RowTrackers(len(rows))
        for j, i in enumerate(rows.tolist()):
            scalar.adopt(j, batched.ship(j))  # type: ignore[union-attr]
            self._scalar[i] = (scalar, j)
        self.groups[g] = (rows, scalar)
        return scalar

    def _gather(self) -> None:
        """The groups' frames as one TrackFrame over all rows."""
        if self._whole:
            self.frame: TrackFrame = self.groups[0][1].frame
        else:
            columns = [np.empty(self.n, dtype=dtype) for dtype in _FIELD_DTYPES]
            for rows, tracker in self.groups:
                for column, values in zip(columns, _FRAME_ROW(tracker.frame), strict=True):
                    column[rows] = values
            self.frame = TrackFrame(*columns)
        self._lists: tuple[list[Any], ...] | None = None

    @property
    def batched_rows(self) -> int:
        """How many rows batched trackers follow (the rest: one scalar tracker each)."""
        return sum(len(rows) for rows, t in self.groups if isinstance(t, PathTracker))

    def row_frame(self, i: int) -> TrackFrame:
        """Row i's frame in the single env's types (float, int leg, bool at_goal)."""
        scalar = self._scalar[i]
        if scalar is not None:  # its own tracker's frame
            return scalar[0].row_frame(scalar[1])
        if self._lists is None:
            self._lists = tuple(np.asarray(c).tolist() for c in _FRAME_ROW(self.frame))
        return TrackFrame(*(column[i] for column in self._lists))

    def cross_track_of(self, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
        """Cross-track errors [m] of sample positions (N, n) of every row relative to its
        frame (:meth:`PathTracker.cross_track_of`)."""
        if self._whole:
            return self.groups[0][1].cross_track_of(xs, ys)
        e = np.empty(np.shape(xs))
        for rows, tracker in self.groups:
            e[rows] = tracker.cross_track_of(xs[rows], ys[rows])
        return e


class RowTrackers:
    """The rows' tracking with one scalar tracker per row (each row's route its own)."""

    def __init__(self, n: int) -> None:
        self._trackers: list[PathTracker | None] = [None] * n
        self._frames: list[TrackFrame | None] = [None] * n
        self._frame: TrackFrame | None = None

    def install(self, i: int, tracker: PathTracker, x: float, y: float) -> None:
        """Row i follows ``tracker``'s route, started at (x, y) [m]."""
        self._trackers[i] = tracker
        self._frames[i] = tracker.reset(x, y)
        self._frame = None

    def adopt(self, i: int, tracker: PathTracker) -> None:
        """Row i follows ``tracker`` (one ship) from its current frame on."""
        self._trackers[i] = tracker
        self._frames[i] = tracker.frame
        self._frame = None

    def update(self, x: np.ndarray, y: np.ndarray, advance: np.ndarray | None = None) -> TrackFrame:
        """Move on the ``advance`` rows (None: all) to positions (x, y) [m] (arrays over all
        rows); returns the rows' frame."""
        xs, ys = x.tolist(), y.tolist()
        rows = range(len(xs)) if advance is None else np.flatnonzero(advance).tolist()
        for i in rows:
            self._frames[i] = self._trackers[i].update(xs[i], ys[i])
        self._frame = None
        return self.frame

    @property
    def frame(self) -> TrackFrame:
        """The rows' frames as one TrackFrame of arrays."""
        if self._frame is None:
            table = np.array([_FRAME_ROW(f) for f in self._frames], dtype=float)
            cols = table.T
            self._frame = TrackFrame(
                cols[0], cols[1], cols[2], cols[3].astype(np.int64), cols[4], cols[5], cols[6] > 0.5
            )
        return self._frame

    def row_frame(self, i: int) -> TrackFrame:
        """Row i's frame (its tracker's)."""
        return self._frames[i]

    def cross_track_of(self, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
        """Cross-track errors [m] of sample positions (N, n) of every row relative to its
        frame."""
        return np.stack(
            [t.cross_track_of(xs[i], ys[i]) for i, t in enumerate(self._trackers)]  # type: ignore[union-attr]
        )
