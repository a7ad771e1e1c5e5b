"""Nomoto regressors and parameter extraction (Liu et al. 2019 §3.1.2, eq. (31)–(42)).

Forward differences of order n at spacing h (eq. (32)) turn the 2nd-order nonlinear Nomoto
model (1) and the rudder servo (2) into two linear regressions y = θᵀx:

* eq. (35)–(36):  y1 = Δ³ψ,  x1 = [−hΔ²ψ, h³δ, h³, −h²Δψ, −(Δψ)³, h²Δδ],
                  θ1 = [T1+T2, K, d0, 1, β, K·T3] / (T1·T2);
* eq. (37):       y2 = (δc − δ)·h,  x2 = Δδ,  θ2 = Tc;

and the parameters follow from θ1 by the algebra after eq. (42) (T1 > T2 root).  The rows
are defined once (:func:`regression_rows`) on increments Δⁿψ ≈ hⁿψ⁽ⁿ⁾; where those come
from is the *front end* (:mod:`shipgym.identification.front_end`): the paper's differences
(default) or an outlier filter + state-variable filter (``front_end="svf"``, an extension
beyond the paper for noisy headings).

Forward-difference bias (h = 0.01 s).  Δⁿf(t)/hⁿ = f⁽ⁿ⁾(t + nh/2) + O(h²): the terms of
(33) are evaluated at t + 1.5h, t + h, t + h/2 and t, so the regression is consistent only
to O(h).  For the servo, with δc held over a fine step the exact update is
Δδ = (δc − δ)(1 − e^{−h/Tc}), so eq. (34) estimates θ2 = h/(1 − e^{−h/Tc}) ≈ Tc + h/2:
+5.1 % at Tc = 0.1 s, +0.5 % at Tc = 1 s.  ``servo_model="exact"`` inverts that relation,
Tc = −h / ln(1 − h/θ2), and is exact for a piecewise-constant command; ``"forward"`` is the
paper's eq. (34) as written.  All angles in rad, rates in rad/s, SI parameters.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from shipgym.identification.errors import (
    IdentificationError,
    check_log_arrays,
    check_log_span,
    check_sampling_step,
)
from shipgym.identification.front_end import (
    PAPER_GAMMA,
    FrontEndSettings,
    RegressionSignals,
    difference_signals,
)
from shipgym.identification.lssvm import LSSVMSolution, lssvm_primal, weighted_lssvm
from shipgym.models.nomoto2 import Nomoto2Params

__all__ = [
    "GAMMA",
    "NomotoRegression",
    "fit_nomoto2",
    "front_end_settings",
    "nomoto_regressors",
    "params_from_theta1",
    "regression_rows",
    "theta1_from_params",
]

#: γ of Liu et al. (2019) §4
GAMMA = PAPER_GAMMA


@dataclasses.dataclass(frozen=True)
class NomotoRegression:
    """Regression data of eq. (35)–(37), one row per time t_k with ψ(t_k … t_k+3h) known."""

    y1: np.ndarray  # (n,) Δ³ψ
    x1: np.ndarray  # (n, 6)
    y2: np.ndarray  # (n,) (δc − δ)·h
    x2: np.ndarray  # (n, 1) Δδ


def regression_rows(signals: RegressionSignals, h: float) -> NomotoRegression:
    """The rows of eq. (35)–(37) from a front end's signals at spacing h [s] (one definition
    for every front end; with the differences these are the paper's rows bit for bit)."""
    s = signals
    x1 = np.empty((len(s), 6))
    x1[:, 0] = -h * s.psi2
    x1[:, 1] = h**3 * s.delta
    x1[:, 2] = h**3
    x1[:, 3] = -(h**2) * s.psi1
    x1[:, 4] = -(s.psi1**3)
    x1[:, 5] = h**2 * s.delta1
    y2 = (s.servo_command - s.servo_delta) * h
    return NomotoRegression(s.psi3, x1, y2, s.servo_delta1[:, None])


def _check_log(psi: np.ndarray, delta: np.ndarray, delta_c: np.ndarray) -> tuple[np.ndarray, ...]:
    return tuple(check_log_arrays((psi, delta, delta_c), finite=True))


