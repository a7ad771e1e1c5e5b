"""A study's definition: ``configs/tuning/<name>.yaml`` (search space, budget, trials).

::

    controller: pid_los            # what `make_controller` builds (classical), or
    kind: classical                # "learned": an agent config of configs/agents
    per_ship: true                 # one study (and one chosen setting) per ship
    budget: 40                     # trials per study (`--trials` overrides)
    objective: cost_ratio_gmean    # the geometric mean over the validation trials of C/C_oracle
    validation: {distribution: validation, per_ship: 8}
    chunk: 2                       # trials between two pruning reports
    fixed: {preset: paper}         # settings every trial gets (under the sampled ones)
    default: {preset: paper}       # what the best is compared with (before tuning)
    params:
      natural_frequency_T: {low: 0.3, high: 10.0, log: true, default: ...}
      los_radius_L: {low: 1.0, high: 8.0}
      tuning: {choices: [pole_placement, vyshnegradsky]}

A parameter is a float (``low``/``high``, ``log``), an int (``type: int``) or categorical
(``choices``); its name is the keyword the controller's factory takes (classical) or a
training setting (learned: :mod:`shipgym_baselines.tuning.learned`).
"""

from __future__ import annotations

import math
import os
from typing import Any, Literal

from pydantic import Field, model_validator

from shipgym.config import ConfigError, StrictModel, list_names, load_yaml_model, resolve
from shipgym_baselines.learned.curves import PlateauRule

#: the objectives a study can minimise
OBJECTIVES = ("cost_ratio_gmean",)


class TuningError(ConfigError):
    """A tuning config cannot be found or is malformed (names the file and key)."""


class ParamSpec(StrictModel):
    """One tuned parameter: ``[low, high]`` (``log``: sampled on a log scale), an ``int``
    range, or ``choices``."""

    type: Literal["float", "int", "categorical"] = "float"
    low: float | None = None
    high: float | None = None
    log: bool = False
    choices: list[Any] | None = None

    @model_validator(mode="after")
    def _valid(self) -> ParamSpec:
        if self.type == "categorical" or self.choices is not None:
            if not self.choices or self.low is not None or self.high is not None:
                raise ValueError("a categorical parameter gives 'choices' only")
            return self
        if self.low is None or self.high is None or not self.low < self.high:
            raise ValueError(f"need low < high, got low={self.low}, high={self.high}")
        if self.log and self.low <= 0:
            raise ValueError(f"log: needs low > 0, got {self.low}")
        if not (math.isfinite(self.low) and math.isfinite(self.high)):
            raise ValueError("low and high must be finite")
        return self

    def suggest(self, trial: Any, name: str) -> Any:
        """The value an Optuna trial suggests for this parameter."""
        if self.choices is not None:
            return trial.suggest_categorical(name, self.choices)
        if self.type == "int":
            return trial.suggest_int(name, int(self.low), int(self.high), log=self.log)
        return trial.suggest_float(name, self.low, self.high, log=self.log)


class ValidationSpec(StrictModel):
    """The validation trials a study scores on: ``per_ship`` of each ship's named
    validation scenarios (None: all), in the distribution's interleaved order."""

    distribution: str = "validation"
    per_ship: int | None = Field(None, ge=1)


class TrainingSpec(StrictModel):
    """Learned studies: the agent config trained per trial, its env steps and the number of
    intermediate evaluations (each one a pruning report)."""

    agent: str
    n_timesteps: int = Field(ge=1)
    evaluations: int = Field(2, ge=1)


#: the final training's default plateau rule: under 2 % gain of the selection metric (the
#: relative cost) over the last 25 % of training (docs/training.md, "Plateau rule")
FINAL_PLATEAU = PlateauRule(
    min_gain=0.02, window=0.25, min_evaluations=4, metric="selection", min_fraction=0.34
)


class FinalSpec(StrictModel):
    """Learned studies: the protocol's final training with the chosen settings
    (``shipgym train AGENT --settings tuned``): its env-step budget, plateau rule, model
    selection and seeds (docs/training.md, "From a study to shipped agents")."""

    n_timesteps: int = Field(ge=1)
    plateau: PlateauRule = FINAL_PLATEAU
    select_on: Literal["return", "relative_cost"] = "relative_cost"
    seeds: list[int] = Field(default_factory=lambda: [0, 1, 2], min_length=1)

    @model_validator(mode="after")
    def _valid(self) -> FinalSpec:
        if any(seed < 0 for seed in self.seeds) or len(set(self.seeds)) != len(self.seeds):
            raise ValueError(f"seeds: distinct non-negative integers, got {self.seeds}")
        if self.plateau.metric == "selection" and self.select_on != "relative_cost":
            raise ValueError("plateau.metric 'selection' needs select_on: relative_cost")
        return self


class TuningConfig(StrictModel):
    name: str
    description: str = ""
    controller: str
    kind: Literal["classical", "learned"] = "classical"
    per_ship: bool = True
    ships: list[str] | None = None
    budget: int = Field(ge=1)
    objective: Literal["cost_ratio_gmean"] = "cost_ratio_gmean"
    validation: ValidationSpec = ValidationSpec()
    chunk: int = Field(4, ge=1)
    sampler_seed: int = Field(0, ge=0)
    startup_trials: int = Field(5, ge=0)
    fixed: dict[str, Any] = Field(default_factory=dict)
    #: the settings the best is compared with: the construction before tuning
    default: dict[str, Any] = Field(default_factory=dict)
    params: dict[str, ParamSpec]
    training: TrainingSpec | None = None
    #: learned studies: the final training with the chosen settings (None: not defined)
    final: FinalSpec | None = None

    @model_validator(mode="after")
    def _valid(self) -> TuningConfig:
        if not self.params:
            raise ValueError("params: list at least one tuned parameter")
        if (self.kind == "learned") != (self.training is not None):
            raise ValueError("training: a learned study gives it, a classical one does not")
        if self.final is not None and self.kind != "learned":
            raise ValueError("final: the final training of a learned study (kind: learned)")
        if self.kind == "learned" and self.per_ship:
            raise ValueError("per_ship: a learned agent is one policy for every ship (false)")
        both = sorted(set(self.fixed) & set(self.params))
        if both:
            raise ValueError(f"fixed: {both} are tuned (params), not fixed")
        if self.kind == "learned":  # the default trains as every trial does (env, rollout)
            unequal = sorted(k for k, v in self.fixed.items() if self.default.get(k, v) != v)
            missing = sorted(set(self.fixed) - set(self.default))
            if unequal or missing:
                raise ValueError(
                    f"default: a learned study's default is trained with the fixed settings "
                    f"of every trial; give {sorted(set(unequal) | set(missing))} as in fixed"
                )
        if self.ships is not None:
            from shipgym.models import MODELS

            unknown = [s for s in self.ships if s not in MODELS]
            if unknown:
                raise ValueError(f"ships: unknown {unknown}; valid: {sorted(MODELS)}")
        return self


def list_tuning() -> list[str]:
    """Names of the packaged tuning configs (``configs/tuning``)."""
    return list_names("tuning")


def load_tuning(name_or_path: str | os.PathLike) -> TuningConfig:
    """A tuning config by name (``configs/tuning/<name>.yaml``) or YAML path."""
    file = resolve("tuning", name_or_path, error=TuningError)
    return load_yaml_model(file, TuningConfig, TuningError)
