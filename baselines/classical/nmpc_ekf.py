"""``nmpc_ekf``: the oracle's NMPC on the ship's own model, fed by an extended Kalman filter.

The certainty-equivalent adaptive design of the marine-control literature (Fossen 2021,
*Handbook of Marine Craft Hydrodynamics and Motion Control*, §13.3: a model-based
controller on the estimates of an augmented-state observer) on the true model structure:

* **Controller.** The oracle's NMPC (:class:`~shipgym_baselines.classical.oracle.PlantNMPC`:
  its cost, horizon, grid, tail and solver) on the ship's own equations, one solver
  iteration a control step (a real-time iteration:
  :data:`~shipgym_baselines.classical.oracle.REAL_TIME_SETTINGS`).  Where the oracle
  reads the true plant now, this one predicts with the filter's estimate: its state, its
  parameters and its current and yaw bias (no wave load: the filter does not resolve it).
* **Estimator.** :class:`shipgym.identification.ekf.ShipEKF` on the same model: it starts
  from the ship's *nominal* parameters (the controller context's) and estimates, from the
  measured position, heading, yaw rate and rudder angle of ``info`` and the command the env
  applied, the unmeasured states, the quantities the change families move
  (:mod:`shipgym.identification.adaptation`: servo time constant and rate limit, rudder
  effectiveness, draught; nomoto2's K and T1) and the current and yaw bias.

It reads no truth: ``reset(context, seed)`` and ``act(obs, info)`` are all it gets, as every
competitor.  The filter's noise settings (:class:`~shipgym.identification.ekf.FilterSettings`)
are its tuned parameters (``configs/tuning/nmpc_ekf.yaml``, the validation split).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, ClassVar

import numpy as np

from shipgym.envs.context import ControllerContext
from shipgym.envs.truth import PlantTruth
from shipgym.identification.adaptation import Adaptation
from shipgym.identification.ekf import FilterSettings, ShipEKF
from shipgym.identification.nominal import first_order_nomoto
from shipgym.identification.servo import ServoFit, servo_constants
from shipgym_baselines.classical.oracle import REAL_TIME_SETTINGS, OracleSettings, PlantNMPC
from shipgym_baselines.records.chosen import tuned_settings

#: the filter settings a study may tune (keywords of the factory)
FILTER_KEYS = tuple(f.name for f in dataclasses.fields(FilterSettings))
#: where the servo's time constant and rate limit come from: the windowed fit of the
#: measured rudder (:mod:`shipgym.identification.servo`, the default) or the EKF's own
#: augmented state ("filter": a slowed servo's prediction is rate-limited, so the filter
#: explains it by the rate limit alone and never sees the time constant)
SERVO_ESTIMATES = ("fit", "filter")
#: the adapted quantities the servo fit gives
SERVO_QUANTITIES = ("servo", "rate")


def measurement(info: dict[str, Any]) -> np.ndarray:
    """y = (x, y, ψ, r, δ) [m, m, rad, rad/s, rad] of one step's ``info``."""
    px, py = info["position"]
    return np.array([px, py, info["heading"], info["yaw_rate"], info["rudder_angle"]], dtype=float)


def servo_fit(context: ControllerContext) -> ServoFit:
    """The windowed servo fit of ``context``'s ship: from the nominal servo, over the last
    yaw time constant T of fine samples (at least one period), bounded as the adapted
    quantities ``servo`` and ``rate`` are."""
    model = context.nominal_model
    _, time_constant = first_order_nomoto(model, context.nominal_params)
    nominal_t, nominal_rate = servo_constants(
        model, context.nominal_params.to_vector(), context.rudder_limit
    )
    bounds = {
        q.name: (q.low, q.high) for q in Adaptation(context.ship, context.nominal_params).quantities
    }
    window = round(time_constant / context.fine_step)
    return ServoFit(
        nominal_t,
        nominal_rate,
        context.fine_step,
        max(window, round(context.control_period / context.fine_step)),
        context.rudder_limit,
        (bounds["servo"], bounds.get("rate", (1.0, 1.0))),
    )


def servo_factors(fit: ServoFit) -> dict[str, float]:
    """The fit's estimate as ln factors on the nominal servo: ``servo`` and, where the
    servo has a rate limit, ``rate``."""
    t, rate = fit.fit()
    nominal_t, nominal_rate = fit.nominal
    factors = {"servo": math.log(t / nominal_t)}
    if math.isfinite(nominal_rate):
        factors["rate"] = math.log(rate / nominal_rate)
    return factors