def nomoto_regressors(
    psi: np.ndarray, delta: np.ndarray, delta_c: np.ndarray, h: float
) -> NomotoRegression:
    """Build eq. (35)–(37) from heading ψ [rad], rudder δ and command δc [rad] at spacing h [s]
    with the paper's forward differences."""
    h = check_sampling_step(h)
    psi, delta, delta_c = _check_log(psi, delta, delta_c)
    if psi.shape[0] < 4:
        raise IdentificationError(f"need at least 4 samples for Δ³ψ, got {psi.shape[0]}")
    return regression_rows(difference_signals(psi, delta, delta_c), h)


def theta1_from_params(p: Nomoto2Params) -> np.ndarray:
    """θ1 of eq. (36) from parameters."""
    return np.array([p.T1 + p.T2, p.K, p.d0, 1.0, p.beta, p.K * p.T3]) / (p.T1 * p.T2)


def time_constants(total: float, product: float) -> tuple[float, float]:
    """T1 ≥ T2 with T1 + T2 = ``total`` and T1·T2 = ``product`` (roots of s² − S·s + P)."""
    disc = total * total - 4.0 * product
    if disc < 0:
        raise IdentificationError(f"T1, T2 complex: (T1 + T2)² − 4·T1·T2 = {disc:.3g} < 0")
    root = math.sqrt(disc)
    return float((total + root) / 2.0), float((total - root) / 2.0)


def params_from_theta1(theta1: np.ndarray) -> dict[str, float]:
    """K, T1, T2, T3, d0, β from θ1 (Liu et al. 2019, after eq. (42), T1 > T2).

    Raises IdentificationError for a non-physical θ1 (θ1(4) ≤ 0, complex T1/T2, K = 0).
    """
    t = np.asarray(theta1, dtype=float)
    if not np.all(np.isfinite(t)):
        raise IdentificationError("θ1 is not finite")
    if t[3] <= 0:
        raise IdentificationError(f"θ1(4) = 1/(T1·T2) = {t[3]:.3g} ≤ 0")
    if t[1] == 0:
        raise IdentificationError("K = 0: the rudder has no effect in the data")
    # θ1(1)/θ1(4) = T1 + T2, 1/θ1(4) = T1·T2
    t1, t2 = time_constants(t[0] / t[3], 1.0 / t[3])
    return {
        "K": t[1] / t[3],
        "T1": t1,
        "T2": t2,
        "T3": t[5] / t[1],
        "d0": t[2] / t[3],
        "beta": t[4] / t[3],
    }


def tc_from_theta2(theta2: float, h: float, servo_model: str = "forward") -> float:
    """Tc from θ2 of eq. (37): as estimated (``forward``) or ZOH-corrected (``exact``)."""
    # for any Tc > 0 a held command gives θ2 = h/(1 − e^{−h/Tc}) > h (module doc): θ2 ≤ h
    # is not a servo the data can show, whichever reading of eq. (34) is used
    if not theta2 > h:
        raise IdentificationError(f"θ2 = {theta2:.3g} ≤ h = {h}: no physical servo time constant")
    if servo_model == "forward":
        return float(theta2)
    if servo_model == "exact":
        return -h / math.log(1.0 - h / theta2)
    raise ValueError(f"servo_model must be 'forward' or 'exact', got {servo_model!r}")


def solve_theta(
    x: np.ndarray,
    y: np.ndarray,
    gamma: float = GAMMA,
    weighted: bool = True,
    bias_penalty: bool = True,
    prior_weights: np.ndarray | None = None,
) -> tuple[LSSVMSolution, np.ndarray]:
    """θ̂ of one sub-model by (weighted) bias-penalised LS-SVM, primal solve (eq. (39)–(42))."""
    if weighted:
        return weighted_lssvm(x, y, gamma, bias_penalty, prior_weights=prior_weights)
    sol = lssvm_primal(x, y, gamma, prior_weights, bias_penalty)
    return sol, np.ones_like(y) if prior_weights is None else np.asarray(prior_weights)


def excitation_problem(x1: np.ndarray, x2: np.ndarray) -> str | None:
    """Why regression rows of eq. (36)–(37) cannot identify the model (None if they can)."""
    if x1.shape[0] == 0 or np.ptp(x1[:, 1]) == 0.0:
        return "rudder angle constant over the data: no excitation (eq. (45)); model kept"
    if not np.any(x2[:, 0] != 0.0):
        return "the rudder never moves: Tc not identifiable; model kept"
    return None


