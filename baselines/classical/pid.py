"""PID heading autopilots on LOS, look-ahead LOS, VF and TVVF guidance (``pid_*``).

Each controller computes its heading reference from the measured position with the same
path tracker the env uses, with the guidance law's parameters from the scenario's
:class:`~shipgym.scenarios.schema.GuidanceConfig` (``context.guidance``), whatever law the
scenario itself names:

* ``pid_los`` — Liu et al. (2019) LOS (eqs. (9), (12)), R_LOS = ``los_radius_L``·L;
* ``pid_lookahead_los`` — Xu & Guedes Soares (2020) eq. (6), Δ = ``lookahead_L``·L;
* ``pid_vf`` — Xu & Guedes Soares (2020) Algorithm 1 (τ, χe, k from the config);
* ``pid_tvvf`` — Xu, Oliveira & Guedes Soares (2021) eqs. (9), (48) (Δ, θ, error unit).

The headings come from :func:`shipgym.guidance.desired_heading` (the law table the env's
guidance mode uses), so a controller and the env agree bit for bit.

The autopilot is the shared :class:`shipgym.autopilot.HeadingPID` with one of two tunings
(``tuning=``), both computed from the nominal model in the controller context, never typed:

* ``"pole_placement"`` — Xu, Oliveira & Guedes Soares (2021) §5.2 on the first-order
  Nomoto model ``shipgym.identification.first_order_nomoto(context.nominal_model)``:
  ωn = 1 rad/s, ζ = 1;
* ``"vyshnegradsky"`` — Xu & Guedes Soares (2020) §5.1–5.2 on the 2nd-order Nomoto model
  (A = B = 4, Ki = Kp/100; :func:`shipgym.autopilot.vyshnegradsky_gains`, whose docstring
  says why (3, 3) reproduces the paper's printed gains).  The 2nd-order model is the ship's
  own parameters on nomoto2 (which *is* that model, as ``first_order_nomoto`` also uses)
  and the fit to the ship's 20/20 zig-zag (:func:`shipgym.identification.zigzag.ship_nomoto`)
  on every other ship — the pipeline of Xu & Guedes Soares (2020).

Default tuning per controller (Xu & Guedes Soares (2020) tune the PID by the Vyshnegradsky
diagram on both LOS and VF guidance):

* ``pid_los``: pole placement — the leaderboard's existing numbers, kept unchanged;
  ``PIDLOS(tuning="vyshnegradsky")`` is the Vyshnegradsky variant.
* ``pid_lookahead_los``, ``pid_vf``: Vyshnegradsky, as Xu & Guedes Soares (2020) pair them.
* ``pid_tvvf``: pole placement, as Xu, Oliveira & Guedes Soares (2021) pair their PID
  baseline with the TVVF law.

Settings presets.  ``preset="paper"`` is the paper-literal design above (what
``shipgym reproduce`` uses); ``preset="tuned"``, the registry's default construction, adds
the ship's section of ``configs/tuning/chosen/<name>.yaml`` (written by ``shipgym tune``,
docs/tuning.md) under any explicit settings, and is the paper's design on a ship without a
section.  Besides the design's own (``tuning``, ``natural_frequency``, ``damping``,
``vyshnegradsky_ab``, ``ki_ratio``) the settings are ``natural_frequency_T`` = ωn·T (the
bandwidth in the ship's own time scale, T the nominal first-order Nomoto time constant),
``drift_compensation`` (ψd = χd − β with the measured drift angle β,
:mod:`shipgym_baselines.classical.drift`, the estimator ``l1_backstepping`` uses; off in
the papers' PID designs) and any guidance parameter of the scenario's ``guidance:`` block
(``los_radius_L``, ``lookahead_L``, ``vf_tau_L``, …), which then replaces the scenario's
for this controller's own heading reference.

Caveat on the Vyshnegradsky tuning for full-scale ships: the design places the closed-loop
frequency ω0 = (K·Kp/(T1T2))^(1/3) from the fast time constant T2, and ignores the rudder
servo and saturation, so on the zig-zag fits of mariner and blanke it asks for Kp ~
10⁴–10⁵ (on the paper's own identified Esso Osaka model the stated A = B = 4 gives Kp =
2167.5; the paper prints its A = B = 3 design, 547.8): the rudder then works bang-bang on
the switching line Kp·ψ̃ = Kd·r. That is what the method gives; no extra scaling is
applied.
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from shipgym.angles import wrap_angle
from shipgym.autopilot import (
    VYSHNEGRADSKY_AB_STATED,
    HeadingPID,
    PIDGains,
    vyshnegradsky_gains,
)
from shipgym.envs.context import ControllerContext
from shipgym.guidance import desired_heading
from shipgym.identification.nominal import first_order_nomoto, second_order_nomoto
from shipgym.models.base import ShipModel
from shipgym.scenarios.schema import GuidanceConfig
from shipgym_baselines.classical.drift import course_and_drift
from shipgym_baselines.policy import check_action_mode
from shipgym_baselines.records.chosen import tuned_settings

TUNINGS = ("pole_placement", "vyshnegradsky")
#: "tuned": the chosen settings of ``shipgym tune`` (docs/tuning.md) for the ship, where
#: there are any; "paper": the paper-literal design (``reproduce`` uses it)
PRESETS = ("tuned", "paper")
#: the design settings and their paper-literal values (module doc)
SETTINGS: dict[str, Any] = {
    "tuning": None,
    "natural_frequency": 1.0,
    "natural_frequency_T": None,
    "damping": 1.0,
    "vyshnegradsky_ab": VYSHNEGRADSKY_AB_STATED,
    "ki_ratio": 0.01,
    "drift_compensation": False,
}
#: the guidance parameters a controller may set for its own heading reference
GUIDANCE_SETTINGS = tuple(k for k in GuidanceConfig.model_fields if k != "law")


def design_gains(
    model: ShipModel,
    tuning: str,
    natural_frequency: float = 1.0,
    damping: float = 1.0,
    vyshnegradsky_ab: tuple[float, float] = VYSHNEGRADSKY_AB_STATED,
    ki_ratio: float = 0.01,
) -> PIDGains:
    """PID gains for ``model`` by ``tuning`` (module doc): pole placement on the first-order
    Nomoto model (ωn [rad/s], ζ) or the Vyshnegradsky diagram on the 2nd-order one ((A, B),
    Ki = ki_ratio·Kp with ki_ratio [1/s])."""
    if tuning == "pole_placement":
        K, T = first_order_nomoto(model)
        return PIDGains.from_nomoto(K, T, natural_frequency, damping)
    if tuning == "vyshnegradsky":
        A, B = vyshnegradsky_ab
        return vyshnegradsky_gains(*second_order_nomoto(model), A=A, B=B, ki_ratio=ki_ratio)
    raise ValueError(f"tuning must be one of {TUNINGS}, got {tuning!r}")


class _GuidedPID:
    """PID heading autopilot on one guidance law (subclasses fix the law and the name)."""

    name: ClassVar[str]
    kind = "classical"
    law: ClassVar[str]  # "los" | "lookahead_los" | "vf" | "tvvf"
    default_tuning: ClassVar[str]
    default_preset: ClassVar[str] = "tuned"

    def __init_subclass__(
        cls, law: str | None = None, default_tuning: str | None = None, **kwargs: Any
    ) -> None:
        """A law's PID: ``law`` (a shipgym.guidance law) and its ``default_tuning``, given
        as class keywords (a subclass of a law's PID keeps them)."""
        super().__init_subclass__(**kwargs)
        if law is not None:
            cls.law = law
        if default_tuning is not None:
            cls.default_tuning = default_tuning

    def __init__(
        self,
        preset: str | None = None,
        *,
        tuning: str | None = None,
        natural_frequency: float | None = None,
        natural_frequency_T: float | None = None,
        damping: float | None = None,
        vyshnegradsky_ab: tuple[float, float] | None = None,
        ki_ratio: float | None = None,
        drift_compensation: bool | None = None,
        los_radius_L: float | None = None,
        lookahead_L: float | None = None,
        vf_tau_L: float | None = None,
        vf_chi_e_deg: float | None = None,
        vf_k: float | None = None,
        tvvf_delta_L: float | None = None,
        tvvf_theta_slope: float | None = None,
        tvvf_theta_offset: float | None = None,
        tvvf_error_unit: str | None = None,
    ) -> None:
        """``preset``: "tuned" (the registry's default: the ship's section of
        ``configs/tuning/chosen/<name>.yaml`` under the explicit ``settings``, the paper's
        where the file has none) or "paper" (the paper-literal design only); None: the
        class's ``default_preset``.  ``settings`` (module doc, :data:`SETTINGS`): tuning
        "pole_placement" | "vyshnegradsky" (None: the controller's default);
        natural_frequency ωn [rad/s] and damping ζ for pole placement, or
        natural_frequency_T = ωn·T [–] (T: the nominal first-order Nomoto time constant, a
        per-ship bandwidth); vyshnegradsky_ab (A, B) and ki_ratio (Ki/Kp [1/s]) for the
        Vyshnegradsky design; any guidance parameter of
        :class:`~shipgym.scenarios.schema.GuidanceConfig` (e.g. ``los_radius_L``) replaces
        the scenario's for this controller's own heading reference (None: not given)."""
        preset = self.default_preset if preset is None else preset
        if preset not in PRESETS:
            raise ValueError(f"{self.name}: preset must be one of {PRESETS}, got {preset!r}")
        given = dict(locals())
        self.preset = preset
        #: the settings given here (None: not given), over the chosen ones at reset
        self.explicit = {
            k: given[k] for k in (*SETTINGS, *GUIDANCE_SETTINGS) if given[k] is not None
        }
        self._configure(self.explicit)

    def _configure(self, settings: dict[str, Any]) -> None:
        """Set the design from ``settings`` (:data:`SETTINGS` defaults under them)."""
        s = {**SETTINGS, **{k: v for k, v in settings.items() if k in SETTINGS}}
        tuning = self.default_tuning if s["tuning"] is None else s["tuning"]
        if tuning not in TUNINGS:
            raise ValueError(f"{self.name}: tuning must be one of {TUNINGS}, got {tuning!r}")
        self.tuning = tuning
        self.natural_frequency = float(s["natural_frequency"])
        self.natural_frequency_T = (
            None if s["natural_frequency_T"] is None else float(s["natural_frequency_T"])
        )
        self.damping = float(s["damping"])
        ab = s["vyshnegradsky_ab"]
        self.vyshnegradsky_ab = (float(ab[0]), float(ab[1]))
        self.ki_ratio = float(s["ki_ratio"])
        self.drift_compensation = bool(s["drift_compensation"])
        self.guidance_settings = {k: v for k, v in settings.items() if k in GUIDANCE_SETTINGS}

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        check_action_mode(self, context)
        if self.preset == "tuned":  # the ship's chosen settings under the explicit ones
            chosen = tuned_settings(type(self).name, context.ship)  # the registered name
            if "natural_frequency" in self.explicit:  # an explicit ωn wins over a chosen ωn·T
                chosen.pop("natural_frequency_T", None)
            self._configure({**chosen, **self.explicit})
        self.ctx = context
        natural_frequency = self.natural_frequency
        if self.natural_frequency_T is not None:
            _, T = first_order_nomoto(context.nominal_model)
            natural_frequency = self.natural_frequency_T / T
        self.gains = design_gains(
            context.nominal_model,
            self.tuning,
            natural_frequency,
            self.damping,
            self.vyshnegradsky_ab,
            self.ki_ratio,
        )
        self.pid = HeadingPID(self.gains, context.rudder_limit)
        self.tracker = context.new_tracker()
        self._guidance = context.guidance.model_copy(
            update={**self.guidance_settings, "law": self.law}
        )
        self._started = False
        self._last: dict[str, Any] | None = None

    def desired_heading(self, cross_track: float, path_angle: float) -> float:
        """ψd [rad] of the controller's law for the current frame (shipgym.guidance table)."""
        return float(desired_heading(self._guidance, cross_track, path_angle, self.ctx.ship_length))

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        x, y = info["position"]
        frame = self.tracker.update(x, y) if self._started else self.tracker.reset(x, y)
        self._started = True
        desired = self.desired_heading(frame.cross_track, frame.path_angle)
        if self.drift_compensation:  # ψd = χd − β, β measured (classical.drift)
            _, drift = course_and_drift(
                info, self._last, self.ctx.control_period, self.ctx.nominal_speed
            )
            desired = float(wrap_angle(desired - drift))
            self._last = {"position": (float(x), float(y)), "psi": float(info["heading"])}
        delta_c = self.pid.command(
            desired, info["heading"], info["yaw_rate"], self.ctx.control_period
        )
        return np.array([delta_c / self.ctx.rudder_limit], dtype=np.float32)

    def episode_stats(self) -> dict[str, Any]:
        """The gains used in the episode (metrics columns)."""
        return {"pid_kp": self.gains.kp, "pid_ki": self.gains.ki, "pid_kd": self.gains.kd}


class PIDLOS(_GuidedPID, law="los", default_tuning="pole_placement"):
    """PID on LOS guidance; pole placement by default (the leaderboard's numbers)."""

    name: ClassVar[str] = "pid_los"


class PIDLookaheadLOS(_GuidedPID, law="lookahead_los", default_tuning="vyshnegradsky"):
    """PID on look-ahead LOS guidance; Vyshnegradsky by default (Xu & Guedes Soares 2020)."""

    name: ClassVar[str] = "pid_lookahead_los"


class PIDVF(_GuidedPID, law="vf", default_tuning="vyshnegradsky"):
    """PID on vector-field guidance; Vyshnegradsky by default (Xu & Guedes Soares 2020)."""

    name: ClassVar[str] = "pid_vf"


class PIDTVVF(_GuidedPID, law="tvvf", default_tuning="pole_placement"):
    """PID on time-varying vector-field guidance; pole placement by default (Xu et al. 2021)."""

    name: ClassVar[str] = "pid_tvvf"
