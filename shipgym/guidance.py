"""Guidance laws: pure functions from (pose, path geometry, parameters) to a desired heading.

Sign conventions are those of :mod:`shipgym.paths`: ẋ = u cos ψ, ẏ = u sin ψ, path angle
ψp = atan2(Δy, Δx), cross-track e > 0 left of the path, so ė = u sin(ψ − ψp)
(Liu et al. 2019 eq. (7)).  Both vector-field papers use the same convention: Xu, Oliveira &
Guedes Soares (2021) define ye by eq. (3) — the formula of :func:`shipgym.paths.segment_frame`
— with ẏe = U sin(χ − γp) (eq. (8)), and Xu & Guedes Soares (2020) eq. (6) turns by
atan(−ye/Δ); so their ``χf − sign(ye)·(…)`` is used as printed: a ship left of the path
(ye > 0) is steered right (χd < χf), one right of it is steered left.  All headings returned
are wrapped to [−π, π).

Laws implemented:

* LOS with a circle of radius R_LOS around the ship — Liu et al. (2019) eqs. (5)–(12);
* look-ahead LOS — Xu & Guedes Soares (2020) eq. (6);
* vector field (VF) — Xu & Guedes Soares (2020) Algorithm 1: χd = χf − ρχe(|ye|/τ)^k inside
  the transition region |ye| < τ, χd = χf − ρχe outside, ρ = sign(ye);
* time-varying vector field (TVVF) — Xu, Oliveira & Guedes Soares (2021) eqs. (9), (48):
  χd = γp − sgn(ye)·atan(|ye|^θ / Δ), θ = 0.05|ye| + 1.

The LOS functions take floats and use the ``math`` module.  The VF and TVVF functions take
floats *or* numpy arrays (the batched env evaluates them over N ships) and compute both with
the same numpy ufuncs, so that a float result equals the matching element of an array result
bit for bit (``math.atan``/``math.pow`` differ from numpy's SIMD ``arctan``/``power`` in the
last bit for some inputs; tests/test_guidance_vf.py checks the identity).

Choices where the papers are silent or ambiguous (explicit options, paper value as default):

* VF exponent k: the paper states only k ≥ 1 (nomenclature) and gives no value; the default
  k = 1 is the smallest admissible one, for which the field is linear in ye inside the
  transition region and the convergence to the path exponential (k > 1 converges only
  algebraically near the path).  τ = 2L and χe = π/2 are Algorithm 1's initial values; the
  nomenclature's 0 < χe < π/2 is relaxed to χe ≤ π/2 to admit that initial value.
* VF line 16 (course-rate feed-forward of Nelson et al. 2007, −(kχeU/(ατ))(|ye|/τ)^(k−1)·
  sin(χ − χf)): α is not given in the paper, so the term is optional (``course_gain=None``
  leaves it out, which is what the env does: it observes heading, not course).  The paper
  prints sin(χ), the case χf = 0 of the path-relative sin(χ − χf) used here.
* TVVF units: θ = 0.05|ye| + 1 with ye in metres, the paper's (scale-model) units; the law
  is not dimensionally homogeneous, so for a full-scale ship θ grows large within a few
  tens of metres.  ``error_unit`` measures ye and Δ in another unit (e.g. ship lengths);
  the default 1 m is the paper's.
* Crab angle: both papers subtract the drift angle β (ψd = χd − β).  The env observes
  heading only, so ``sideslip`` defaults to 0 (the desired course is used as heading).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from shipgym.angles import wrap_angle
from shipgym.numerics import SCALAR
from shipgym.paths import segment_frame

__all__ = [
    "GUIDANCE_LAWS",
    "desired_heading",
    "lookahead_los_heading",
    "los_heading",
    "los_point",
    "los_radius",
    "los_relative_heading",
    "tvvf_heading",
    "tvvf_theta",
    "vector_field_heading",
]

Point = Sequence[float]  # (x, y) [m]; tuples, lists or numpy arrays
FloatOrArray = float | NDArray[np.float64]  # float in → float out; array in → array out

_PI = math.pi
_TWO_PI = 2.0 * math.pi
_HALF_PI = 0.5 * math.pi


# --------------------------------------------------------------------------------------------
# LOS guidance with an R_LOS circle — Liu et al. (2019) §2.2
# --------------------------------------------------------------------------------------------
#: Xu, Oliveira & Guedes Soares (2021)'s ship, the 1:100 Esso Osaka model: L = 3.25 m
TVVF_PAPER_SHIP_LENGTH = 3.25
#: scenario ``tvvf_error_unit`` → the unit [m] of ye and Δ in the TVVF law for a ship of
#: length L: the paper's metre, a ship length, or the paper's metre scaled to the ship
TVVF_ERROR_UNITS = {
    "m": lambda L: 1.0,
    "L": lambda L: L,
    "similar": lambda L: L / TVVF_PAPER_SHIP_LENGTH,
}


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


# --------------------------------------------------------------------------------------------
# Vector-field guidance — Xu & Guedes Soares (2020) §3; Xu, Oliveira & Guedes Soares (2021) §3
# Floats or arrays, the same numpy operations for both (module doc).
# --------------------------------------------------------------------------------------------
def _require(
    ok: bool | np.bool_ | NDArray[np.bool_], name: str, value: ArrayLike, cond: str
) -> None:
    """ValueError naming ``name`` unless ``ok`` (a bool, or an array of them: all true)."""
    if not (ok.all() if isinstance(ok, np.ndarray) else ok):
        raise ValueError(f"{name} must be {cond}, got {value}")


def vector_field_heading(
    cross_track: ArrayLike,
    path_angle: ArrayLike,
    tau: ArrayLike,
    entry_angle: float = _HALF_PI,
    k: float = 1.0,
    sideslip: ArrayLike = 0.0,
    *,
    course_gain: float | None = None,
    speed: ArrayLike = 0.0,
    course: ArrayLike | None = None,
) -> FloatOrArray:
    """Vector-field desired heading [rad] — Xu & Guedes Soares (2020) Algorithm 1.

    With ρ = sign(ye) (line 3):

    * |ye| ≥ τ (lines 8–11): χd = χf − ρχe, the constant entry angle towards the path;
    * |ye| < τ (lines 13–14): χd = χf − ρχe(|ye|/τ)^k;
    * ψd = χd − β, minus, if ``course_gain`` α is given and |ye| < τ, the course-rate
      feed-forward of line 16: (kχeU/(ατ))(|ye|/τ)^(k−1)·sin(χ − χf) (module doc).

    Outside the transition region the result is exactly the float χf ∓ χe − β (wrapping
    leaves values already in [−π, π) untouched).

    Args:
        cross_track: ye [m], > 0 left of the path (float or array).
        path_angle: χf [rad], path (tangent) angle at the reference point.
        tau: τ [m], > 0, width of the transition region (2L in the paper).
        entry_angle: χe [rad], 0 < χe ≤ π/2 (π/2 in the paper).
        k: exponent, ≥ 1 (the paper gives no value; module doc).
        sideslip: β [rad], course minus heading (χ = ψ + β, eq. (7)).
        course_gain: α [1/s] of the course response χ̇ = α(χc − χ) assumed by line 16;
            None (default) leaves the feed-forward term out.
        speed: U [m/s], ship speed, used only with ``course_gain``.
        course: χ [rad], ship course, required with ``course_gain``.

    Returns:
        ψd [rad] in [−π, π): a float for scalar inputs, else an array (broadcast shape).
    """
    e = np.asarray(cross_track, dtype=np.float64)
    tau_a = np.asarray(tau, dtype=np.float64)
    _require(tau_a > 0.0, "tau", tau, "> 0")
    _require(0.0 < entry_angle <= _HALF_PI, "entry_angle", entry_angle, "in (0, π/2]")
    _require(k >= 1.0, "k", k, "≥ 1")
    rho = np.sign(e)
    ratio = np.minimum(np.abs(e) / tau_a, 1.0)  # |ye|/τ, exactly 1 outside (1^k = 1)
    psi_d = path_angle - rho * entry_angle * np.power(ratio, k) - sideslip
    if course_gain is not None:
        _require(course_gain > 0.0, "course_gain", course_gain, "> 0")
        if course is None:
            raise ValueError("course is required when course_gain is given")
        gain = k * entry_angle * np.asarray(speed, dtype=np.float64) / (course_gain * tau_a)
        feed = gain * np.power(ratio, k - 1.0) * np.sin(np.subtract(course, path_angle))
        psi_d = psi_d - np.where(ratio < 1.0, feed, 0.0)
    return wrap_angle(psi_d)


def tvvf_theta(cross_track: ArrayLike, slope: float = 0.05, offset: float = 1.0) -> FloatOrArray:
    """θ(ye) = slope·|ye| + offset — Xu, Oliveira & Guedes Soares (2021) §5.2 (0.05, 1).

    Non-decreasing in |ye| with θ(0) = offset ≥ 1, as Definition 1 requires; ``slope`` is per
    unit of ye (1/m in the paper).
    """
    _require(slope >= 0.0, "theta slope", slope, "≥ 0")
    _require(offset >= 1.0, "theta offset", offset, "≥ 1 (Definition 1: θ(0) ≥ 1)")
    theta = slope * np.abs(np.asarray(cross_track, dtype=np.float64)) + offset
    return float(theta) if theta.ndim == 0 else theta


def tvvf_heading(
    cross_track: ArrayLike,
    path_angle: ArrayLike,
    delta: ArrayLike,
    theta: ArrayLike | None = None,
    sideslip: ArrayLike = 0.0,
    *,
    theta_slope: float = 0.05,
    theta_offset: float = 1.0,
    error_unit: float = 1.0,
) -> FloatOrArray:
    """Time-varying vector-field desired heading [rad] — Xu, Oliveira & Guedes Soares (2021).

    ψd = γp − sgn(ye)·atan(|ye|^θ / Δ) − β (eqs. (9), (48)), with ye and Δ expressed in
    ``error_unit`` before the power (1 m: the paper).  θ ≡ 1 gives look-ahead LOS
    (the remark after Definition 1; :func:`lookahead_los_heading`).  |ye|^θ may overflow to
    inf far from the path, where the law saturates at γp ∓ π/2.

    Args:
        cross_track: ye [m], > 0 left of the path (float or array).
        path_angle: γp [rad], path (tangent) angle at the reference point.
        delta: Δ [m], > 0 (2L in the paper).
        theta: θ, ≥ 1 (Definition 1), a number or an array broadcasting with ye; None
            (default): θ = theta_slope·|ye| + theta_offset (:func:`tvvf_theta`).
        sideslip: β [rad], course minus heading.
        theta_slope, theta_offset: the default θ's slope (per error unit) and offset.
        error_unit: [m], > 0, unit in which ye and Δ enter the law (module doc).

    Returns:
        ψd [rad] in [−π, π): a float for scalar inputs, else an array (broadcast shape).
    """
    e = np.asarray(cross_track, dtype=np.float64)
    delta_a = np.asarray(delta, dtype=np.float64)
    _require(delta_a > 0.0, "delta", delta, "> 0")
    _require(error_unit > 0.0, "error_unit", error_unit, "> 0")
    a = np.abs(e) / error_unit
    if theta is None:
        th = tvvf_theta(a, theta_slope, theta_offset)
    else:
        th = np.asarray(theta, dtype=np.float64)
        _require(th >= 1.0, "theta", theta, "≥ 1 (Definition 1)")
    with np.errstate(over="ignore"):  # |ye|^θ → inf far from the path: atan(inf) = π/2
        ratio = np.power(a, th) / (delta_a / error_unit)
    psi_d = path_angle - np.sign(e) * np.arctan(ratio) - sideslip
    return wrap_angle(psi_d)


# --------------------------------------------------------------------------------------------
# TVVF derivatives in ye — for controllers that feed ψ̇d, ψ̈d forward (Xu et al. 2021 eq. (35))
# Floats only (math module): one ship per call.
# --------------------------------------------------------------------------------------------
def tvvf_heading_derivatives(
    cross_track: float,
    delta: float,
    theta_slope: float = 0.05,
    theta_offset: float = 1.0,
    error_unit: float = 1.0,
) -> tuple[float, float]:
    """dψd/dye [rad/m] and d²ψd/dye² [rad/m²] of :func:`tvvf_heading` (default θ).

    ψd = γp − sgn(ye)·atan(q(a)/D) − β, a = |ye|/unit, D = Δ/unit, q(a) = a^θ(a),
    θ(a) = slope·a + offset.  With q' = q·(slope·ln a + θ/a) and
    q'' = q'·(slope·ln a + θ/a) + q·(2·slope/a − θ/a²), F = atan(q/D) has
    F' = (q'/D)/(1 + (q/D)²) and F'' = ((q''/D)(1 + (q/D)²) − 2(q/D)(q'/D)²)/(1 + (q/D)²)²;
    dψd/dye = −F'(a)/unit and d²ψd/dye² = −sgn(ye)·F''(a)/unit².  a is floored at 1e-9
    (the log singularity of q'' at ye = 0 has the small weight ``theta_slope``); far from the
    path (q/D > 1e12) both derivatives are 0.  γp and β are held constant.

    Args:
        cross_track: ye [m], > 0 left of the path.
        delta: Δ [m], > 0.
        theta_slope, theta_offset: θ's slope (per error unit) and offset.
        error_unit: [m], > 0, unit in which ye and Δ enter the law.
    """
    _require(delta > 0.0, "delta", delta, "> 0")
    _require(error_unit > 0.0, "error_unit", error_unit, "> 0")
    unit = error_unit
    d = delta / unit
    a = max(abs(cross_track) / unit, 1e-9)
    th = theta_slope * a + theta_offset
    log_a = math.log(a)
    log_ratio = th * log_a - math.log(d)  # ln(q/D)
    if log_ratio > math.log(1e12):
        return 0.0, 0.0
    g = math.exp(log_ratio)  # q/D
    lam = theta_slope * log_a + th / a  # q'/q
    g1 = g * lam  # q'/D
    g2 = g1 * lam + g * (2.0 * theta_slope / a - th / (a * a))  # q''/D
    den = 1.0 + g * g
    f1 = g1 / den
    f2 = (g2 * den - 2.0 * g * g1 * g1) / (den * den)
    sign = 1.0 if cross_track > 0 else (-1.0 if cross_track < 0 else 0.0)
    return -f1 / unit, -sign * f2 / (unit * unit)


# --------------------------------------------------------------------------------------------
# The law table: the only place a guidance law is added
# --------------------------------------------------------------------------------------------
def _los_law(g: Any, e: Any, path_angle: Any, L: float, scale: Any, xp: Any) -> Any:
    """LOS, Liu et al. (2019) eqs. (9), (12): ψp − asin(e / R_LOS), R_LOS = nL or |e| + L."""
    n_l = (g.los_radius_L * scale) * L
    abs_e = xp.abs(e)
    return path_angle - xp.arcsin(e / xp.where(abs_e <= n_l, n_l, abs_e + L))


def _lookahead_law(g: Any, e: Any, path_angle: Any, L: float, scale: Any, xp: Any) -> Any:
    """Look-ahead LOS, Xu & Guedes Soares (2020) eq. (6) with Δ = lookahead_L·L."""
    return wrap_angle(path_angle + xp.arctan(-e / (g.lookahead_L * L * scale)))


def _vf_law(g: Any, e: Any, path_angle: Any, L: float, scale: Any, xp: Any) -> Any:
    """VF, Xu & Guedes Soares (2020) Algorithm 1 with τ = vf_tau_L·L (numpy for both)."""
    return vector_field_heading(
        e, path_angle, g.vf_tau_L * L * scale, math.radians(g.vf_chi_e_deg), g.vf_k
    )


def _tvvf_law(g: Any, e: Any, path_angle: Any, L: float, scale: Any, xp: Any) -> Any:
    """TVVF, Xu, Oliveira & Guedes Soares (2021) eqs. (9), (48) with Δ = tvvf_delta_L·L."""
    return tvvf_heading(
        e,
        path_angle,
        g.tvvf_delta_L * L * scale,
        theta_slope=g.tvvf_theta_slope,
        theta_offset=g.tvvf_theta_offset,
        error_unit=TVVF_ERROR_UNITS[g.tvvf_error_unit](L),
    )


#: law name (a scenario's ``guidance.law``) → ``law(settings, e [m], ψp [rad], L [m], scale,
#: xp) -> ψd [rad]``: ``settings`` holds the law's parameters (a scenario's ``guidance:``
#: block), ``scale`` multiplies its length scale (the guidance action's 2^a0), ``xp`` is
#: SCALAR (floats) or ARRAY (arrays over ships) of :mod:`shipgym.numerics`.
GUIDANCE_LAWS: dict[str, Callable[..., Any]] = {
    "los": _los_law,
    "lookahead_los": _lookahead_law,
    "vf": _vf_law,
    "tvvf": _tvvf_law,
}


def desired_heading(
    settings: Any,
    cross_track: Any,
    path_angle: Any,
    ship_length: float,
    scale: Any = 1.0,
    xp: Any = SCALAR,
    law: str | None = None,
) -> Any:
    """Desired heading [rad] of the law ``law`` (default ``settings.law``) from the table
    :data:`GUIDANCE_LAWS`, for one ship (floats) or N (arrays, ``xp=ARRAY``)."""
    name = settings.law if law is None else law
    try:
        fn = GUIDANCE_LAWS[name]
    except KeyError:
        raise ValueError(
            f"unknown guidance law {name!r}; valid: {', '.join(GUIDANCE_LAWS)}"
        ) from None
    return fn(settings, cross_track, path_angle, ship_length, scale, xp)
