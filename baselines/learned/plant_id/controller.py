"""``nmpc_learned_id``: the oracle's NMPC fed by the learned estimator φ.

RMA's architecture (Kumar, Fu, Pathak & Malik 2021, "RMA: Rapid Motor Adaptation for
Legged Robots"): an adaptation module φ reads a window of the recent history and estimates
what the base policy needs of the plant; here the base policy is the oracle's NMPC on the
ship's own model (:class:`~shipgym_baselines.classical.oracle.PlantNMPC`, one solver
iteration a step as ``nmpc_ekf``'s:
:data:`~shipgym_baselines.classical.oracle.REAL_TIME_SETTINGS`), and φ estimates
the adapted quantities, the current and the yaw bias (:mod:`.labels`).  At every step:

1. φ(window) = (μ, σ²) per slot (:mod:`.network`).
2. **Where φ is unsure it falls back** towards the nominal ship, or for the servo towards
   a model-based fit inside the window: each slot is the posterior mean of φ's N(μ, σ²)
   under a prior N(m, s²), (μ/σ² + m/s²)/(1/σ² + 1/s²).  The prior is the nominal ship and
   no disturbance (m = 0, s = ``prior_std``), but for the servo's time constant and rate
   limit the windowed fit of the measured rudder (:class:`shipgym.identification.servo.
   ServoFit`, m its ln factors, s = ``fit_std``) once it has samples.  A confident φ
   (σ ≪ s) is used as it is; an unsure one gives way to the prior.
3. The unmeasured states (surge and sway, a model's internal states) come from a
   one-period prediction of the ship's model with the previous estimate, the measured
   ones (position, heading, yaw rate, rudder angle) from ``info``.

It reads ``info`` and the controller context only: φ learned from the truth at training
time (:mod:`~shipgym_baselines.training.plant_id`), never at evaluation.  The shipped estimators
are the folders
``seeds/seed_<k>`` beside this module (``estimator.pt``, weights only, and ``meta.json``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from shipgym.envs.context import ControllerContext
from shipgym.envs.truth import PlantTruth
from shipgym.identification.adaptation import Adaptation
from shipgym.identification.ekf import MEASURED, full_rudder_bias, measured_start
from shipgym_baselines.classical.nmpc_ekf import measurement, servo_factors, servo_fit
from shipgym_baselines.classical.oracle import REAL_TIME_SETTINGS, OracleSettings, PlantNMPC
from shipgym_baselines.errors import ControllerError
from shipgym_baselines.learned.plant_id.features import Window
from shipgym_baselines.learned.plant_id.labels import SLOTS, UNLEARNED, plant_of, slot_mask
from shipgym_baselines.learned.plant_id.network import Estimator
from shipgym_baselines.learned.plant_id.shipped import SHIPPED, shipped_seeds
from shipgym_baselines.records.chosen import tuned_settings

#: s of the fallback before tuning: to the nominal ship (``prior_std``, ln factors and slot
#: units) and to the servo's windowed fit (``fit_std``)
FALLBACK_DEFAULTS = {"prior_std": 0.5, "fit_std": 0.1}


def _positive(key: str, value: Any) -> float:
    """``value`` as a float > 0, else a ValueError that names ``key``."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{key} must be a number > 0, got {value!r}") from None
    if not number > 0:
        raise ValueError(f"{key} must be > 0, got {value!r}")
    return number