class NmpcEkf(PlantNMPC):
    """``nmpc_ekf`` (module doc).  ``preset``: "tuned" (default) reads the ship's chosen
    filter settings (``configs/tuning/chosen/nmpc_ekf.yaml``) under the ones given here;
    "default" reads none.  Keywords: the fields of :class:`FilterSettings`."""

    name: ClassVar[str] = "nmpc_ekf"
    kind: ClassVar[str] = "classical"
    default_settings: ClassVar[OracleSettings] = REAL_TIME_SETTINGS

    def __init__(
        self,
        settings: OracleSettings | None = None,
        preset: str = "tuned",
        servo: str = "fit",
        **filter_settings: float,
    ) -> None:
        super().__init__(settings)
        if preset not in ("tuned", "default"):
            raise ValueError(f"preset must be 'tuned' or 'default', got {preset!r}")
        if servo not in SERVO_ESTIMATES:
            raise ValueError(f"servo must be one of {SERVO_ESTIMATES}, got {servo!r}")
        self.servo = servo
        unknown = sorted(set(filter_settings) - set(FILTER_KEYS))
        if unknown:
            raise ValueError(f"nmpc_ekf has no setting(s) {unknown}; valid: {list(FILTER_KEYS)}")
        FilterSettings(**filter_settings)  # an invalid value is an error here, not at reset
        self.preset = preset
        self.explicit = {k: float(v) for k, v in filter_settings.items()}
        #: per step (t [s], state, parameter vector, disturbances): the plant it predicts
        #: with (:mod:`shipgym_baselines.studies.estimation` scores it against the truth)
        self.estimate_log: list[tuple[float, np.ndarray, np.ndarray, np.ndarray]] = []

    def filter_settings(self, ship: str) -> FilterSettings:
        """The filter's settings on ``ship``: the chosen ones (``preset="tuned"``) under the
        ones given to the constructor."""
        chosen = tuned_settings(self.name, ship) if self.preset == "tuned" else {}
        given = {k: v for k, v in chosen.items() if k in FILTER_KEYS}
        return FilterSettings(**{**given, **self.explicit})

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        self.start(context)
        model = context.nominal_model
        _, time_constant = first_order_nomoto(model, context.nominal_params)
        adaptation = Adaptation(context.ship, context.nominal_params)
        fitted = self.servo == "fit"
        self.ekf = ShipEKF(
            model,
            adaptation,
            context.control_period,
            self.solver.grid.substeps,
            time_constant,
            context.ship_length,
            context.nominal_speed,
            context.rudder_limit,
            self.filter_settings(context.ship),
            given=tuple(q for q in SERVO_QUANTITIES if fitted and q in adaptation.names),
        )
        self.servo_fit = servo_fit(context) if fitted else None
        self._filtering = False
        self.estimates: list[np.ndarray] = []  # η per step (ln factors)
        self.estimate_log = []

    def _fit_servo(self, info: dict[str, Any]) -> None:
        """The servo fit over the period just ended, handed to the filter (ln factors)."""
        fit = self.servo_fit
        samples = info.get("samples")
        if fit is None or samples is None:
            return
        fit.add(samples["delta"], samples["delta_c"], float(info["rudder_angle"]))
        self.ekf.set_given(servo_factors(fit))

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        self.mark()
        y = measurement(info)
        if not self._filtering:
            self.ekf.start(y, self.ctx.nominal_speed)
            self._filtering = True
        else:
            self._fit_servo(info)
            self.ekf.step(float(info["rudder_command"]), y)
        theta = self.ekf.params()
        plant = PlantTruth(
            t=float(info["t"]),
            state=self.ekf.state.copy(),
            params=type(self.ctx.nominal_params).from_vector(theta),
            disturbance_now=self.ekf.disturbances.copy(),
        )
        self.estimates.append(self.ekf.eta.copy())
        self.estimate_log.append((plant.t, plant.state, theta, plant.disturbance_now))
        return self.steer(plant)

    def episode_stats(self) -> dict[str, float]:
        stats = super().episode_stats()
        ekf = getattr(self, "ekf", None)
        stats["filter_resets"] = float(ekf.resets) if ekf is not None else math.nan
        stats["filter_divergences"] = float(ekf.divergences) if ekf is not None else math.nan
        return stats
