"""The NMPC family on every ship: prediction model and numbers from the ship's own time scales.

Liu et al. (2019) tuned the NMPC and its identifiers for one ship, the 0.95 m nomoto2 model
(the *paper ship*: T = T1 + T2 − T3 = 1.448 s, L/U = 1.19 s, Ts = 0.5 s, h = 0.01 s).  On
every ship the family runs the same controller with numbers derived by the rules below from
what the controller context gives (the nominal model, L, U, Ts, h, the LOS radius: never the
truth).  Every rule returns the paper's number on the paper ship (tested).  On nomoto2 the
rules are evaluated on the paper ship's time scales whatever the scenario's parameters (Liu
et al. keep N_p, N_w, … in all their cases, whose ships differ: Case 3's T1 = 3 s), so
nomoto2 runs exactly as before and ``shipgym reproduce liu2019`` is unchanged bit for bit.

**Prediction model.** Always the nomoto2 structure (eq. (1)–(4), the model the LS-SVM
identifiers estimate online), with u0 = U and L of the ship:

* nomoto2 (a closed-form Nomoto model): its nominal parameters as they are;
* every other ship: the fit to its own 20/20 zig-zag, the nominal model PID and LQR use
  (:func:`shipgym.identification.zigzag.ship_nomoto`: K, T1, T2, T3, d0 and the servo's
  effective Tc), *reduced to first order*: T1 = T = T1 + T2 − T3 (Nomoto's approximation,
  ``first_order_nomoto``), T2 = T3 = Tc, β = 0, Kc = 1.  The pole at −1/T2 is cancelled by
  the zero at −1/T3, so δ → r is exactly K/(1 + T·s); the servo's Tc is then the fastest mode.
  Why: on these ships the fitted T2 (0.19 s Esso Osaka, 0.10 s Mariner, 0.09 s Blanke) is of
  the order of the fit's sampling step h and nearly cancelled by the fitted T3 (0.35, 0.29,
  0.22 s): an artefact, not a yaw mode, but RK4 would have to resolve it, ≈ 300 substeps
  per prediction interval on the Mariner.  The online identifiers still estimate all of K,
  T1, T2, T3, d0, β, Tc; each estimate reaches the prediction through the same reduction
  (:meth:`ShipNMPCPlan.prediction_params`): K, d0 and T = T1 + T2 − T3 adapt; an estimate
  with K ≤ 0 or T ≤ 0 keeps the previous model (no real plant has them; the weighted
  LS-SVM, which keeps a K < 0 on nomoto2 as the paper's Figure 7 shows, otherwise steered
  the Esso Osaka and the Blanke ship out of their corridors), and K, T are clipped to
  [x/2, 2x] around the nominal model (F = :data:`PROJECTION_FACTOR`, as the adaptive LQR's
  projection): the training distribution changes a ship's rudder effectiveness by ×0.6–1.5;
  on the Blanke ship the paper's differences front end estimates T anywhere in 0.11–27 s
  (nominal 2.86 s), and a T of 0.16 s made the NMPC circle 300 m off the path (3 randomised
  trials: ACE 91 m, no goal; with F = 3 one trial 48 m; with F = 2 all three 7.9–9.5 m, at
  the goal, against 7.7 m for ``nmpc``); β, Tc stay nominal.  β is not identifiable at the
  yaw rates of path following (Esso Osaka estimates range −4 … 140 s²), and these ships'
  steering gears are rate-limited, so the servo regression's Tc is an amplitude-dependent
  fit (0.13 s on the Esso Osaka's small corrections against 0.88 s in its zig-zag), not a
  parameter to adapt; taken into the prediction, it made RK4 diverge in 60 % of the steps.

**Numbers** (T, K: the nominal first-order Nomoto model; τ_f = min(T2, Tc) of the nominal
prediction model; n = the scenario's ``los_radius_L``; subscript p: the paper ship):

* horizon time t_H = max((n + 1)·L/U, 3·T): the LOS look-ahead travelled plus one ship
  length, and 95 % of the heading response (paper ship: max(4.75, 4.34) s);
* prediction interval k·Ts with k = ⌈t_H / (10·Ts)⌉ control periods (move blocking: each
  planned command is held for k periods in the prediction, the first is applied for one),
  so that N_p = ⌈t_H / (k·Ts)⌉ ≤ 10, the paper's N_p, and N_c = min(8, N_p): the QP keeps the
  paper's size and cost on every ship (paper ship: k = 1, N_p = 10, N_c = 8);
* RK4 substeps per interval ⌈k·Ts / (τ_f/2)⌉: |h·λ| ≤ 0.5 for the fastest mode, well inside
  RK4's stability limit 2.79, so that an identified mode up to 5 × faster stays stable
  (paper ship: τ_f = Tc = 0.1 s → 10);
* cost weights in the paper ship's Froude units: Q_e·(L_p/L)², Q_r·(τ/τ_p)², Q_ṙ·(τ/τ_p)⁴
  with τ = L/U; the heading, rudder and R weights (rad) unchanged;
* identifier window N_w·h = (12 s / T_p)·T ≈ 8.3·T (the paper's 1200 samples × 0.01 s in
  units of T), re-identified every N_u samples, N_u·h = N_w·h / 24 (the paper's ratio)
  rounded to whole control periods (at least one);
* change thresholds of λ-LS-SVM (eq. (43)): λ_c¹ in units of Δ³ψ ≈ h³·ψ‴, ψ‴ ∼ K·δ/T²:
  λ_c¹ = 1e-5·(h³K/T²)/(h³K/T²)_p; λ_c² in units of (δc − δ)·h: λ_c² = 1e-2·h/h_p;
* SVF bandwidth (the ``_svf`` variants) 3 rad/s·T_p/T;
* persistent excitation (eq. (45), off by default as on nomoto2): each draw is held for
  max(1, round((Ts_p/T_p)·T/Ts)) control periods, so that the excitation's spectrum has the
  same place relative to the ship's bandwidth as the paper's (one draw per 0.35·T).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from typing import Any

from shipgym.envs.context import ControllerContext
from shipgym.identification.front_end import SVF_BANDWIDTH
from shipgym.identification.nominal import first_order_nomoto
from shipgym.identification.online import PAPER_LAMBDA_C, PAPER_UPDATE_EVERY, PAPER_WINDOW
from shipgym.identification.zigzag import ship_nomoto
from shipgym.models.base import ParameterError
from shipgym.models.nomoto2 import Nomoto2, Nomoto2Params, nomoto2_first_order

#: the paper's N_p, N_c, Q (Liu et al. 2019 §4; ``NMPCSettings``' defaults)
PAPER_HORIZON = 10
PAPER_CONTROL_HORIZON = 8
PAPER_Q = (1.0, 1.0, 0.01, 0.01, 0.001)
#: N_w / N_u of the paper's identifiers (1200 / 50)
PAPER_WINDOW_TO_UPDATE = PAPER_WINDOW / PAPER_UPDATE_EVERY
#: RK4 step per fastest time constant τ_f (|h·λ| ≤ 0.5)
STEP_PER_FAST_TIME_CONSTANT = 0.5
#: heading response settled (95 %) after 3 T
SETTLING_TIME_CONSTANTS = 3.0
#: F: estimates of K and T reach the prediction clipped to [x/F, x·F] around the nominal
PROJECTION_FACTOR = 2.0


@dataclasses.dataclass(frozen=True)
class ShipTimeScales:
    """The time scales the rules use (SI): first-order Nomoto K [1/s], T [s]; L [m]; U [m/s];
    Ts, h [s]; the fastest mode τ_f [s] of the prediction model; the LOS radius n [L]."""

    K: float
    T: float
    L: float
    U: float
    Ts: float
    h: float
    fast: float
    los_radius_L: float

    @property
    def length_time(self) -> float:
        """L/U [s]: the time to travel one ship length."""
        return self.L / self.U


@functools.cache
def paper_ship() -> ShipTimeScales:
    """The paper ship's time scales (nomoto2 with Liu et al.'s parameters, n = 3)."""
    return time_scales(Nomoto2Params(), Nomoto2.control_period, Nomoto2.fine_step, 3.0)


def time_scales(
    params: Nomoto2Params, control_period: float, fine_step: float, los_radius_L: float
) -> ShipTimeScales:
    """:class:`ShipTimeScales` of a nomoto2 prediction model (Ts, h [s]; n [L])."""
    K, T = nomoto2_first_order(params.K, params.T1, params.T2, params.T3)
    return ShipTimeScales(
        K=K,
        T=T,
        L=params.L,
        U=params.u0,
        Ts=control_period,
        h=fine_step,
        fast=min(params.T2, params.Tc),
        los_radius_L=los_radius_L,
    )


def _ceil(x: float) -> int:
    """⌈x⌉ forgiving the last bits of rounding (10.000000000000002 → 10)."""
    return math.ceil(x - 1e-9 * abs(x))


def nominal_prediction_params(context: ControllerContext) -> Nomoto2Params:
    """The nominal prediction model's parameters (module doc): nomoto2's own, else the
    first-order reduction of the ship's zig-zag fit."""
    model = context.nominal_model
    if isinstance(context.nominal_params, Nomoto2Params):
        return context.nominal_params
    fit, tc = ship_nomoto(model)
    K, T = first_order_nomoto(model)
    return Nomoto2Params(
        K=K,
        T1=T,
        T2=tc,
        T3=tc,
        d0=fit.d0,
        beta=0.0,
        Tc=tc,
        Kc=1.0,
        u0=context.nominal_speed,
        L=context.ship_length,
    )


