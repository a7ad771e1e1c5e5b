"""Scenario schema: ship, initial state, path, disturbances, sensors, events, reward.

Validated once, at the boundary (pydantic, unknown keys rejected), so that a bad file fails
with an error naming the file and the key.  Values are in the units of the config files:
metres, seconds, degrees where a key says ``_deg``; ship parameters in the units of the
model's source paper (for nomoto2: Liu et al. 2019, d0 in °/s), converted to SI by the
model under the scenario's ``unit_reading``.  The ``disturbances`` and ``sensors`` sections
are the models of :mod:`shipgym.disturbance_config`.  Every number is
finite (``.inf`` / ``.nan`` are rejected, :class:`shipgym.config.StrictModel`), and the checks
that relate two keys (an event after the time limit) name the key at fault.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import AfterValidator, Field, field_validator, model_validator
from pydantic_core import InitErrorDetails, PydanticCustomError, ValidationError

from shipgym.config import Name, StrictModel
from shipgym.disturbance_config import DisturbanceConfig, SensorConfig
from shipgym.limits import MAX_POSITION_M, MAX_WAYPOINTS
from shipgym.models import MODELS
from shipgym.models.base import ParameterError
from shipgym.scenarios.families import OTHER, check_family

#: one problem found by a check across keys: (location, message, the input at fault)
KeyProblem = tuple[tuple[str | int, ...], str, Any]

__all__ = [
    "EventConfig",
    "GuidanceConfig",
    "InitialState",
    "PathConfig",
    "RewardConfig",
    "ScenarioConfig",
    "ShipConfig",
]


class ShipConfig(StrictModel):
    """Which model, its parameters (paper units) and the unit reading of those numbers."""

    model: str = "nomoto2"
    unit_reading: str | None = Field(
        default=None, description="how the paper's units map to SI (nomoto2: si|degrees|…)"
    )
    params: dict[str, float] = Field(default_factory=dict)
    variant: str | None = Field(
        default=None, description="structural variant of the model's equations (esso_osaka: …)"
    )

    @model_validator(mode="after")
    def _a_real_ship(self) -> ShipConfig:
        """A known model, variant and unit reading, and parameters a real plant can have
        (:meth:`shipgym.models.base.ParameterRecord.plant`: every bad one named)."""
        model_cls = MODELS.get(self.model)
        if model_cls is None:
            message = f"unknown model {self.model!r}; valid: {sorted(MODELS)}"
            raise key_errors("ShipConfig", [(("model",), message, self.model)])
        problems: list[KeyProblem] = []
        if self.variant is not None and self.variant not in model_cls.variants:
            valid = list(model_cls.variants) or "none (the model has one form)"
            message = f"unknown variant {self.variant!r} of {self.model}; valid: {valid}"
            problems.append((("variant",), message, self.variant))
        if self.unit_reading is not None and self.unit_reading not in model_cls.unit_readings:
            message = (
                f"unknown unit_reading {self.unit_reading!r} of {self.model}; "
                f"valid: {list(model_cls.unit_readings)}"
            )
            problems.append((("unit_reading",), message, self.unit_reading))
        if not problems:
            try:
                model_cls.from_config(self.params, self.unit_reading, self.variant)
            except ParameterError as exc:
                problems += [(("params",), text, self.params) for text in exc.problems]
        if problems:
            raise key_errors("ShipConfig", problems)
        return self


def check_position(value: float) -> float:
    """A coordinate [m] within the documented limit ±MAX_POSITION_M (shipgym.limits)."""
    if abs(value) > MAX_POSITION_M:
        raise ValueError(f"{value:.6g} m is beyond the limit of ±{MAX_POSITION_M:.6g} m")
    return value


class InitialState(StrictModel):
    x: Annotated[float, AfterValidator(check_position)] = 0.0  # m
    y: Annotated[float, AfterValidator(check_position)] = 0.0  # m
    heading_deg: float = 0.0  # deg
    states: dict[str, float] = Field(default_factory=dict)  # other states, SI


class PathConfig(StrictModel):
    type: Literal["waypoints", "pchip"] = "waypoints"
    waypoints: list[tuple[float, float]]
    switching: Literal["circle", "along_track"] = "circle"
    acceptance_radius_L: float = Field(2.0, gt=0)  # R0 = 2L, Liu et al. (2019) eq. (13)

    @field_validator("waypoints")
    @classmethod
    def _at_least_two(cls, v: list[tuple[float, float]]) -> list[tuple[float, float]]:
        if len(v) < 2:
            raise ValueError("a path needs at least 2 waypoints")
        if len(v) > MAX_WAYPOINTS:
            raise ValueError(f"{len(v)} waypoints, beyond the limit of {MAX_WAYPOINTS}")
        for point in v:
            for c in point:
                check_position(c)
        return v


class GuidanceConfig(StrictModel):
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


class EventConfig(StrictModel):
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


class RewardConfig(StrictModel):
    """r = −(|e|/L + w_ψ|ψ̃| + w_δ(δc/δmax)² + w_Δ(Δδc/δmax)²) per step (docs/environment.md)."""

    heading_weight: float = Field(0.1, ge=0)
    rudder_weight: float = Field(0.01, ge=0)
    rudder_rate_weight: float = Field(0.05, ge=0)
    goal_bonus: float = Field(10.0, ge=0)
    max_cross_track_L: float = Field(10.0, gt=0)  # corridor half-width in ship lengths


class ScenarioConfig(StrictModel):
    name: Name  # figures and tables are files named after it (shipgym.limits.name_problem)
    description: str = ""
    source: str = ""
    #: the change family (shipgym.scenarios.families; a file without it: "other"), left
    #: out of every dump: the recorded settings, and a trial's identity, are the plant's
    #: (a copy with overrides keeps it: StrictModel.with_overrides)
    family: Annotated[str, AfterValidator(check_family)] = Field(OTHER, exclude=True)
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
    def _times_within_the_episode(self) -> ScenarioConfig:
        """Events in time order and before the time limit (each problem under its key)."""
        problems: list[KeyProblem] = []
        for i, event in enumerate(self.events):
            if event.time >= self.time_limit:
                problems.append(
                    (
                        ("events", i, "time"),
                        f"event at {event.time} s is not before the time limit "
                        f"(time_limit: {self.time_limit} s): it would never happen",
                        event.time,
                    )
                )
            if i and event.time < self.events[i - 1].time:
                problems.append(
                    (
                        ("events", i, "time"),
                        f"events must be listed in time order: {event.time} s comes after "
                        f"{self.events[i - 1].time} s",
                        event.time,
                    )
                )
        if problems:
            raise key_errors(type(self).__name__, problems)
        return self


def key_errors(title: str, problems: list[KeyProblem]) -> ValidationError:
    """A pydantic ValidationError with one error per (location, message, input), so that a
    check relating several keys reports each problem under the key at fault (raised from a
    model validator, the locations nest under the model's own)."""
    return ValidationError.from_exception_data(
        title,
        [
            InitErrorDetails(
                type=PydanticCustomError("invalid", "{message}", {"message": message}),
                loc=loc,
                input=value,
            )
            for loc, message, value in problems
        ],
    )
