"""L1 adaptive backstepping heading control on time-varying vector-field guidance.

Xu, Oliveira & Guedes Soares (2021), §2–3 and §5.2, as two controllers:
``l1_backstepping`` (low-pass filter C(s) on, the paper's L1 controller) and
``adaptive_backstepping`` (filter off: "a typical adaptive backstepping controller", §5.2).
The pieces live in :mod:`shipgym_baselines.classical.adaptive`, one module per idea:

* design model, eqs. (15)–(17): T·ṙ + σ·H(r)·r = ρ·K·δ + b, H(r) = 1 + a2·r², K, T, a2 of
  the ship from the identification pipeline
  (:mod:`~shipgym_baselines.classical.adaptive.design_model`);
* state predictor, eq. (20), with the adaptation laws (24)–(25) and their projection
  operator (:mod:`~shipgym_baselines.classical.adaptive.predictor`,
  :mod:`~shipgym_baselines.classical.adaptive.projection`);
* backstepping law, eqs. (27)–(35) (:mod:`~shipgym_baselines.classical.adaptive.backstepping`);
* low-pass filter, eq. (39): δ_ctrl = C(s)δ, C(s) = ω²/(s² + 2ζωs + ω²)
  (:mod:`~shipgym_baselines.classical.adaptive.lowpass`);
* guidance, eq. (48): ψd = γp − sgn(ye)·atan(|ye|^θ/Δ) − β, θ = 0.05|ye| + 1, Δ = 2L, and
  its derivatives in ye (:func:`shipgym.guidance.tvvf_heading`,
  :func:`shipgym.guidance.tvvf_heading_derivatives`; Δ, θ and the error unit from the
  scenario's guidance settings, ``context.guidance.tvvf_*``, whose defaults are the paper's);
* the §5.2 gains and their transfer to another ship
  (:mod:`~shipgym_baselines.classical.adaptive.settings`); the linearised loop
  (:mod:`~shipgym_baselines.classical.adaptive.loop_analysis`); the rudder's high-frequency content
  (:func:`shipgym.metrics.high_frequency_power`).

Choices of this module, where the paper is silent or ambiguous (options of
:class:`L1BacksteppingSettings`; the others are in the modules above):

* **Samples.**  Predictor and adaptation run at the env's fine step h on
  ``info["samples"]`` (measured ψ, r and rudder angle δ at t0, t0 + h, …, plus the
  measurement at t0 + Ts).  Without samples (a missing or diverged step) the period's two
  end measurements are interpolated instead.
* **Control law and filter at Ts.**  The law (35) is evaluated once per control period
  (the command is held over Ts anyway) and saturated at ±δmax; with the filter on, C(s) is
  driven by that zero-order-held law output and the command over [t_k, t_k + Ts) is the
  period average of C(s)'s exact continuous output (:class:`SecondOrderLowPass`).
* **Filter placement** (``filter_placement``).  Eq. (39) writes δ_ctrl = C(s)δ with δ the
  whole law (35), and §3.2 motivates it by the adaptation: "the adaption of uncertainties of
  parameters may contain high-frequency signals"; Fig. 4 shows "control law with low-pass
  filter".  Default ``"command"``: C(s) on the whole (saturated) law, as eq. (39) is
  printed.  ``"adaptive"``: C(s) only on the estimates' share of the law,
  δ = δ_nom + C(s)(δ − δ_nom) with δ_nom the law (35) at the initial estimates ρ̂ = σ̂ = 1,
  b̂ = 0 (unsaturated, the sum saturated) — the standard L1 structure u = u_m + C(s)u_ad of
  Hovakimyan & Cao (2010), the paper's ref. [21].  With exact nominal estimates the filtered
  share is zero, so the linearised loop is that of ``adaptive_backstepping`` (stable); on
  ``osaka_stochastic_current`` the estimates stay within 0.5 % of nominal and this variant
  is indistinguishable from ``adaptive_backstepping`` (``shipgym reproduce xu2021``).
* **Reference derivatives.**  ψ̇d and ψ̈d from the guidance law's analytic derivatives in
  ye along the kinematics ẏe = U·sin(χ − γp) (eq. (8)), ÿe = U·cos(χ − γp)·r (constant
  U, χ̇ ≈ r, β̇ ≈ 0); the leg switches' steps in γp, and the tangent rate on a PCHIP path,
  are not differentiated.
* **Drift angle β** (eq. (48); the paper assumes it measured): course over ground from the
  last period's position change minus the period's mean measured heading
  (``drift_compensation``); β = 0 on the first step.  U is the speed over ground of the
  same period (nominal speed on the first step).

Behaviour (seed 0, tests/baselines/classical/test_l1_backstepping.py).  Linearised on its
design model, the printed design is stable without C(s) and *unstable* with C(s) on the
whole command on every ship, the paper's own included (Esso Osaka: K2 = 15 makes the
yaw-rate loop cross over near 0.45 rad/s, above ω, with a phase margin of −26°; pole at
+0.070 1/s,
:func:`~shipgym_baselines.classical.adaptive.loop_analysis.linearised_closed_loop_poles`).
``l1_backstepping`` therefore settles
into an oscillation bounded by the rudder limit (Esso Osaka, calm water: rudder ±30°,
heading ±15°, period ≈ 33 s) instead of the smooth rudder the paper describes;
``adaptive_backstepping`` is stable, its saturated high-gain law switching at the control
rate.  Both reach the goal on nomoto2 ``nominal``, ``blanke_current_shift`` and
``osaka_stochastic_current``; on ``mariner_track`` (steering gear rate-limited to
3.8°/s) the adaptive controller converges on each leg and the L1 one oscillates with
hundreds of metres of cross-track error.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from shipgym.angles import wrap_angle
from shipgym.envs.context import ControllerContext
from shipgym.guidance import tvvf_heading, tvvf_heading_derivatives
from shipgym.metrics import high_frequency_power
from shipgym_baselines.classical.adaptive.backstepping import backstepping_rudder
from shipgym_baselines.classical.adaptive.design_model import nominal_design_model
from shipgym_baselines.classical.adaptive.lowpass import SecondOrderLowPass
from shipgym_baselines.classical.adaptive.predictor import StatePredictor
from shipgym_baselines.classical.adaptive.settings import Gains, L1BacksteppingSettings
from shipgym_baselines.classical.drift import course_and_drift
from shipgym_baselines.policy import check_action_mode
from shipgym_baselines.records.chosen import tuned_settings

__all__ = [
    "AdaptiveBackstepping",
    "L1Backstepping",
]


class L1Backstepping:
    """L1 adaptive backstepping heading control on TVVF guidance (``l1_backstepping``)."""

    name = "l1_backstepping"
    kind = "classical"
    #: C(s) of eq. (39) on the command (off: plain adaptive backstepping)
    low_pass = True

    def __init__(
        self,
        settings: L1BacksteppingSettings | None = None,
        preset: str = "tuned",
        **overrides: Any,
    ) -> None:
        """``settings`` (default: the paper's) with ``overrides``; ``preset``: "tuned" adds
        the ship's section of ``configs/tuning/chosen/<name>.yaml`` (``shipgym tune``,
        docs/tuning.md) under the overrides at reset, "paper" does not."""
        if preset not in ("tuned", "paper"):
            raise ValueError(f"preset must be 'tuned' or 'paper', got {preset!r}")
        self.preset = preset
        self._base = settings if settings is not None else L1BacksteppingSettings()
        self._overrides = dict(overrides)
        # L1BacksteppingSettings validates itself, also when replaced with overrides
        self.settings = dataclasses.replace(self._base, **overrides) if overrides else self._base

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        check_action_mode(self, context)
        if self.preset == "tuned":  # the ship's chosen settings under the overrides
            chosen = tuned_settings(type(self).name, context.ship)
            if chosen:
                self.settings = dataclasses.replace(self._base, **{**chosen, **self._overrides})
        s = self.settings
        self.ctx = context
        self.model = nominal_design_model(context.nominal_model)
        g = context.guidance
        unit = s.error_unit if s.error_unit is not None else g.tvvf_error_unit
        self.gains = k = Gains.transfer(s, context.ship_length, context.nominal_speed, unit)
        b_max = s.b_bound_rudder * abs(self.model.K) * context.rudder_limit
        self.predictor = StatePredictor(
            self.model,
            k.gamma1,
            k.gamma2,
            k.gamma_rho,
            k.gamma_sigma,
            k.gamma_b,
            {"rho": s.rho_bounds, "sigma": s.sigma_bounds, "b": (-b_max, b_max)},
            s.projection_epsilon,
            (s.rho0, s.sigma0, s.b0),
        )
        self.filter = (
            SecondOrderLowPass(k.filter_frequency, s.filter_damping, context.control_period)
            if self.low_pass
            else None
        )
        self.delta = g.tvvf_delta_L * context.ship_length  # Δ = 2L
        self.tracker = context.new_tracker()
        self._started = False
        self._last: dict[str, Any] = {}
        self.history: dict[str, list[float]] = {
            k: []
            for k in ("t", "psi_err", "r_err", "rho", "sigma", "b", "law", "command", "z1", "z2")
        }

    # -- pieces ---------------------------------------------------------------------------
    def _update_predictor(self, info: dict[str, Any]) -> None:
        psi, r, delta = info["heading"], info["yaw_rate"], info["rudder_angle"]
        samples = info.get("samples")
        if samples is not None and len(samples["psi"]) > 0:
            step = self.ctx.fine_step
            psis = [*samples["psi"].tolist(), psi]
            rs = [*samples["r"].tolist(), r]
            deltas = [*samples["delta"].tolist(), delta]
        else:  # no valid samples: the period's end points (module doc)
            last = self._last
            n = max(1, round(self.ctx.control_period / self.ctx.fine_step))
            step = self.ctx.control_period / n
            psis = np.linspace(last["psi"], last["psi"] + wrap_angle(psi - last["psi"]), n + 1)
            rs = np.linspace(last["r"], r, n + 1)
            deltas = np.linspace(last["delta"], delta, n + 1)
        self.predictor.advance(psis, rs, deltas, step)

    def _course(self, info: dict[str, Any]) -> tuple[float, float]:
        """(speed over ground U [m/s], drift angle β [rad]) over the last period."""
        return course_and_drift(
            info,
            self._last if self._started else None,
            self.ctx.control_period,
            self.ctx.nominal_speed,
            self.settings.drift_compensation,
        )

    def _reference(
        self, ye: float, path_angle: float, psi: float, r: float, speed: float, drift: float
    ) -> tuple[float, float, float]:
        """(ψd [rad], ψ̇d [rad/s], ψ̈d [rad/s²]) at cross-track ye [m], path angle γp [rad]:
        eq. (48) and its derivatives along the kinematics, eq. (8) (module doc, "Reference
        derivatives")."""
        g, unit = self.ctx.guidance, self.gains.error_unit
        psi_d = tvvf_heading(
            ye,
            path_angle,
            self.delta,
            sideslip=drift,
            theta_slope=g.tvvf_theta_slope,
            theta_offset=g.tvvf_theta_offset,
            error_unit=unit,
        )
        d1, d2 = tvvf_heading_derivatives(
            ye, self.delta, g.tvvf_theta_slope, g.tvvf_theta_offset, unit
        )
        rel_course = psi + drift - path_angle
        ye_dot = speed * math.sin(rel_course)
        ye_ddot = speed * math.cos(rel_course) * r
        return psi_d, d1 * ye_dot, d2 * ye_dot * ye_dot + d1 * ye_ddot

    # -- policy API -----------------------------------------------------------------------
    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        k, m, ctx = self.gains, self.model, self.ctx
        psi, r = float(info["heading"]), float(info["yaw_rate"])
        x, y = info["position"]
        if self._started:
            self._update_predictor(info)
            frame = self.tracker.update(x, y)
        else:
            self.predictor.reset(psi, r)
            frame = self.tracker.reset(x, y)
        speed, drift = self._course(info)
        reference = self._reference(frame.cross_track, frame.path_angle, psi, r, speed, drift)
        # backstepping, eqs. (27)–(35)
        rho, sigma, b = self.predictor.estimates
        law, z1, z2 = backstepping_rudder(m, k, psi, r, reference, (rho, sigma, b))
        limit = ctx.rudder_limit
        if self.filter is not None and self.settings.filter_placement == "adaptive":
            # δ = δ_nom + C(s)(δ − δ_nom), δ_nom the law at the initial (nominal) estimates
            s = self.settings
            nominal, _, _ = backstepping_rudder(m, k, psi, r, reference, (s.rho0, s.sigma0, s.b0))
            command = nominal + self.filter.step(law - nominal)
            law = min(limit, max(-limit, law))
        else:
            law = min(limit, max(-limit, law))
            command = self.filter.step(law) if self.filter is not None else law
        command = min(limit, max(-limit, command))
        self._record(
            t=float(info["t"]),
            psi_err=float(wrap_angle(self.predictor.psi_hat - psi)),
            r_err=self.predictor.r_hat - r,
            rho=rho,
            sigma=sigma,
            b=b,
            law=law,
            command=command,
            z1=z1,
            z2=z2,
        )
        self._last = {
            "psi": psi,
            "r": r,
            "delta": float(info["rudder_angle"]),
            "position": (float(x), float(y)),
        }
        self._started = True
        return np.array([command / limit], dtype=np.float32)

    def _record(self, **values: float) -> None:
        for key, value in values.items():
            self.history[key].append(value)

    def episode_stats(self) -> dict[str, float]:
        """Final estimates, mean |r̃| and the command's RMS above the filter frequency."""
        h = self.history
        stats = {
            "rho_hat": h["rho"][-1],
            "sigma_hat": h["sigma"][-1],
            "b_hat": h["b"][-1],
            "mean_abs_r_prediction_error": float(np.mean(np.abs(h["r_err"]))),
        }
        if len(h["command"]) >= 8:
            power = high_frequency_power(
                np.array(h["command"]), self.ctx.control_period, self.gains.filter_frequency
            )
            stats["rudder_command_hf_rms_deg"] = math.degrees(math.sqrt(power))
        return stats


class AdaptiveBackstepping(L1Backstepping):
    """The same controller with C(s) off (``adaptive_backstepping``; Xu et al. 2021 §5.2)."""

    name = "adaptive_backstepping"
    low_pass = False
