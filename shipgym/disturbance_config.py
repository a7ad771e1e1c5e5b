"""Settings of the disturbances and the sensor model (``disturbances:`` and ``sensors:`` of a
scenario), validated at the boundary; :mod:`shipgym.disturbances` turns them into processes.

Units are those of the config files: m/s, seconds, degrees where a key says ``_deg``.  The
scenario schema (:mod:`shipgym.scenarios.schema`) embeds these models, so the dependency
points scenarios → disturbances.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import Field, field_validator, model_validator

from shipgym.config import StrictModel


class _CurrentBase(StrictModel):
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


class WaveConfig(StrictModel):
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


class DisturbanceConfig(StrictModel):
    """Environmental disturbances (shipgym.disturbances): current and waves."""

    current: CurrentConfig = ConstantCurrent()
    waves: WaveConfig | None = None  # None: calm sea

    @field_validator("current", mode="before")
    @classmethod
    def _constant_by_default(cls, v: object) -> object:
        if isinstance(v, dict) and "kind" not in v:
            return {**v, "kind": "constant"}
        return v


class SensorConfig(StrictModel):
    """Measurement model of heading and yaw rate (shipgym.disturbances.SensorModel)."""

    heading_noise_deg: float = Field(0.0, ge=0)  # std of Gaussian heading noise
    yaw_rate_noise_deg_s: float = Field(0.0, ge=0)
    outlier_probability: float = Field(0.0, ge=0, le=1)  # per fine sample
    outlier_magnitude_deg: tuple[float, float] = (5.0, 15.0)  # |spike| range on heading
    dropout_probability: float = Field(0.0, ge=0, le=1)  # per fine sample: hold last value

    @field_validator("outlier_magnitude_deg")
    @classmethod
    def _a_range(cls, v: tuple[float, float]) -> tuple[float, float]:
        """A range of spike sizes: 0 ≤ low ≤ high (what the sensor draws from)."""
        if not 0 <= v[0] <= v[1]:
            raise ValueError(f"must be [low, high] with 0 ≤ low ≤ high, got {list(v)}")
        return v
