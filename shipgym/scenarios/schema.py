"""Scenario schema: ship, initial state, path, disturbances, sensors, events, reward.

Validated once, at the boundary (pydantic, unknown keys rejected), so that a bad file fails
with an error naming the file and the key.  Values are in the units of the config files:
metres, seconds, degrees where a key says ``_deg``; ship parameters in the units of the
model's source paper (for nomoto2: Liu et al. 2019, d0 in °/s), converted to SI by the
model under the scenario's ``unit_reading``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Literal, TypeVar

import yaml
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

#: a validated config model
M = TypeVar("M", bound=BaseModel)


def format_validation_error(err: ValidationError, origin: str) -> str:
    """One line per problem, naming the file (``origin``) and the key."""
    lines = []
    for item in err.errors():
        key = ".".join(str(part) for part in item["loc"]) or "<top level>"
        lines.append(f"{origin}: key '{key}': {item['msg']}")
    return "\n".join(lines)


def load_yaml_model(path: Path, model: type[M], error: type[Exception]) -> M:
    """``model`` validated from the YAML file ``path``; ``error`` names the file and key."""
    try:
        return model.model_validate(yaml.safe_load(path.read_text()))
    except yaml.YAMLError as exc:
        raise error(f"{path}: malformed YAML: {exc}") from None
    except ValidationError as exc:
        raise error(format_validation_error(exc, str(path))) from None


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class ShipConfig(_Strict):
    """Which model, its parameters (paper units) and the unit reading of those numbers."""

    model: str = "nomoto2"
    unit_reading: str | None = Field(
        default=None, description="how the paper's units map to SI (nomoto2: si|degrees|…)"
    )
    params: dict[str, float] = Field(default_factory=dict)
    variant: str | None = Field(
        default=None, description="structural variant of the model's equations (esso_osaka: …)"
    )


class InitialState(_Strict):
    x: float = 0.0  # m
    y: float = 0.0  # m
    heading_deg: float = 0.0  # deg
    states: dict[str, float] = Field(default_factory=dict)  # other states, SI


class PathConfig(_Strict):
    type: Literal["waypoints", "pchip"] = "waypoints"
    waypoints: list[tuple[float, float]]
    switching: Literal["circle", "along_track"] = "circle"
    acceptance_radius_L: float = Field(2.0, gt=0)  # R0 = 2L, Liu et al. (2019) eq. (13)

    @field_validator("waypoints")
    @classmethod
    def _at_least_two(cls, v: list[tuple[float, float]]) -> list[tuple[float, float]]:
        if len(v) < 2:
            raise ValueError("a path needs at least 2 waypoints")
        return v


class GuidanceConfig(_Strict):
    """Guidance law the env uses for its heading reference (observation, guidance mode).

    Laws and their parameters are those of :mod:`shipgym.guidance` (its module doc has the
    choices where the papers are silent).
    """

    law: Literal["los", "lookahead_los", "vf", "tvvf"] = "los"
    los_radius_L: float = Field(3.0, gt=0)  # R_LOS = 3L, Liu et al. (2019) eq. (12)
    lookahead_L: float = Field(2.0, gt=0)  # Δ for look-ahead LOS
    # vector field, Xu & Guedes Soares (2020) Algorithm 1
    vf_tau_L: float = Field(2.0, gt=0)  # transition region τ = 2L
    vf_chi_e_deg: float = Field(90.0, gt=0, le=90)  # entry angle χe ≤ π/2
    vf_k: float = Field(1.0, ge=1)  # exponent k ≥ 1 (no value in the paper: the smallest)
    # time-varying vector field, Xu, Oliveira & Guedes Soares (2021) eqs. (9), (48)
    tvvf_delta_L: float = Field(2.0, gt=0)  # Δ = 2L
    tvvf_theta_slope: float = Field(0.05, ge=0)  # θ = slope·|ye| + offset, per error unit
    tvvf_theta_offset: float = Field(1.0, ge=1)  # θ(0) ≥ 1 (Definition 1)
    #: unit of ye and Δ in |ye|^θ/Δ: "m" as the paper; "L" ship lengths; "similar" the
    #: paper's metre scaled to this ship, L/3.25 m (Xu et al. 2021's 3.25 m Esso Osaka
    #: model), which is how the L1 controller transfers the law to other ships
    tvvf_error_unit: Literal["m", "L", "similar"] = "m"


class _CurrentBase(_Strict):
    speed: float = Field(0.0, ge=0)  # (mean) current speed [m/s]
    direction_deg: float = 0.0  # (mean) direction the current flows TO [deg]
    #: extra yaw bias in the model's ``yaw_disturbance`` unit per m/s of current speed
    #: (nomoto2: rad/s per m/s, added to d0 as Liu et al. (2019) Case 2 does); 0 = off.
    #: Meant for kinematic-current models; 3-DOF models already feel the current through
    #: their relative velocities (shipgym.disturbances module doc).
    yaw_bias_per_speed: float = 0.0


class ConstantCurrent(_CurrentBase):
    """Constant current (the default when ``kind`` is omitted)."""

    kind: Literal["constant"] = "constant"


class _GaussMarkovFields(_CurrentBase):
    """First-order Gauss–Markov speed and direction (data file §4.3; Fossen 2011 §8.3).

    V = V̄ + x with ẋ + μx = σw (w unit white noise), state saturated to [min_speed,
    max_speed]; direction β = β̄ + d with ḋ + μ₂d = σ₂w₂, |d| ≤ direction_max_deviation_deg.
    Stationary std σ/√(2μ), correlation time 1/μ.  μ, σ are not given by the sources: the
    defaults (1/μ = 50 s, std 0.02 m/s, constant direction) are our assumption.
    """

    mu: float = Field(0.02, gt=0)  # μ [1/s]
    sigma: float = Field(0.004, ge=0)  # σ, white-noise intensity √ [m/s/√s]
    min_speed: float = Field(0.0, ge=0)  # [m/s]
    max_speed: float | None = Field(None, gt=0)  # [m/s]; None: no upper bound
    direction_mu: float = Field(0.02, gt=0)  # μ₂ [1/s]
    direction_sigma_deg: float = Field(0.0, ge=0)  # σ₂ [deg/√s]; 0: constant direction
    direction_max_deviation_deg: float | None = Field(None, gt=0, le=180)  # |d| bound [deg]

    def _mean_speeds(self) -> dict[str, float]:
        return {"speed": self.speed}

    @model_validator(mode="after")
    def _bounds_consistent(self) -> _GaussMarkovFields:
        hi = math.inf if self.max_speed is None else self.max_speed
        if self.min_speed > hi:
            raise ValueError(f"min_speed ({self.min_speed}) > max_speed ({self.max_speed})")
        for key, value in self._mean_speeds().items():
            if not self.min_speed <= value <= hi:
                raise ValueError(
                    f"{key} ({value}) must lie within [min_speed, max_speed] = "
                    f"[{self.min_speed}, {self.max_speed}]"
                )
        return self


class GaussMarkovCurrent(_GaussMarkovFields):
    """Gauss–Markov current about the mean ``speed`` / ``direction_deg``."""

    kind: Literal["gauss_markov"]
    speed: float = Field(ge=0)  # mean speed V̄ [m/s] (required)


class TwoPhaseCurrent(_GaussMarkovFields):
    """Two-phase stochastic current, Xu et al. (2021) §5.2: constant direction 180°, a weak
    phase oscillating about 0.1 m/s, then a stronger one of mean 0.2 m/s.  The paper does not
    give the switch time nor the fluctuation: ``switch_time`` (None: half the scenario's
    time limit), ``transition_time`` (linear ramp of the mean, 0: a step) and the
    Gauss–Markov fluctuation shared by both phases are our options.
    """

    kind: Literal["two_phase"]
    speed: float = Field(0.1, ge=0)  # first-phase mean [m/s]
    second_speed: float = Field(0.2, ge=0)  # second-phase mean [m/s]
    direction_deg: float = 180.0  # β_c = 180°
    switch_time: float | None = Field(None, ge=0)  # [s]; None: time_limit / 2
    transition_time: float = Field(0.0, ge=0)  # [s]

    def _mean_speeds(self) -> dict[str, float]:
        return {"speed": self.speed, "second_speed": self.second_speed}


#: ``disturbances.current``: a constant, Gauss–Markov or two-phase current, by ``kind``.
CurrentConfig = Annotated[
    ConstantCurrent | GaussMarkovCurrent | TwoPhaseCurrent, Field(discriminator="kind")
]


class WaveConfig(_Strict):
    """Wave-induced yaw disturbance: Fossen's 2nd-order wave filter (data file §4.3).

    h(s) = K_w s/(s² + 2λω₀s + ω₀²), K_w = 2λω₀σ_w, σ_w² = max S(ω), ω₀ the modal frequency
    of the sea-state spectrum: ``pierson_moskowitz`` (from ``wind_speed``) or ``ittc`` (from
    ``significant_height`` and ``modal_period``).  The filter output y [m] (one-sided PSD
    |h(jω)|², peak S(ω₀)) enters the plant as ``yaw_disturbance = gain·y``: ``gain`` is in
    the model's yaw_disturbance unit per metre: nomoto2 rad/s per m (added to the yaw bias
    d0); mariner, esso_osaka, blanke rad/s² per m (added to ṙ; see each model's module doc).
    No source gives the gain, so it has no default.
    """

    spectrum: Literal["pierson_moskowitz", "ittc"] = "pierson_moskowitz"
    wind_speed: float | None = Field(None, gt=0)  # V₁₉.₅ [m/s] (pierson_moskowitz)
    significant_height: float | None = Field(None, gt=0)  # H_s [m] (ittc)
    modal_period: float | None = Field(None, gt=0)  # T₀ [s] (ittc)
    damping: float = Field(0.1, gt=0, lt=1)  # λ (Fossen: 0.1)
    gain: float  # [yaw_disturbance unit / m]

    @model_validator(mode="after")
    def _spectrum_inputs(self) -> WaveConfig:
        needs = {
            "pierson_moskowitz": ("wind_speed",),
            "ittc": ("significant_height", "modal_period"),
        }
        for spectrum, keys in needs.items():
            for key in keys:
                given = getattr(self, key) is not None
                if spectrum == self.spectrum and not given:
                    raise ValueError(f"spectrum {self.spectrum!r} needs {key}")
                if spectrum != self.spectrum and given:
                    raise ValueError(f"{key} does not apply to spectrum {self.spectrum!r}")
        return self


class DisturbanceConfig(_Strict):
    """Environmental disturbances (shipgym.disturbances): current and waves."""

    current: CurrentConfig = ConstantCurrent()
    waves: WaveConfig | None = None  # None: calm sea

    @field_validator("current", mode="before")
    @classmethod
    def _constant_by_default(cls, v: object) -> object:
        if isinstance(v, dict) and "kind" not in v:
            return {**v, "kind": "constant"}
        return v


class SensorConfig(_Strict):
    heading_noise_deg: float = Field(0.0, ge=0)  # std of Gaussian heading noise
    yaw_rate_noise_deg_s: float = Field(0.0, ge=0)
    outlier_probability: float = Field(0.0, ge=0, le=1)  # per fine sample
    outlier_magnitude_deg: tuple[float, float] = (5.0, 15.0)  # |spike| range on heading
    dropout_probability: float = Field(0.0, ge=0, le=1)  # per fine sample: hold last value


class EventConfig(_Strict):
    """At ``time`` the true plant parameters change (step, or linear ramp over ``duration``)."""

    time: float = Field(ge=0)
    params: dict[str, float]
    kind: Literal["step", "ramp"] = "step"
    duration: float = Field(0.0, ge=0)

    @model_validator(mode="after")
    def _ramp_needs_duration(self) -> EventConfig:
        if self.kind == "ramp" and self.duration <= 0:
            raise ValueError("a ramp event needs duration > 0")
        if not self.params:
            raise ValueError("an event must change at least one parameter")
        return self


class RewardConfig(_Strict):
    """r = −(|e|/L + w_ψ|ψ̃| + w_δ(δc/δmax)² + w_Δ(Δδc/δmax)²), SPEC §5."""

    heading_weight: float = Field(0.1, ge=0)
    rudder_weight: float = Field(0.01, ge=0)
    rudder_rate_weight: float = Field(0.05, ge=0)
    goal_bonus: float = Field(10.0, ge=0)
    max_cross_track_L: float = Field(10.0, gt=0)  # corridor half-width in ship lengths


class ScenarioConfig(_Strict):
    name: str
    description: str = ""
    source: str = ""
    ship: ShipConfig = ShipConfig()
    initial_state: InitialState = InitialState()
    path: PathConfig
    guidance: GuidanceConfig = GuidanceConfig()
    disturbances: DisturbanceConfig = DisturbanceConfig()
    sensors: SensorConfig = SensorConfig()
    events: list[EventConfig] = Field(default_factory=list)
    time_limit: float = Field(gt=0)  # s
    control_period: float | None = Field(None, gt=0)  # s; None: the ship's default
    fine_step: float | None = Field(None, gt=0)  # s; None: the ship's default
    reward: RewardConfig = RewardConfig()
    convergence_threshold: float | None = Field(None, gt=0)  # m; None: 0.05·L/0.95

    @model_validator(mode="after")
    def _events_sorted(self) -> ScenarioConfig:
        times = [e.time for e in self.events]
        if times != sorted(times):
            raise ValueError("events must be listed in time order")
        return self
