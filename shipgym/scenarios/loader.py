"""Load scenarios by catalogue name, from a YAML file, or from a config object."""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Iterable, Mapping
from importlib.resources.abc import Traversable
from typing import Any

import yaml
from pydantic import ValidationError

from shipgym.config import (
    ConfigError,
    ConfigFile,
    catalogue,
    compose_yaml,
    error_message,
    is_path,
    list_names,
    load_yaml_model,
    read_config_text,
    read_yaml,
    resolve,
    validate_model,
)
from shipgym.identification.nominal import first_order_nomoto
from shipgym.limits import MAX_EPISODE_STEPS, MAX_SUBSTEPS
from shipgym.models import MODELS
from shipgym.models.base import ParameterError, ParameterRecord, ShipModel
from shipgym.paths import PchipPath, WaypointPath
from shipgym.scenarios.events import ParameterEvent, ParameterSchedule
from shipgym.scenarios.nominal import nominal_problem
from shipgym.scenarios.schema import ScenarioConfig

DEG = math.pi / 180.0


class ScenarioError(ConfigError):
    """A scenario cannot be found or is malformed; the message names the file and key.

    ``problems`` lists what :func:`build_scenario` found, one :class:`Problem` each (the
    message has one line per problem).
    """

    def __init__(self, message: str, problems: Iterable[Problem] = ()) -> None:
        super().__init__(message)
        self.problems: tuple[Problem, ...] = tuple(problems)


@dataclasses.dataclass(frozen=True)
class Problem:
    """One problem of a scenario: the dotted key at fault (``""``: the file as a whole),
    what is wrong, and the 1-based line of the YAML file when known."""

    key: str
    message: str
    line: int | None = None

    def text(self, file: str | None = None) -> str:
        """``line N: key 'K': message``, or with ``file`` ``FILE:N: key 'K': message`` (the
        parts that are known)."""
        line = "" if self.line is None else str(self.line)
        if file is not None:
            where = f"{file}:{line}: " if line else f"{file}: "
        else:
            where = f"line {line}: " if line else ""
        key = f"key '{self.key}': " if self.key else ""
        return f"{where}{key}{self.message}"


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
    def family(self) -> str:
        """The change family the file names (:mod:`shipgym.scenarios.families`)."""
        return self.config.family

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
    """SI objects from a validated config; errors name ``origin`` and the key.

    Checks every part (the ship's parameters against a real plant's, each event's result,
    path, initial states, control period) and reports all problems at once, one line each.
    """
    ship = config.ship  # model, variant, unit reading and parameters checked by the schema
    model_cls = MODELS[ship.model]
    model = model_cls.from_config(ship.params, ship.unit_reading, ship.variant)
    problems: list[Problem] = []
    events = []
    current: ParameterRecord | None = model.params
    for i, ev in enumerate(config.events):
        key = f"events.{i}.params"
        try:
            values = model_cls.config_to_si(ev.params, ship.unit_reading)
        except ParameterError as exc:
            problems += [Problem(key, text) for text in exc.problems]
            continue
        events.append(ParameterEvent(ev.time, values, ev.kind, ev.duration))
        if current is None:
            continue
        try:  # the ship after the change must be a real plant too
            current = current.plant(**values)
        except ParameterError as exc:
            problems += [Problem(key, f"after the event at {ev.time} s: {t}") for t in exc.problems]
            current = None
    schedule = None
    if not problems:
        try:
            schedule = ParameterSchedule(model.params, events)
        except ParameterError as exc:
            problems.append(Problem("events", str(exc)))
    path = None
    try:
        path_cls = WaypointPath if config.path.type == "waypoints" else PchipPath
        path = path_cls(config.path.waypoints)
    except ValueError as exc:
        problems.append(Problem("path.waypoints", str(exc)))
    try:
        model.initial_state(**config.initial_state.states)
    except KeyError as exc:
        problems.append(Problem("initial_state.states", str(exc.args[0])))
    problems += timing_problems(config, model)
    if problems:
        raise ScenarioError("\n".join(p.text(origin) for p in problems), problems=problems)
    return Scenario(config, model, path, schedule, origin if origin != "<scenario>" else None)


def nominal_nomoto(scenario: Scenario) -> tuple[float, float]:
    """First-order Nomoto (K [1/s], T [s]) of the scenario's nominal ship, as guidance mode
    and the model-based controllers use it; a :class:`ScenarioError` naming the key when
    there is none (:func:`shipgym.scenarios.nominal.nominal_problem`)."""
    found = nominal_problem(scenario)
    if found is not None:
        problem = Problem(*found)
        raise ScenarioError(problem.text(scenario.source_file or scenario.name), [problem])
    return first_order_nomoto(scenario.model, scenario.nominal_params)  # cached: not rerun