class NmpcLearnedId(PlantNMPC):
    """``nmpc_learned_id`` (module doc).  ``training_seed``: which shipped estimator (None:
    the first); ``folder``: an estimator's folder instead of a shipped one; ``prior_std``
    and ``fit_std``: s of the fallback to the nominal ship and to the servo's fit (ln-factor
    and slot units; None: the ship's chosen value with ``preset="tuned"``, the default, from
    ``configs/tuning/chosen/nmpc_learned_id.yaml``, else :data:`FALLBACK_DEFAULTS`)."""

    name: ClassVar[str] = "nmpc_learned_id"
    kind: ClassVar[str] = "learned"
    default_settings: ClassVar[OracleSettings] = REAL_TIME_SETTINGS

    def __init__(
        self,
        training_seed: int | None = None,
        folder: str | Path | None = None,
        prior_std: float | None = None,
        fit_std: float | None = None,
        settings: OracleSettings | None = None,
        preset: str = "tuned",
    ) -> None:
        super().__init__(settings)
        if preset not in ("tuned", "default"):
            raise ValueError(f"preset must be 'tuned' or 'default', got {preset!r}")
        self.preset = preset
        given = {"prior_std": prior_std, "fit_std": fit_std}
        self.explicit = {k: _positive(k, v) for k, v in given.items() if v is not None}
        if folder is None:
            seeds = shipped_seeds()
            if not seeds:
                raise ControllerError(
                    "nmpc_learned_id: no shipped estimator in "
                    f"{SHIPPED}; train one (python -m shipgym_baselines.training.plant_id)"
                )
            seed = seeds[0] if training_seed is None else training_seed
            if seed not in seeds:
                raise ControllerError(f"nmpc_learned_id: no training seed {seed}; shipped {seeds}")
            folder = SHIPPED / f"seed_{seed}"
            self.training_seed = seed
        else:
            self.training_seed = training_seed
        self.estimator = Estimator.load(Path(folder))
        self.estimate_log: list[tuple[float, np.ndarray, np.ndarray, np.ndarray]] = []

    def fallback_settings(self, ship: str) -> dict[str, float]:
        """``prior_std`` and ``fit_std`` on ``ship``: those given to the constructor over the
        chosen ones (``preset="tuned"``) over :data:`FALLBACK_DEFAULTS`."""
        chosen = tuned_settings(self.name, ship) if self.preset == "tuned" else {}
        unknown = sorted(set(chosen) - set(FALLBACK_DEFAULTS))
        if unknown:
            raise ValueError(
                f"nmpc_learned_id's chosen settings on {ship} name {unknown}; "
                f"valid: {sorted(FALLBACK_DEFAULTS)}"
            )
        values = {**FALLBACK_DEFAULTS, **chosen, **self.explicit}
        return {k: _positive(k, v) for k, v in values.items()}

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        self.start(context)
        fallback = self.fallback_settings(context.ship)
        self.prior_var = fallback["prior_std"] ** 2
        self.fit_var = fallback["fit_std"] ** 2
        model = context.nominal_model
        self.window = Window(context)
        self.mask = slot_mask(context.ship)
        self.adaptation = Adaptation(context.ship, context.nominal_params)
        self.unlearned = np.array([s in UNLEARNED for s in SLOTS])
        self.bias_scale = full_rudder_bias(model, context.rudder_limit)
        self.substep = context.control_period / self.solver.grid.substeps
        self.state: np.ndarray | None = None
        self.theta = context.nominal_params.to_vector()
        self.w = np.zeros(model.n_disturbances)
        self.measured = np.array([model.state_index(n) for n in MEASURED])
        self.estimate_log = []
        self.slot_log: list[tuple[np.ndarray, np.ndarray]] = []  # (μ, σ²) per step
        self.servo_fit = servo_fit(context)
        self.prior_mean = np.zeros(len(SLOTS))
        self.prior_vars = np.full(len(SLOTS), self.prior_var)

    def _state(self, info: dict[str, Any]) -> np.ndarray:
        """The state now: the model's one-period prediction from the previous estimate with
        the applied command, the measured entries from ``info``."""
        model = self.ctx.nominal_model
        y = measurement(info)
        if self.state is None:
            return measured_start(model, y, self.ctx.nominal_speed)
        x = self.state
        command = [float(info["rudder_command"])]
        for _ in range(self.solver.grid.substeps):
            x = model.step_numpy(x, command, self.w, self.theta, self.substep)
        if not np.isfinite(x).all():
            return measured_start(model, y, self.ctx.nominal_speed)
        x = np.array(x, dtype=float)
        x[self.measured] = y
        return x

    def _prior(self, info: dict[str, Any]) -> None:
        """The servo's slots' prior from the windowed fit of the period just ended."""
        samples = info.get("samples")
        if samples is None:
            return
        self.servo_fit.add(samples["delta"], samples["delta_c"], float(info["rudder_angle"]))
        for name, value in servo_factors(self.servo_fit).items():
            self.prior_mean[SLOTS.index(name)] = value
            self.prior_vars[SLOTS.index(name)] = self.fit_var

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        self.mark()
        self.state = self._state(info)
        self.window.add(info)
        self._prior(info)
        mean, var = self.estimator.predict(self.window.input())
        var[self.unlearned] = np.inf  # the prior alone: φ does not estimate them
        precision = 1.0 / var + 1.0 / self.prior_vars
        slots = (mean / var + self.prior_mean / self.prior_vars) / precision * self.mask
        self.theta, self.w = plant_of(self.ctx, self.adaptation, slots, self.bias_scale)
        self.slot_log.append((mean, var))
        t = float(info["t"])
        self.estimate_log.append((t, self.state.copy(), self.theta.copy(), self.w.copy()))
        plant = PlantTruth(
            t=t,
            state=self.state.copy(),
            params=type(self.ctx.nominal_params).from_vector(self.theta),
            disturbance_now=self.w,
        )
        return self.steer(plant)


__all__ = ["NmpcLearnedId"]
