"""Reference paths for ship path following.

Conventions (fixed for the whole package): SI units and radians, plane coordinates (x, y),
heading ψ with ẋ = u cos ψ, ẏ = u sin ψ.  For a leg from P_n to P_{n+1}:

* path angle        ψp  = atan2(y_{n+1} − y_n, x_{n+1} − x_n),
* along-track       x_r = (x − x_n) cos ψp + (y − y_n) sin ψp,
* cross-track error e   = −(x − x_n) sin ψp + (y − y_n) cos ψp,

which is Borkowski (2018) eq. (25).  e > 0 on the side a positive heading rotation points to
(left of the path in an x-right / y-up plot), so that ė = u sin(ψ − ψp), Liu et al. (2019)
eq. (7).  Angles are wrapped to [−π, π).

Two path types are provided:

* :class:`WaypointPath` — the straight-leg polyline of Liu et al. (2019) §2.2 / Borkowski
  (2018) §3, with a fast per-leg frame for the environment step;
* :class:`PchipPath` — a smooth, shape-preserving piecewise cubic Hermite path through the same
  waypoints (Xu & Guedes Soares 2020 §2, eqs. (2)–(5)), parametrised by arc length.

Waypoint switching rules are pure functions: the acceptance circle of Liu et al. (2019)
eq. (13) and the along-track rule of Borkowski (2018) eq. (27).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import PchipInterpolator

from shipgym.angles import wrap_angle
from shipgym.numerics import SCALAR

__all__ = [
    "LegFrame",
    "LegTable",
    "PchipPath",
    "WaypointPath",
    "acceptance_circle_reached",
    "advance_leg",
    "advance_legs",
    "along_track",
    "along_track_reached",
    "cross_track",
    "segment_frame",
]


# --------------------------------------------------------------------------------------------
# Leg frame
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True, slots=True)
class LegFrame:
    """Ship position in the frame of one straight leg (Borkowski 2018 eq. (25)).

    Attributes:
        along_track: x_r [m], distance along the leg from its start point.
        cross_track: e [m], signed; positive left of the leg (x-right / y-up plot).
        path_angle: ψp [rad], direction of the leg, in [−π, π).
        leg_length: |P_n P_{n+1}| [m].
    """

    along_track: float
    cross_track: float
    path_angle: float
    leg_length: float


def along_track(rx: Any, ry: Any, c: Any, s: Any) -> Any:
    """x_r = rx cos ψp + ry sin ψp [m] of the offset (rx, ry) from a point of the path, with
    (c, s) = (cos ψp, sin ψp) — Borkowski (2018) eq. (25); floats or arrays."""
    return rx * c + ry * s


def cross_track(rx: Any, ry: Any, c: Any, s: Any) -> Any:
    """e = −rx sin ψp + ry cos ψp [m], > 0 left of the path — Borkowski (2018) eq. (25);
    floats or arrays.  The one signed cross-track formula of the package."""
    return -rx * s + ry * c


def segment_frame(
    x: float, y: float, p_start: tuple[float, float], p_end: tuple[float, float]
) -> LegFrame:
    """Leg frame of the point (x, y) [m] for the leg p_start → p_end [m] (pure float math).

    Raises ValueError if p_start and p_end coincide.
    """
    x0 = float(p_start[0])
    y0 = float(p_start[1])
    dx = float(p_end[0]) - x0
    dy = float(p_end[1]) - y0
    length = math.hypot(dx, dy)
    if not length > 0.0:
        raise ValueError("segment_frame: p_start and p_end coincide (zero-length leg)")
    c = dx / length
    s = dy / length
    rx = x - x0
    ry = y - y0
    # Borkowski (2018) eq. (25); the path angle is eq. (26) written as atan2.
    return LegFrame(
        along_track(rx, ry, c, s), cross_track(rx, ry, c, s), math.atan2(dy, dx), length
    )


def _validate_waypoints(waypoints: ArrayLike) -> NDArray[np.float64]:
    """Return waypoints as a fresh float (M, 2) array, or raise ValueError naming the problem."""
    try:
        arr = np.array(waypoints, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"waypoints must be a numeric (M, 2) array: {exc}") from exc
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ValueError(f"waypoints must have shape (M, 2), got shape {arr.shape}")
    if arr.shape[0] < 2:
        raise ValueError(f"at least 2 waypoints are required, got {arr.shape[0]}")
    if not np.all(np.isfinite(arr)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(arr), axis=1))[0])
        raise ValueError(f"waypoints contain non-finite values (first at index {bad})")
    steps = np.diff(arr, axis=0)
    same = np.flatnonzero(np.all(steps == 0.0, axis=1))
    if same.size:
        i = int(same[0])
        raise ValueError(
            f"consecutive waypoints {i} and {i + 1} are identical ({arr[i].tolist()}): "
            "zero-length leg"
        )
    arr.setflags(write=False)
    return arr


def _readonly(a: NDArray[np.float64]) -> NDArray[np.float64]:
    a.setflags(write=False)
    return a


# --------------------------------------------------------------------------------------------
# Straight-leg path
# --------------------------------------------------------------------------------------------
class WaypointPath:
    """Polyline of straight legs through M ≥ 2 waypoints [m] (Liu et al. 2019 §2.2, Fig. 3).

    Leg i runs from waypoint i to waypoint i + 1 (i = 0 … n_legs − 1).  Arc length s [m] is
    measured from waypoint 0 along the legs.
    """

    def __init__(self, waypoints: ArrayLike) -> None:
        wp = _validate_waypoints(waypoints)
        self.waypoints: NDArray[np.float64] = wp
        steps = np.diff(wp, axis=0)
        self.n_legs: int = wp.shape[0] - 1
        self.leg_lengths: NDArray[np.float64] = _readonly(np.hypot(steps[:, 0], steps[:, 1]))
        self.cumulative_length: NDArray[np.float64] = _readonly(
            np.concatenate(([0.0], np.cumsum(self.leg_lengths)))
        )
        self.length: float = float(self.cumulative_length[-1])
        angles = np.arctan2(steps[:, 1], steps[:, 0])
        self._angles_arr = _readonly(wrap_angle(angles))
        self._unit = _readonly(steps / self.leg_lengths[:, None])
        # Plain Python floats for the per-step leg_frame (no numpy scalar overhead).
        self._x0: list[float] = wp[:-1, 0].tolist()
        self._y0: list[float] = wp[:-1, 1].tolist()
        self._cos: list[float] = self._unit[:, 0].tolist()
        self._sin: list[float] = self._unit[:, 1].tolist()
        self._angle: list[float] = self._angles_arr.tolist()
        self._len: list[float] = self.leg_lengths.tolist()

    def __repr__(self) -> str:
        return f"WaypointPath(n_legs={self.n_legs}, length={self.length:.6g})"

    @cached_property
    def legs(self) -> LegTable:
        """The per-leg constants of the step core (:class:`LegTable`)."""
        return LegTable.of(self)

    # -- per-leg frame --------------------------------------------------------------------
    def leg_frame(self, x: float, y: float, leg: int) -> LegFrame:
        """Frame of the point (x, y) [m] relative to leg `leg` (Borkowski 2018 eq. (25))."""
        if not 0 <= leg < self.n_legs:
            raise IndexError(f"leg {leg} out of range [0, {self.n_legs - 1}]")
        c = self._cos[leg]
        s = self._sin[leg]
        rx = x - self._x0[leg]
        ry = y - self._y0[leg]
        return LegFrame(
            along_track(rx, ry, c, s), cross_track(rx, ry, c, s), self._angle[leg], self._len[leg]
        )

    def leg_angle(self, leg: int) -> float:
        """Path angle ψp [rad] of leg `leg`."""
        return self._angle[leg]

    def next_leg_angle_change(self, leg: int) -> float:
        """Wrapped course change [rad] from leg `leg` to leg `leg + 1` (0 for the last leg)."""
        if not 0 <= leg < self.n_legs:
            raise IndexError(f"leg {leg} out of range [0, {self.n_legs - 1}]")
        if leg == self.n_legs - 1:
            return 0.0
        return wrap_angle(self._angle[leg + 1] - self._angle[leg])

    # -- arc-length parametrisation -------------------------------------------------------
    def _leg_of(self, s: NDArray[np.float64]) -> NDArray[np.intp]:
        # At a shared waypoint the outgoing (later) leg is used.
        idx = np.searchsorted(self.cumulative_length, s, side="right") - 1
        return np.clip(idx, 0, self.n_legs - 1)

    def leg_index(self, s: float) -> int:
        """Index of the leg containing arc length s [m] (the later leg at a waypoint)."""
        return int(self._leg_of(np.asarray(float(s)))[()])

    def point(self, s: ArrayLike) -> NDArray[np.float64]:
        """Point [m] at arc length s [m], clamped to [0, length]; shape (2,) or (N, 2)."""
        s_arr = np.clip(np.asarray(s, dtype=float), 0.0, self.length)
        leg = self._leg_of(s_arr)
        ds = s_arr - self.cumulative_length[leg]
        return self.waypoints[leg] + ds[..., None] * self._unit[leg]

    def angle(self, s: ArrayLike) -> float | NDArray[np.float64]:
        """Path angle ψp [rad] at arc length s [m] (the outgoing leg at a waypoint)."""
        s_arr = np.clip(np.asarray(s, dtype=float), 0.0, self.length)
        out = self._angles_arr[self._leg_of(s_arr)]
        return float(out) if out.ndim == 0 else out

    def curvature(self, s: ArrayLike) -> float | NDArray[np.float64]:
        """Curvature [1/m] at arc length s [m]: 0 on straight legs."""
        s_arr = np.asarray(s, dtype=float)
        return 0.0 if s_arr.ndim == 0 else np.zeros_like(s_arr)

    # -- closest point --------------------------------------------------------------------
    def project(self, x: float, y: float) -> tuple[float, float, float, NDArray[np.float64]]:
        """Global closest point of the polyline to (x, y) [m].

        Returns (s, cross_track, path_angle, closest_point): arc length s [m] of the closest
        point, signed cross-track error [m] relative to the line of the leg holding that
        point (same convention as :meth:`leg_frame`), that leg's angle [rad], and the point
        itself [m] as a (2,) array.  On exact ties the earliest leg wins, except that a closest
        point at a shared waypoint is attributed to the outgoing leg (consistent with
        :meth:`angle`).
        """
        p0 = self.waypoints[:-1]
        rx = x - p0[:, 0]
        ry = y - p0[:, 1]
        along = along_track(rx, ry, self._unit[:, 0], self._unit[:, 1])
        cross = cross_track(rx, ry, self._unit[:, 0], self._unit[:, 1])
        t = np.clip(along, 0.0, self.leg_lengths)
        d2 = (along - t) ** 2 + cross**2
        k = int(np.argmin(d2))
        if k + 1 < self.n_legs and t[k] >= self.leg_lengths[k] and along[k + 1] <= 0.0:
            # Closest point is waypoint k+1, shared by legs k and k+1: use the outgoing leg.
            k += 1
        tk = float(t[k])
        if tk <= 0.0:
            closest = self.waypoints[k].copy()
        elif tk >= self.leg_lengths[k]:
            closest = self.waypoints[k + 1].copy()
        else:
            closest = self.waypoints[k] + tk * self._unit[k]
        s = float(self.cumulative_length[k]) + tk
        return s, float(cross[k]), self._angle[k], closest


# --------------------------------------------------------------------------------------------
# Smooth PCHIP path
# --------------------------------------------------------------------------------------------
_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(8)


class PchipPath:
    """Smooth path through the waypoints by piecewise cubic Hermite interpolation.

    Xu & Guedes Soares (2020) §2 build P(x) with the shape-preserving slopes of eqs. (4)–(5)
    (Moler 2004), which needs monotone x.  Here x(t) and y(t) are each interpolated with
    ``scipy.interpolate.PchipInterpolator`` (the same Fritsch–Carlson-type slopes) over the
    cumulative chord length t, so any waypoint order works (U-turns, loops), and the curve is
    then re-parametrised by arc length s ∈ [0, length] [m]: |P'(t)| is integrated with
    Gauss–Legendre quadrature on a fine grid and s → t is inverted by safeguarded Newton
    iterations started from linear interpolation of that grid.

    Caveat of component-wise PCHIP: at a waypoint where *both* x and y have a local extremum
    or a flat neighbouring step (e.g. an axis-aligned right-angle turn), both slopes are set
    to zero, so dP/dt = 0 there and the curve has a corner (the tangent jumps, curvature is
    unbounded nearby).  ``angle`` returns the outgoing tangent at such a point and
    ``curvature`` returns 0 exactly at it.

    Args:
        waypoints: (M, 2) waypoints [m], M ≥ 2, no two consecutive identical.
        samples_per_segment: grid subintervals per waypoint interval used for arc length and
            the coarse closest-point search.
    """

    def __init__(self, waypoints: ArrayLike, samples_per_segment: int = 64) -> None:
        if samples_per_segment < 2:
            raise ValueError(f"samples_per_segment must be >= 2, got {samples_per_segment}")
        wp = _validate_waypoints(waypoints)
        self.waypoints: NDArray[np.float64] = wp
        chords = np.hypot(*np.diff(wp, axis=0).T)
        knots = np.concatenate(([0.0], np.cumsum(chords)))
        self._knots = _readonly(knots)
        # Vector-valued PCHIP: x(t) and y(t) together (axis 0 is the parameter).
        self._p = PchipInterpolator(knots, wp, axis=0)
        self._dp = self._p.derivative(1)
        self._ddp = self._p.derivative(2)

        # Parameter grid, containing every knot exactly.
        n = int(samples_per_segment)
        #: grid subintervals per waypoint interval
        self.samples_per_segment: int = n
        frac = np.linspace(0.0, 1.0, n + 1)[:-1]
        tg = (knots[:-1, None] + chords[:, None] * frac[None, :]).ravel()
        tg = np.concatenate((tg, knots[-1:]))
        knot_idx = np.arange(wp.shape[0]) * n
        tg[knot_idx] = knots
        self._tg = _readonly(tg)
        a, b = tg[:-1], tg[1:]
        seg = self._quad_speed(a, b)
        sg = np.concatenate(([0.0], np.cumsum(seg)))
        self._sg = _readonly(sg)
        self._pg = _readonly(self._p(tg))
        self.length: float = float(sg[-1])
        self.waypoint_arc_lengths: NDArray[np.float64] = _readonly(sg[knot_idx].copy())
        self._tol_s = 1e-13 * max(1.0, self.length)
        self._tiny_speed = 1e-12
        #: tangent angle [rad] at each waypoint (the outgoing one; the incoming at the end)
        self.waypoint_angles: NDArray[np.float64] = _readonly(
            np.asarray(self.angle(self.waypoint_arc_lengths), dtype=np.float64)
        )
        self.waypoint_arc_lengths_list: list[float] = self.waypoint_arc_lengths.tolist()
        self.waypoint_angles_list: list[float] = self.waypoint_angles.tolist()
        self.end: tuple[float, float] = (float(wp[-1, 0]), float(wp[-1, 1]))
        self._cells = _CurveCells(self)

    def __repr__(self) -> str:
        return f"PchipPath(n_waypoints={self.waypoints.shape[0]}, length={self.length:.6g})"

    # -- internals ------------------------------------------------------------------------
    def _speed(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        d = self._dp(t)
        return np.hypot(d[..., 0], d[..., 1])

    def _quad_speed(self, a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
        """∫_a^b |P'(t)| dt by 8-point Gauss–Legendre (a, b 1-D arrays of the same shape)."""
        half = 0.5 * (b - a)
        mid = 0.5 * (b + a)
        nodes = mid[:, None] + half[:, None] * _GL_NODES[None, :]
        return half * (self._speed(nodes) @ _GL_WEIGHTS)

    def _s_of_t(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        t = np.clip(t, self._tg[0], self._tg[-1])
        j = np.clip(np.searchsorted(self._tg, t, side="right") - 1, 0, self._tg.size - 2)
        return self._sg[j] + self._quad_speed(self._tg[j], t)

    def _t_of_s(self, s: NDArray[np.float64]) -> NDArray[np.float64]:
        """Invert the arc length: solve S(t) = s on the bracketing grid cell (1-D arrays)."""
        s = np.clip(s, 0.0, self.length)
        tg, sg = self._tg, self._sg
        j = np.clip(np.searchsorted(sg, s, side="right") - 1, 0, tg.size - 2)
        lo = tg[j].copy()
        hi = tg[j + 1].copy()
        s_lo = sg[j]
        t = lo + (hi - lo) * (s - s_lo) / (sg[j + 1] - s_lo)
        for _ in range(60):
            f = s_lo + self._quad_speed(tg[j], t) - s
            active = np.abs(f) > self._tol_s
            if not np.any(active):
                break
            hi = np.where(f > 0.0, t, hi)
            lo = np.where(f < 0.0, t, lo)
            sp = self._speed(t)
            with np.errstate(divide="ignore", invalid="ignore"):
                t_new = t - f / sp
            # Safeguard: bisect the bracket when Newton leaves it or the speed vanishes.
            bad = ~((t_new >= lo) & (t_new <= hi)) | (sp <= self._tiny_speed)
            t_new = np.where(bad, 0.5 * (lo + hi), t_new)
            t = np.where(active, t_new, t)  # converged entries stay put
        return t

    def _tangent_angle(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        d = self._dp(t)
        stalled = np.hypot(d[..., 0], d[..., 1]) <= self._tiny_speed
        if np.any(stalled):
            # Zero parametric speed (corner): use the outgoing direction, or the incoming one
            # at the path end.
            eps = 1e-7 * max(1.0, float(self._tg[-1]))
            t_st = t[stalled]
            t_st = np.where(t_st + eps <= self._tg[-1], t_st + eps, t_st - eps)
            d = d.copy()
            d[stalled] = self._dp(t_st)
        return wrap_angle(np.arctan2(d[..., 1], d[..., 0]))

    def _curvature_t(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        d = self._dp(t)
        dd = self._ddp(t)
        sp = np.hypot(d[..., 0], d[..., 1])
        num = d[..., 0] * dd[..., 1] - d[..., 1] * dd[..., 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            k = num / sp**3
        return np.where(sp > self._tiny_speed, k, 0.0)

    # -- arc-length parametrisation -------------------------------------------------------
    def point(self, s: ArrayLike) -> NDArray[np.float64]:
        """Point [m] at arc length s [m], clamped to [0, length]; shape (2,) or (N, 2)."""
        s_arr = np.asarray(s, dtype=float)
        p = self._p(self._t_of_s(np.atleast_1d(s_arr).ravel()))
        return p[0] if s_arr.ndim == 0 else p.reshape((*s_arr.shape, 2))

    def angle(self, s: ArrayLike) -> float | NDArray[np.float64]:
        """Tangent angle [rad] at arc length s [m], in [−π, π)."""
        s_arr = np.asarray(s, dtype=float)
        a = self._tangent_angle(self._t_of_s(np.atleast_1d(s_arr).ravel()))
        return float(a[0]) if s_arr.ndim == 0 else a.reshape(s_arr.shape)

    def curvature(self, s: ArrayLike) -> float | NDArray[np.float64]:
        """Signed curvature [1/m] at arc length s [m] (positive turning left, i.e. ψ increasing).

        PCHIP is C¹ only, so curvature jumps at waypoints; there the outgoing piece is used.
        """
        s_arr = np.asarray(s, dtype=float)
        k = self._curvature_t(self._t_of_s(np.atleast_1d(s_arr).ravel()))
        return float(k[0]) if s_arr.ndim == 0 else k.reshape(s_arr.shape)

    def segment_index(self, s: float) -> int:
        """Index i of the waypoint interval [waypoint i, waypoint i+1] containing s [m]."""
        idx = np.searchsorted(self.waypoint_arc_lengths, float(s), side="right") - 1
        return int(np.clip(idx, 0, self.waypoints.shape[0] - 2))

    # -- closest point, fast (the step core) ----------------------------------------------
    def follow(self, x: Any, y: Any, s_hint: Any, window: float | None, xp: Any) -> CurvePoint:
        """Closest point of the curve to ship position(s) (x, y) [m], for one ship or N.

        The grid point nearest to the ship among those within ``window`` [m] of arc length
        around ``s_hint`` [m] (and the next one out on each side; all of them with
        ``window=None``) starts a safeguarded Newton iteration on g(t) = (P(t) − q)·P'(t) = 0
        inside its two neighbouring grid cells (a fixed number of iterations: quadratic
        convergence from within a cell; the grid point is kept if the iterate is farther).
        Arc length s by 8-point Gauss–Legendre on the cell.  Written once for ``xp = SCALAR``
        (floats) and ``xp = ARRAY`` (arrays over ships): the same IEEE operations in the
        same order, so both give the same bits (:mod:`shipgym.numerics`).  About 15 µs for
        one ship, ≈ 1 µs per ship for N = 1024 (the scipy search it replaces: ≈ 0.3–1 ms).
        """
        return self._cells.follow(x, y, s_hint, window, xp)

    # -- closest point --------------------------------------------------------------------
    def project(
        self, x: float, y: float, s_hint: float | None = None, window: float | None = None
    ) -> tuple[float, float, float, NDArray[np.float64]]:
        """Closest point of the curve to (x, y) [m] (:meth:`follow` for one ship).

        The search is global unless both `s_hint` and `window` [m] are given, in which case it
        is restricted to the grid points within `window` of arc length around `s_hint` (use it
        to follow the ship along self-approaching routes).

        Returns (s, cross_track, path_angle, closest_point) as :meth:`WaypointPath.project`,
        with the signed cross-track e = −(x − x_c) sin ψ_c + (y − y_c) cos ψ_c relative to the
        tangent angle ψ_c at the closest point (x_c, y_c) — positive left of the path.
        """
        local = s_hint is not None and window is not None
        if local and window < 0.0:
            raise ValueError(f"window must be >= 0, got {window}")
        hint = float(s_hint) if local else 0.0
        p = self.follow(float(x), float(y), hint, float(window) if local else None, SCALAR)
        return p.s, p.cross_track, p.angle, np.array([p.x, p.y])


@dataclass(frozen=True, slots=True)
class CurvePoint:
    """Closest point of a :class:`PchipPath` to a ship (floats, or arrays over N ships)."""

    grid_index: Any  # nearest grid point
    t: Any  # curve parameter (cumulative chord length) [m]
    s: Any  # arc length [m]
    x: Any  # closest point [m]
    y: Any
    ux: Any  # unit tangent (cos ψc, sin ψc)
    uy: Any
    angle: Any  # tangent angle ψc [rad] in [−π, π)
    cross_track: Any  # e = −(x − x_c) sin ψc + (y − y_c) cos ψc [m], > 0 left of the path


_NEWTON_ITERATIONS = 4


class _CurveCells:
    """Per-grid-cell cubic coefficients of a PCHIP path, as lists (one ship) and arrays (N).

    Cell j spans grid parameters [tg[j], tg[j+1]] inside one PCHIP piece with origin o_j:
    P(t) = ((c0 τ + c1) τ + c2) τ + c3, τ = t − o_j, for x and y.
    """

    def __init__(self, path: PchipPath) -> None:
        tg = path._tg
        knots = path._knots
        coef = path._p.c  # (4, pieces, 2), highest power first
        piece = np.clip(np.searchsorted(knots, tg[:-1], side="right") - 1, 0, coef.shape[1] - 1)
        tables = {
            "tg": tg,
            "sg": path._sg,
            "px": path._pg[:, 0],
            "py": path._pg[:, 1],
            "origin": knots[piece],
            # fallback direction where the parametric speed vanishes (corners): grid angle
            "grid_angle": path._tangent_angle(tg),
        }
        cells = [knots[piece]]  # origin, then per axis: c0..c3, P' (d0, d1), P'' (e0)
        for axis in (0, 1):
            c = coef[:, piece, axis]
            cells += [c[0], c[1], c[2], c[3], 3.0 * c[0], 2.0 * c[1], 6.0 * c[0]]
        self.arrays = dict(tables)
        self.lists = {k: v.tolist() for k, v in tables.items()}
        #: per cell: (origin, c0x, c1x, c2x, c3x, d0x, d1x, e0x, c0y, …, e0y); as a
        #: (15, cells) array (N ships: one gather of the 15 coefficients) and as tuples
        self.cell_table = np.stack(cells)
        self.cell_tuples = list(zip(*(c.tolist() for c in cells), strict=True))
        self.grid_ux = np.cos(tables["grid_angle"])
        self.grid_uy = np.sin(tables["grid_angle"])
        self.n_grid = tg.size
        self.tiny = path._tiny_speed
        self.gl = list(zip(_GL_NODES.tolist(), _GL_WEIGHTS.tolist(), strict=True))
        self._widths: dict[float, int] = {}

    def _window_width(self, window: float) -> int:
        """Most grid points any arc-length window of ±``window`` [m] (plus the next point
        out on each side) can hold: the candidate count of the batched search."""
        if window not in self._widths:
            sg = self.arrays["sg"]
            lo = np.clip(np.searchsorted(sg, sg - window, side="right") - 1, 0, sg.size - 1)
            hi = np.clip(np.searchsorted(sg, sg + window, side="right"), 0, sg.size - 1)
            # windows centred between grid points hold at most one more point
            self._widths[window] = int(np.max(hi - lo)) + 2
        return self._widths[window]

    def _cell(self, j: Any, xp: Any) -> tuple[Any, ...]:
        """Cell coefficients: a tuple of floats (one ship) or of arrays gathered by j."""
        if xp.batched:
            return tuple(self.cell_table.take(j, axis=1))
        return self.cell_tuples[j]

    def follow(self, x: Any, y: Any, s_hint: Any, window: float | None, xp: Any) -> CurvePoint:
        tab = self.arrays if xp.batched else self.lists
        a = self.arrays
        last = self.n_grid - 1
        # -- coarse: nearest grid point among the candidates (first one on ties)
        if window is None:
            lo, hi = 0, last
        else:
            lo = xp.clip_index(xp.searchsorted_right(tab["sg"], s_hint - window) - 1, 0, last)
            hi = xp.clip_index(xp.searchsorted_right(tab["sg"], s_hint + window), 0, last)
        if xp.batched and window is not None and 2 * self._window_width(window) > self.n_grid:
            # windows spanning most of the grid: all grid points, those outside a ship's
            # window at +inf (the same candidates' distances, the same first minimum)
            dx = a["px"] - x[:, None]
            dy = a["py"] - y[:, None]
            d2 = dx * dx + dy * dy
            grid = np.arange(self.n_grid)
            d2[(grid < lo[:, None]) | (grid > hi[:, None])] = np.inf
            k = np.argmin(d2, axis=1)
        elif xp.batched:
            width = self.n_grid if window is None else self._window_width(window)
            idx = (
                np.minimum(lo + np.arange(width), hi)
                if window is None
                else np.minimum(lo[:, None] + np.arange(width), hi[:, None])
            )
            idx = np.broadcast_to(idx, (np.size(x), width))
            dx = a["px"][idx] - x[:, None]
            dy = a["py"][idx] - y[:, None]
            k = idx[np.arange(idx.shape[0]), np.argmin(dx * dx + dy * dy, axis=1)]
        else:
            dx = a["px"][lo : hi + 1] - x
            dy = a["py"][lo : hi + 1] - y
            k = lo + int(np.argmin(dx * dx + dy * dy))
        tg = tab["tg"]
        k_lo = xp.maximum(k - 1, 0)
        k_hi = xp.minimum(k + 1, last)
        t_lo, t_hi, t_k = tg[k_lo], tg[k_hi], tg[k]
        gx, gy = tab["px"][k] - x, tab["py"][k] - y
        d2_grid = gx * gx + gy * gy
        # -- Newton on g(t) = (P − q)·P' inside [t_lo, t_hi]
        t = t_k
        for _ in range(_NEWTON_ITERATIONS):
            j = xp.minimum(xp.where(t < t_k, k_lo, k), last - 1)
            px, py, dpx, dpy, ddx, ddy = _cubic(self._cell(j, xp), t)
            rx, ry = px - x, py - y
            g = rx * dpx + ry * dpy
            dg = dpx * dpx + dpy * dpy + rx * ddx + ry * ddy
            positive = dg > 0.0
            step = xp.where(positive, g / xp.where(positive, dg, 1.0), 0.0)
            t = xp.minimum(xp.maximum(t - step, t_lo), t_hi)
        j = xp.minimum(xp.where(t < t_k, k_lo, k), last - 1)
        cell = self._cell(j, xp)
        px, py, dpx, dpy, _, _ = _cubic(cell, t)
        rx, ry = px - x, py - y
        worse = rx * rx + ry * ry > d2_grid
        if xp.batched or worse:  # keep the grid point (one ship: rarely)
            t = xp.where(worse, t_k, t)
            j = xp.where(worse, xp.minimum(k, last - 1), j)
            cell = self._cell(j, xp)
            px, py, dpx, dpy, _, _ = _cubic(cell, t)
        # -- arc length: s_j + ∫_{tg_j}^{t} |P'| dt (8-point Gauss–Legendre, fixed order)
        t_j = tg[j]
        half = 0.5 * (t - t_j)
        mid = 0.5 * (t + t_j)
        acc = 0.0
        if xp.batched:  # the nodes as columns of one (N, 8) array; the sum in node order
            qx, qy = _velocity(
                tuple(c[:, None] for c in cell), mid[:, None] + half[:, None] * _GL_NODES
            )
            terms = _GL_WEIGHTS * np.sqrt(qx * qx + qy * qy)
            for column in terms.T:
                acc = acc + column
        else:
            for node, weight in self.gl:
                qx, qy = _velocity(cell, mid + half * node)
                acc = acc + weight * xp.sqrt(qx * qx + qy * qy)
        s = tab["sg"][j] + half * acc
        # -- tangent: P'/|P'| (the grid direction where P' vanishes, at corners)
        speed = xp.sqrt(dpx * dpx + dpy * dpy)
        stalled = speed <= self.tiny
        safe = xp.where(stalled, 1.0, speed)
        if xp.batched:
            ux = np.where(stalled, self.grid_ux[k], dpx / safe)
            uy = np.where(stalled, self.grid_uy[k], dpy / safe)
        else:
            ux = float(self.grid_ux[k]) if stalled else dpx / safe
            uy = float(self.grid_uy[k]) if stalled else dpy / safe
        angle = xp.where(stalled, tab["grid_angle"][k], xp.arctan2(dpy, dpx))
        angle = wrap_angle(angle)
        cross = -(x - px) * uy + (y - py) * ux
        return CurvePoint(k, t, s, px, py, ux, uy, angle, cross)


def _cubic(cell: tuple[Any, ...], t: Any) -> tuple[Any, ...]:
    """P, P' and P'' of a cell (:attr:`_CurveCells.cell_tuples`) at parameter t, by Horner."""
    o, c0x, c1x, c2x, c3x, d0x, d1x, e0x, c0y, c1y, c2y, c3y, d0y, d1y, e0y = cell
    tau = t - o
    return (
        ((c0x * tau + c1x) * tau + c2x) * tau + c3x,
        ((c0y * tau + c1y) * tau + c2y) * tau + c3y,
        (d0x * tau + d1x) * tau + c2x,
        (d0y * tau + d1y) * tau + c2y,
        e0x * tau + d1x,
        e0y * tau + d1y,
    )


def _velocity(cell: tuple[Any, ...], t: Any) -> tuple[Any, Any]:
    """P'(t) of a cell (the integrand of the arc length)."""
    tau = t - cell[0]
    return (cell[5] * tau + cell[6]) * tau + cell[3], (cell[12] * tau + cell[13]) * tau + cell[10]


# --------------------------------------------------------------------------------------------
# Waypoint switching
# --------------------------------------------------------------------------------------------
def acceptance_circle_reached(x: Any, y: Any, waypoint: tuple[Any, Any], radius: float) -> Any:
    """Liu et al. (2019) eq. (13): (x − x_{n+1})² + (y − y_{n+1})² ≤ R0² (all in m).

    The caller chooses R0; the paper uses R0 = 2L and requires R_LOS ≥ R0.
    """
    dx = x - waypoint[0]  # floats, or arrays over ships (the step core)
    dy = y - waypoint[1]
    return dx * dx + dy * dy <= radius * radius


def along_track_reached(frame: LegFrame, radius: float) -> bool:
    """Borkowski (2018) eq. (27): |P_i P_{i+1}| − x_r < R [m] (remaining along-track distance)."""
    return frame.leg_length - frame.along_track < radius


@dataclass(frozen=True)
class LegTable:
    """Per-leg constants of a polyline: start/end points, unit direction (c, s) = (cos ψp,
    sin ψp), length, angle and the angle change to the next leg; each a list (one ship) and
    an array (N ships: gathered by the leg index array)."""

    lists: dict[str, list[float]]
    arrays: dict[str, np.ndarray]
    last_leg: int
    goal: tuple[float, float]

    #: the order of the rows of :attr:`matrix`
    COLUMNS = ("x0", "y0", "x1", "y1", "c", "s", "length", "angle", "change")

    @cached_property
    def matrix(self) -> np.ndarray:
        """The arrays as one (len(COLUMNS), legs) array: N ships' constants in one gather."""
        return np.stack([self.arrays[name] for name in self.COLUMNS])

    @classmethod
    def of(cls, path: WaypointPath) -> LegTable:
        wp = [(float(p[0]), float(p[1])) for p in path.waypoints]
        legs = range(len(wp) - 1)
        # math.hypot / math.atan2: exactly the numbers of shipgym.paths.segment_frame
        length = [math.hypot(wp[i + 1][0] - wp[i][0], wp[i + 1][1] - wp[i][1]) for i in legs]
        lists = {
            "x0": [wp[i][0] for i in legs],
            "y0": [wp[i][1] for i in legs],
            "x1": [wp[i + 1][0] for i in legs],
            "y1": [wp[i + 1][1] for i in legs],
            "c": [(wp[i + 1][0] - wp[i][0]) / length[i] for i in legs],
            "s": [(wp[i + 1][1] - wp[i][1]) / length[i] for i in legs],
            "length": length,
            "angle": [math.atan2(wp[i + 1][1] - wp[i][1], wp[i + 1][0] - wp[i][0]) for i in legs],
            "change": [path.next_leg_angle_change(i) for i in legs],
        }
        arrays = {k: np.array(v) for k, v in lists.items()}
        return cls(lists, arrays, len(wp) - 2, wp[-1])


def advance_legs(
    x: Any, y: Any, leg: Any, table: LegTable, radius: float, switching: str, xp: Any
) -> Any:
    """Active leg(s) after the switching rule at position(s) (x, y) [m].

    Leg i ends at waypoint i + 1; while that waypoint counts as reached (``"circle"``: Liu et
    al. 2019 eq. (13), (x − x_{i+1})² + (y − y_{i+1})² ≤ R0²; ``"along_track"``: Borkowski
    2018 eq. (27), |P_i P_{i+1}| − x_r < R) the next leg becomes active, so several legs can
    be skipped in one call; the last leg is never left.
    """
    tab = table.arrays if xp.batched else table.lists
    last = table.last_leg
    for _ in range(last):
        if switching == "circle":
            reached = acceptance_circle_reached(x, y, (tab["x1"][leg], tab["y1"][leg]), radius)
        else:
            along = along_track(
                x - tab["x0"][leg], y - tab["y0"][leg], tab["c"][leg], tab["s"][leg]
            )
            reached = tab["length"][leg] - along < radius
        step = reached & (leg < last)
        if not xp.any(step):
            break
        leg = leg + step
    return leg


def advance_leg(
    path: WaypointPath,
    x: float,
    y: float,
    leg: int,
    radius: float,
    rule: Literal["circle", "along_track"] = "circle",
) -> int:
    """Active leg index after applying the waypoint switching rule at ship position (x, y) [m]
    (:func:`advance_legs` for one ship, with its arguments checked)."""
    if rule not in ("circle", "along_track"):
        raise ValueError(f"unknown switching rule {rule!r}; use 'circle' or 'along_track'")
    last = path.n_legs - 1
    if not 0 <= leg <= last:
        raise IndexError(f"leg {leg} out of range [0, {last}]")
    return advance_legs(float(x), float(y), int(leg), path.legs, radius, rule, SCALAR)