@dataclasses.dataclass(frozen=True)
class ShipNMPCPlan:
    """Everything the NMPC family derives from one ship's time scales (module doc)."""

    nominal: Nomoto2Params  # the nominal prediction model
    reduce: bool  # estimates are reduced to first order (ships without a closed form)
    scales: ShipTimeScales
    horizon: int  # N_p
    control_horizon: int  # N_c
    interval: int  # k: control periods per prediction interval
    substeps: int  # RK4 steps per prediction interval
    Q: tuple[float, float, float, float, float]
    window: int  # N_w [samples]
    update_every: int  # N_u [samples]
    lambda_c: tuple[float, float]
    svf_bandwidth: float  # [rad/s]
    excitation_hold: int  # control periods per excitation draw

    @property
    def horizon_time(self) -> float:
        """N_p·k·Ts [s]."""
        return self.horizon * self.interval * self.scales.Ts

    def prediction_params(self, estimate: Nomoto2Params) -> Nomoto2Params | None:
        """An identified model in the prediction model's structure, K and T clipped to
        [x/F, x·F] around the nominal (None: K ≤ 0 or T ≤ 0)."""
        if not self.reduce:
            return estimate
        try:
            K, T = nomoto2_first_order(estimate.K, estimate.T1, estimate.T2, estimate.T3)
        except ParameterError:
            return None
        if not K > 0:  # a real plant steers the documented way (Nomoto2Params.plant_positive)
            return None
        n, f = self.nominal, PROJECTION_FACTOR
        K = min(max(K, self.scales.K / f), self.scales.K * f)
        T = min(max(T, self.scales.T / f), self.scales.T * f)
        return estimate.replace(K=K, T1=T, T2=n.T2, T3=n.T3, beta=n.beta, Tc=n.Tc)

    def identifier_options(self, lambda_thresholds: bool) -> dict[str, Any]:
        """Window, update period (and λ_c¹, λ_c² for λ-LS-SVM) of the online identifiers."""
        options: dict[str, Any] = {"window": self.window, "update_every": self.update_every}
        if lambda_thresholds:
            options["lambda_c1"], options["lambda_c2"] = self.lambda_c
        return options

    def as_dict(self) -> dict[str, Any]:
        """The derived numbers (for reports): horizon, interval, substeps, windows [s]."""
        s = self.scales
        return {
            "T_s": s.T,
            "L_over_U_s": s.length_time,
            "horizon": self.horizon,
            "control_horizon": self.control_horizon,
            "interval_periods": self.interval,
            "horizon_s": self.horizon_time,
            "substeps": self.substeps,
            "window_samples": self.window,
            "window_s": self.window * s.h,
            "update_every_samples": self.update_every,
            "lambda_c": list(self.lambda_c),
            "svf_bandwidth": self.svf_bandwidth,
            "excitation_hold": self.excitation_hold,
        }


