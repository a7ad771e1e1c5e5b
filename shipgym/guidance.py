"""Guidance laws: pure functions from (pose, path geometry, parameters) to a desired heading.

Floats in, floats out, using only the ``math`` module (they run every environment step).
Sign conventions are those of :mod:`shipgym.paths`: ẋ = u cos ψ, ẏ = u sin ψ, path angle
ψp = atan2(Δy, Δx), cross-track e > 0 left of the path, so ė = u sin(ψ − ψp)
(Liu et al. 2019 eq. (7)).  All headings returned are wrapped to [−π, π).

Laws implemented:

* LOS with a circle of radius R_LOS around the ship — Liu et al. (2019) eqs. (5)–(12);
* look-ahead LOS — Xu & Guedes Soares (2020) eq. (6).

Vector-field guidance (Xu & Guedes Soares 2020 Algorithm 1; time-varying VF of Xu, Oliveira &
Guedes Soares 2021 eqs. (9), (48)) is added by a later issue as further functions of the same
shape: ``(cross_track, path_angle, params...) -> desired heading``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from shipgym.paths import segment_frame, wrap_angle

__all__ = [
    "lookahead_los_heading",
    "los_heading",
    "los_point",
    "los_radius",
    "los_relative_heading",
]

Point = Sequence[float]  # (x, y) [m]; tuples, lists or numpy arrays


# --------------------------------------------------------------------------------------------
# LOS guidance with an R_LOS circle — Liu et al. (2019) §2.2
# --------------------------------------------------------------------------------------------
def los_radius(cross_track: float, ship_length: float, n: float = 3.0) -> float:
    """LOS circle radius R_LOS [m] — Liu et al. (2019) eq. (12).

    R_LOS = nL if |e| ≤ nL, else |e| + L, which guarantees |e| < R_LOS so that eq. (9) has a
    real solution.  The paper writes the condition with e, but it means the magnitude |e|
    (a negative e would otherwise give R_LOS = 3L < |e| and no intersection).

    Args:
        cross_track: e [m].
        ship_length: L [m], > 0.
        n: circle radius in ship lengths (3 in the paper).
    """
    if not ship_length > 0.0:
        raise ValueError(f"ship_length must be > 0, got {ship_length}")
    n_l = n * ship_length
    abs_e = abs(cross_track)
    return n_l if abs_e <= n_l else abs_e + ship_length


def los_relative_heading(cross_track: float, radius: float) -> float:
    """Desired heading relative to the path ψ̃_LOS [rad] — Liu et al. (2019) eq. (9).

    ψ̃_LOS = −arcsin(e / R_LOS); raises ValueError if |e| > R_LOS (no LOS point exists).
    """
    ratio = cross_track / radius
    if abs(ratio) > 1.0:
        if abs(ratio) > 1.0 + 1e-12:
            raise ValueError(
                f"|cross_track| = {abs(cross_track)} m exceeds the LOS radius {radius} m"
            )
        ratio = math.copysign(1.0, ratio)
    return -math.asin(ratio)


def los_point(
    x: float, y: float, p_start: Point, p_end: Point, radius: float
) -> tuple[float, float]:
    """LOS point (x_LOS, y_LOS) [m] — geometric solution of Liu et al. (2019) eqs. (5)–(6).

    Intersects the circle of radius `radius` [m] around the ship (eq. (5)) with the line
    through the leg p_start → p_end (eq. (6)) and returns the intersection closer to p_end,
    as the paper prescribes.  While the ship has not passed p_end (along-track x_r ≤ leg
    length) this is the forward intersection, whose bearing from the ship is ψp + ψ̃_LOS
    (eq. (9)); beyond p_end it is the backward one.  Raises ValueError if |e| > R (no real
    intersection) or if the leg has zero length.
    """
    f = segment_frame(x, y, (p_start[0], p_start[1]), (p_end[0], p_end[1]))
    e = f.cross_track
    disc = radius * radius - e * e
    if disc < 0.0:
        if disc < -1e-12 * radius * radius:
            raise ValueError(
                f"no LOS point: |cross_track| = {abs(e)} m exceeds the radius {radius} m"
            )
        disc = 0.0
    half_chord = math.sqrt(disc)
    fwd = f.along_track + half_chord
    bwd = f.along_track - half_chord
    a = fwd if abs(fwd - f.leg_length) <= abs(bwd - f.leg_length) else bwd
    c = math.cos(f.path_angle)
    s = math.sin(f.path_angle)
    return float(p_start[0]) + a * c, float(p_start[1]) + a * s


def los_heading(
    x: float, y: float, p_start: Point, p_end: Point, ship_length: float, n: float = 3.0
) -> tuple[float, float, float]:
    """Desired LOS heading for the leg p_start → p_end — Liu et al. (2019) eqs. (9), (12).

    ψ_LOS = ψp + ψ̃_LOS with ψ̃_LOS = −arcsin(e / R_LOS) and R_LOS from eq. (12).

    Args:
        x, y: ship position [m].
        p_start, p_end: leg end points P_n, P_{n+1} [m].
        ship_length: L [m].
        n: LOS radius in ship lengths.

    Returns:
        (desired_heading [rad] in [−π, π), R_LOS [m], cross_track e [m]).
    """
    f = segment_frame(x, y, (p_start[0], p_start[1]), (p_end[0], p_end[1]))
    radius = los_radius(f.cross_track, ship_length, n)
    psi_rel = los_relative_heading(f.cross_track, radius)
    return wrap_angle(f.path_angle + psi_rel), radius, f.cross_track


# --------------------------------------------------------------------------------------------
# Look-ahead LOS — Xu & Guedes Soares (2020) §3
# --------------------------------------------------------------------------------------------
def los_desired_heading(
    cross_track: float, path_angle: float, ship_length: float, n: float = 3.0
) -> float:
    """ψ_LOS = ψp + ψ̃_LOS with R_LOS of eq. (12): Liu et al. (2019) eq. (9)–(12) [rad]."""
    return path_angle + los_relative_heading(cross_track, los_radius(cross_track, ship_length, n))


def lookahead_los_heading(
    cross_track: float, path_angle: float, lookahead: float, sideslip: float = 0.0
) -> float:
    """Look-ahead LOS desired heading [rad] — Xu & Guedes Soares (2020) eq. (6).

    ψd = χf + atan(−ye / Δ) − β, wrapped to [−π, π).

    Args:
        cross_track: ye [m] (positive left of the path, so the correction turns right).
        path_angle: χf [rad], path (tangent) angle at the reference point.
        lookahead: Δ [m], > 0.
        sideslip: β [rad], course minus heading (χ = ψ + β, eq. (7)).
    """
    if not lookahead > 0.0:
        raise ValueError(f"lookahead must be > 0, got {lookahead}")
    return wrap_angle(path_angle + math.atan(-cross_track / lookahead) - sideslip)
