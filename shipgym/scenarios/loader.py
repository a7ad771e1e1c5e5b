"""Load scenarios by catalogue name, from a YAML file, or from a config object."""

from __future__ import annotations

import dataclasses
import math
import os
from pathlib import Path as FilePath
from typing import Any

import yaml
from pydantic import ValidationError

from shipgym.models import MODELS, ParameterError, ShipModel
from shipgym.paths import PchipPath, WaypointPath
from shipgym.scenarios.events import ParameterEvent, ParameterSchedule
from shipgym.scenarios.schema import ScenarioConfig, format_validation_error

DEG = math.pi / 180.0


class ScenarioError(ValueError):
    """A scenario cannot be found or is malformed; the message names the file and key."""


def catalogue_dir() -> FilePath:
    """``configs/scenarios`` of the repository (override with ``SHIPGYM_SCENARIO_DIR``)."""
    override = os.environ.get("SHIPGYM_SCENARIO_DIR")
    if override:
        return FilePath(override)
    return FilePath(__file__).resolve().parents[2] / "configs" / "scenarios"


def list_scenarios() -> list[str]:
    """Names of the catalogue scenarios."""
    return sorted(p.stem for p in catalogue_dir().glob("*.yaml"))


@dataclasses.dataclass(frozen=True)
class Scenario:
    """A validated scenario, with SI objects built: model, path, parameter schedule.

    ``nominal_params`` (the pre-change parameters) is what a model-based controller may
    use; ``schedule`` is the truth and is for the simulator only.
    """

    config: ScenarioConfig
    model: ShipModel
    path: WaypointPath | PchipPath
    schedule: ParameterSchedule
    source_file: str | None = None

    @property
    def name(self) -> str:
        return self.config.name

    @property
    def nominal_params(self):
        return self.schedule.nominal

    @property
    def ship_length(self) -> float:
        return self.model.length

    @property
    def control_period(self) -> float:
        return self.config.control_period or self.model.control_period

    @property
    def fine_step(self) -> float:
        return self.config.fine_step or self.model.fine_step

    @property
    def substeps(self) -> int:
        n = round(self.control_period / self.fine_step)
        return n

    @property
    def acceptance_radius(self) -> float:
        return self.config.path.acceptance_radius_L * self.ship_length

    @property
    def max_cross_track(self) -> float:
        return self.config.reward.max_cross_track_L * self.ship_length

    @property
    def change_time(self) -> float | None:
        return self.schedule.first_change_time

    def initial_state(self):
        cfg = self.config.initial_state
        values = {"x": cfg.x, "y": cfg.y, "psi": cfg.heading_deg * DEG, **cfg.states}
        return self.model.cruise_state(**values)


def build_scenario(config: ScenarioConfig, origin: str = "<scenario>") -> Scenario:
    """SI objects from a validated config; errors name ``origin`` and the key."""
    ship = config.ship
    if ship.model not in MODELS:
        raise ScenarioError(
            f"{origin}: key 'ship.model': unknown model {ship.model!r}; valid: {sorted(MODELS)}"
        )
    model_cls = MODELS[ship.model]
    if ship.variant is not None and ship.variant not in model_cls.variants:
        valid = list(model_cls.variants) or "none (the model has one form)"
        raise ScenarioError(
            f"{origin}: key 'ship.variant': unknown variant {ship.variant!r} of {ship.model}; "
            f"valid: {valid}"
        )
    try:
        model = model_cls.from_config(ship.params, ship.unit_reading, ship.variant)
    except ParameterError as exc:
        raise ScenarioError(f"{origin}: key 'ship.params': {exc}") from exc
    events = []
    for i, ev in enumerate(config.events):
        try:
            values = model_cls.config_to_si(ev.params, ship.unit_reading)
        except ParameterError as exc:
            raise ScenarioError(f"{origin}: key 'events.{i}.params': {exc}") from exc
        events.append(ParameterEvent(ev.time, values, ev.kind, ev.duration))
    try:
        schedule = ParameterSchedule(model.params, events)
    except ParameterError as exc:
        raise ScenarioError(f"{origin}: key 'events': {exc}") from exc
    try:
        path_cls = WaypointPath if config.path.type == "waypoints" else PchipPath
        path = path_cls(config.path.waypoints)
    except ValueError as exc:
        raise ScenarioError(f"{origin}: key 'path.waypoints': {exc}") from exc
    try:
        model.initial_state(**config.initial_state.states)
    except KeyError as exc:
        raise ScenarioError(f"{origin}: key 'initial_state.states': {exc.args[0]}") from None
    fine = config.fine_step or model.fine_step
    period = config.control_period or model.control_period
    ratio = period / fine
    if abs(ratio - round(ratio)) > 1e-9 or round(ratio) < 1:
        raise ScenarioError(
            f"{origin}: key 'control_period': {period} s is not a whole multiple of the "
            f"fine step {fine} s"
        )
    return Scenario(config, model, path, schedule, origin if origin != "<scenario>" else None)


def scenario_from_dict(data: Any, origin: str = "<dict>") -> Scenario:
    if not isinstance(data, dict):
        raise ScenarioError(
            f"{origin}: expected a mapping at the top level, got {type(data).__name__}"
        )
    try:
        config = ScenarioConfig.model_validate(data)
    except ValidationError as exc:
        raise ScenarioError(format_validation_error(exc, origin)) from None
    return build_scenario(config, origin)


def load_scenario_file(path: str | os.PathLike) -> Scenario:
    file = FilePath(path)
    if not file.is_file():
        raise ScenarioError(f"scenario file not found: {file}")
    try:
        data = yaml.safe_load(file.read_text())
    except yaml.YAMLError as exc:
        raise ScenarioError(f"{file}: malformed YAML: {exc}") from None
    return scenario_from_dict(data, str(file))


def load_scenario(spec: str | os.PathLike | Scenario | ScenarioConfig) -> Scenario:
    """A scenario from a catalogue name, a YAML path, a Scenario, a ScenarioConfig or the
    name of a held-out test scenario ``"<distribution>:<index>"`` (``heldout:3``)."""
    if isinstance(spec, Scenario):
        return spec
    if isinstance(spec, ScenarioConfig):
        return build_scenario(spec)
    if isinstance(spec, dict):
        return scenario_from_dict(spec)
    if not isinstance(spec, str | os.PathLike):
        raise ScenarioError(
            f"scenario must be a catalogue name, a YAML path or a Scenario, got {spec!r}"
        )
    text = os.fspath(spec)
    if text.endswith((".yaml", ".yml")) or os.sep in text:
        return load_scenario_file(text)
    if ":" in text:  # a named scenario of a test distribution, e.g. "heldout:3"
        from shipgym.scenarios.sampling import DistributionError, sampled_scenario_config

        try:
            return build_scenario(sampled_scenario_config(text), text)
        except DistributionError as exc:
            raise ScenarioError(str(exc)) from None
    names = list_scenarios()
    if text not in names:
        raise ScenarioError(f"unknown scenario {text!r}; valid names: {', '.join(names)}")
    return load_scenario_file(catalogue_dir() / f"{text}.yaml")