def ship_plan(context: ControllerContext, horizon_scale: float = 1.0) -> ShipNMPCPlan:
    """The family's numbers for the context's ship (module doc, rule by rule);
    ``horizon_scale``: a factor on the horizon time t_H (1: the rule; a tuned setting)."""
    if not (math.isfinite(horizon_scale) and horizon_scale > 0):
        raise ValueError(f"horizon_scale must be finite and > 0, got {horizon_scale!r}")
    nominal = nominal_prediction_params(context)
    closed_form = isinstance(context.nominal_params, Nomoto2Params)
    p = paper_ship()
    # nomoto2: the paper's numbers for every parameter set (Liu et al. keep them in all cases)
    s = (
        p
        if closed_form
        else time_scales(
            nominal, context.control_period, context.fine_step, context.guidance.los_radius_L
        )
    )
    horizon_time = horizon_scale * max(
        (s.los_radius_L + 1.0) * s.length_time, SETTLING_TIME_CONSTANTS * s.T
    )
    interval = max(1, _ceil(horizon_time / (PAPER_HORIZON * s.Ts)))
    horizon = _ceil(horizon_time / (interval * s.Ts))
    substeps = _ceil(interval * s.Ts / (STEP_PER_FAST_TIME_CONSTANT * s.fast))
    length_ratio = p.L / s.L
    time_ratio = s.length_time / p.length_time
    q = PAPER_Q
    weights = (
        q[0] * length_ratio**2,
        q[1],
        q[2] * time_ratio**2,
        q[3] * time_ratio**4,
        q[4],
    )
    t_ratio = s.T / p.T
    window = round(PAPER_WINDOW * p.h * t_ratio / s.h)
    periods = max(1, round(window * s.h / PAPER_WINDOW_TO_UPDATE / s.Ts))
    update_every = periods * round(s.Ts / s.h)
    jerk_ratio = (s.h**3 * s.K / s.T**2) / (p.h**3 * p.K / p.T**2)
    lambda_c = (PAPER_LAMBDA_C[0] * jerk_ratio, PAPER_LAMBDA_C[1] * (s.h / p.h))
    hold = max(1, round((p.Ts / p.T) * s.T / s.Ts))
    return ShipNMPCPlan(
        nominal=nominal,
        reduce=not closed_form,
        scales=s,
        horizon=horizon,
        control_horizon=min(PAPER_CONTROL_HORIZON, horizon),
        interval=interval,
        substeps=substeps,
        Q=weights,
        window=window,
        update_every=update_every,
        lambda_c=lambda_c,
        svf_bandwidth=SVF_BANDWIDTH / t_ratio,
        excitation_hold=hold,
    )
