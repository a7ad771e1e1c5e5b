"""Load scenarios by catalogue name, from a YAML file, or from a config object."""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Iterable, Mapping
from importlib.resources.abc import Traversable
from typing import Any

from shipgym.config import (
    ConfigError,
    catalogue,
    is_path,
    list_names,
    load_yaml_model,
    resolve,
    validate_model,
)
from shipgym.models import MODELS, ParameterError, ShipModel
from shipgym.paths import PchipPath, WaypointPath
from shipgym.scenarios.events import ParameterEvent, ParameterSchedule
from shipgym.scenarios.schema import ScenarioConfig

DEG = math.pi / 180.0


class ScenarioError(ConfigError):
    """A scenario cannot be found or is malformed; the message names the file and key."""


def catalogue_dir() -> Traversable:
    """The packaged scenario catalogue, ``configs/scenarios``."""
    return catalogue("scenarios")


def list_scenarios() -> list[str]:
    """Names of the catalogue scenarios."""
    return list_names("scenarios")


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

    def with_overrides(
        self,
        overrides: Mapping[str, Any] | None = None,
        *,
        name: str | None = None,
        drop: Iterable[str] = (),
    ) -> Scenario:
        """This scenario with its config changed: the ``drop`` sections (dotted keys, e.g.
        ``"sensors"``) back to their defaults, then ``overrides`` deep-merged (mappings merge
        key by key: ``{"ship": {"params": {"Tc": 0.2}}}`` keeps the other parameters), then
        ``name``; validated and built like a loaded file."""
        if name is not None:
            overrides = {**(overrides or {}), "name": name}
        origin = name or f"{self.name} (overrides)"
        config = self.config.with_overrides(overrides, drop, origin, ScenarioError)
        return build_scenario(config, origin)


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
    """A scenario from a mapping of the YAML keys; errors name ``origin`` and the key."""
    return build_scenario(validate_model(data, ScenarioConfig, origin, ScenarioError), origin)


def load_scenario_file(path: str | os.PathLike | Traversable) -> Scenario:
    """A scenario from a YAML file (:func:`shipgym.config.resolve` finds it)."""
    file = resolve("scenarios", path, error=ScenarioError)
    return build_scenario(load_yaml_model(file, ScenarioConfig, ScenarioError), str(file))


def load_scenario(
    spec: str | os.PathLike | Traversable | Scenario | ScenarioConfig | Mapping[str, Any],
) -> Scenario:
    """A scenario from a catalogue name, a YAML path, a Scenario, a ScenarioConfig, a mapping
    of the YAML keys or the name of a held-out test scenario ``"<distribution>:<index>"``
    (``heldout:3``)."""
    if isinstance(spec, Scenario):
        return spec
    if isinstance(spec, ScenarioConfig):
        return build_scenario(spec)
    if isinstance(spec, Mapping):
        return scenario_from_dict(spec)
    if isinstance(spec, str) and ":" in spec and not is_path(spec):
        # a named scenario of a test distribution, e.g. "heldout:3"
        from shipgym.scenarios.sampling import DistributionError, sampled_scenario_config

        try:
            return build_scenario(sampled_scenario_config(spec), spec)
        except DistributionError as exc:
            raise ScenarioError(str(exc)) from None
    if not isinstance(spec, str | os.PathLike | Traversable):
        raise ScenarioError(
            f"scenario must be a catalogue name, a YAML path or a Scenario, got {spec!r}"
        )
    return load_scenario_file(spec)