def timing_problems(config: ScenarioConfig, model: ShipModel) -> list[Problem]:
    """Problems of the episode's timing: a control period that is not a whole multiple of
    the fine step, and the limits of :mod:`shipgym.limits` — substeps per control period
    (named under ``fine_step`` when the file sets it, else ``control_period``) and steps
    per episode (``time_limit``)."""
    fine = config.fine_step or model.fine_step
    period = config.control_period or model.control_period
    ratio = period / fine
    if ratio > MAX_SUBSTEPS:
        key = "fine_step" if config.fine_step is not None else "control_period"
        return [
            Problem(
                key,
                f"control_period / fine_step = {period:.6g} s / {fine:.6g} s = {ratio:.6g} "
                f"substeps per step, beyond the limit of {MAX_SUBSTEPS}",
            )
        ]
    problems = []
    if abs(ratio - round(ratio)) > 1e-9 or round(ratio) < 1:
        problems.append(
            Problem(
                "control_period",
                f"{period} s is not a whole multiple of the fine step {fine} s",
            )
        )
    steps = config.time_limit / period
    if steps > MAX_EPISODE_STEPS:
        problems.append(
            Problem(
                "time_limit",
                f"time_limit / control_period = {config.time_limit:.6g} s / {period:.6g} s = "
                f"{steps:.6g} steps per episode, beyond the limit of {MAX_EPISODE_STEPS}",
            )
        )
    return problems


def scenario_from_dict(data: Any, origin: str = "<dict>") -> Scenario:
    """A scenario from a mapping of the YAML keys; errors name ``origin`` and the key."""
    return build_scenario(validate_model(data, ScenarioConfig, origin, ScenarioError), origin)


def load_scenario_file(path: str | os.PathLike | Traversable) -> Scenario:
    """A scenario from a YAML file (:func:`shipgym.config.resolve` finds it)."""
    file = resolve("scenarios", path, error=ScenarioError)
    return build_scenario(load_yaml_model(file, ScenarioConfig, ScenarioError), str(file))


def check_scenario_file(path: str | os.PathLike | Traversable) -> list[Problem]:
    """Every problem of a scenario YAML file, each with its key and line (empty: valid).

    Unlike :func:`load_scenario_file`, which stops at the first failing stage, this lists
    all schema problems pydantic finds (types, ranges, unknown keys, non-finite numbers,
    events after the time limit) and, when the schema passes, all problems of building
    the scenario (non-physical parameters, a bad path, …), then the nominal model's
    identification (:func:`nominal_nomoto`): every file it accepts makes an env."""
    composed = composed_config("scenarios", path, ScenarioError)
    if isinstance(composed, Problem):
        return [composed]
    file, _, root = composed
    try:
        data = read_yaml(file, ScenarioError)
    except ScenarioError as exc:
        return [Problem("", str(exc))]
    if not isinstance(data, Mapping):
        return [Problem("", f"expected a mapping at the top level, got {type(data).__name__}")]
    try:
        scenario = build_scenario(ScenarioConfig.model_validate(data), str(file))
        nominal_nomoto(scenario)  # what construction builds (guidance mode, controllers)
    except ValidationError as exc:
        found = [
            Problem(
                ".".join(str(part) for part in item["loc"]), error_message(item, ScenarioConfig)
            )
            for item in exc.errors()
        ]
    except ScenarioError as exc:
        found = list(exc.problems) or [Problem("", str(exc))]
    else:
        return []
    return [dataclasses.replace(p, line=yaml_line(root, p.key)) for p in found]


def composed_config(
    kind: str, name_or_path: str | os.PathLike | Traversable, error: type[ConfigError]
) -> tuple[ConfigFile, str, yaml.Node | None] | Problem:
    """The config file of ``kind`` (:func:`shipgym.config.resolve`), its text and its YAML
    node tree (where each key is written), or the problem that stops a check there (the
    file unreadable, ``error``'s message, or its YAML malformed)."""
    try:
        file = resolve(kind, name_or_path, error=error)
        text = read_config_text(file, error)
    except error as exc:
        return Problem("", str(exc))
    try:
        root = compose_yaml(text)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        return Problem("", f"malformed YAML: {exc.problem}", mark.line + 1 if mark else None)
    except yaml.YAMLError as exc:
        return Problem("", f"malformed YAML: {exc}")
    return file, text, root


def yaml_line(root: yaml.Node | None, key: str) -> int | None:
    """The 1-based line where the dotted ``key`` is written in a YAML node tree, or of its
    deepest part that is (a missing key: its parent's line); None for the whole file.
    Parts not in the tree are skipped (a union's tag, e.g. ``current.gauss_markov.mu``)."""
    if root is None or not key:
        return None
    node, line = root, None
    for part in key.split("."):
        if isinstance(node, yaml.MappingNode):
            for k, v in node.value:
                if isinstance(k, yaml.ScalarNode) and k.value == part:
                    node, line = v, k.start_mark.line + 1
                    break
        elif isinstance(node, yaml.SequenceNode) and part.isdigit():
            if int(part) < len(node.value):
                node = node.value[int(part)]
                line = node.start_mark.line + 1
    return line


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