def fit_nomoto2(
    psi: np.ndarray,
    delta: np.ndarray,
    delta_c: np.ndarray,
    h: float,
    *,
    gamma: float | None = None,
    weighted: bool = True,
    bias_penalty: bool = True,
    servo_model: str = "forward",
    base: Nomoto2Params | None = None,
    front_end: str | FrontEndSettings = "differences",
    svf_bandwidth: float | None = None,
    outlier_filter: bool | None = None,
    outlier_window: int | None = None,
    outlier_threshold: float | None = None,
) -> Nomoto2Params:
    """Batch fit of the nomoto2 parameters from sampled ψ, δ, δc [rad] at spacing h [s].

    Liu et al. (2019) eq. (31)–(42): weighted (robust) bias-penalised LS-SVM with a linear
    kernel, solved in its primal form.  ``front_end``: ``"differences"`` (the paper's
    eq. (32), default) or ``"svf"`` (Hampel outlier filter + state-variable filter of
    bandwidth ``svf_bandwidth`` [rad/s], :mod:`shipgym.identification.front_end`), or a
    :class:`FrontEndSettings`; ``gamma`` None: the front end's γ (the paper's 1e15 with the
    differences, 1e20 with the SVF: ``FrontEndSettings.gamma``).  Returns a
    :class:`Nomoto2Params` in SI units (u0, L, Kc from ``base``).  Raises
    IdentificationError (naming the reason) on bad input or degenerate data: a non-finite
    sample (array and index), arrays of different lengths (their names), a log shorter than
    5 × T1 of ``base`` (default: Liu's ship) or of the identified model (the minimum
    length).
    """
    h = check_sampling_step(h)
    settings = front_end_settings(
        front_end, svf_bandwidth, outlier_filter, outlier_window, outlier_threshold
    )
    gamma = settings.gamma if gamma is None else gamma
    if settings.front_end == "differences" and not settings.use_outlier_filter:
        # the paper's rows, exactly as eq. (35)-(37)
        reg = nomoto_regressors(psi, delta, delta_c, h)
    else:
        psi, delta, delta_c = _check_log(psi, delta, delta_c)
        signals, _ = settings.make(h).push(psi, delta, delta_c)
        if len(signals) < 10:
            raise IdentificationError(
                f"{psi.shape[0]} samples leave {len(signals)} rows after the {settings.front_end} "
                "front end's start transient and delay: need a longer log"
            )
        reg = regression_rows(signals, h)
    base = base if base is not None else Nomoto2Params()
    problem = excitation_problem(reg.x1, reg.x2)
    if problem is not None:
        raise IdentificationError(problem)
    n = np.asarray(psi).shape[0]
    check_log_span(n, h, base.T1, "the base model")
    sol1, _ = solve_theta(reg.x1, reg.y1, gamma, weighted, bias_penalty)
    sol2, _ = solve_theta(reg.x2, reg.y2, gamma, weighted, bias_penalty)
    values = params_from_theta1(sol1.theta)
    values["Tc"] = tc_from_theta2(float(sol2.theta[0]), h, servo_model)
    check_log_span(n, h, values["T1"], "the identified model")
    try:
        return base.replace(**values)
    except ValueError as exc:
        raise IdentificationError(f"identified parameters are not physical: {exc}") from exc


def front_end_settings(
    front_end: str | FrontEndSettings = "differences",
    svf_bandwidth: float | None = None,
    outlier_filter: bool | None = None,
    outlier_window: int | None = None,
    outlier_threshold: float | None = None,
) -> FrontEndSettings:
    """The :class:`FrontEndSettings` of the keyword options (None: the default)."""
    given = {
        k: v
        for k, v in (
            ("svf_bandwidth", svf_bandwidth),
            ("outlier_filter", outlier_filter),
            ("outlier_window", outlier_window),
            ("outlier_threshold", outlier_threshold),
        )
        if v is not None
    }
    if isinstance(front_end, FrontEndSettings):
        return dataclasses.replace(front_end, **given) if given else front_end
    if not isinstance(front_end, str):
        raise IdentificationError(
            f"front_end must be 'differences' or 'svf' (or FrontEndSettings), got {front_end!r}"
        )
    return FrontEndSettings(front_end, **given)
