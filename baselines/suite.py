"""Benchmark suites (``configs/suites``): the scenarios, controllers and seeds of a
leaderboard run (docs/leaderboard.md), validated when the file is read."""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Annotated, Any

from pydantic import Discriminator, Field, Tag, ValidationError, field_validator, model_validator

from shipgym.config import (
    ConfigError,
    ConfigFile,
    Name,
    StrictModel,
    error_message,
    is_path,
    list_names,
    load_yaml_model,
    parse_yaml,
    read_yaml,
    resolve,
)
from shipgym.errors import ShipgymError
from shipgym.limits import (
    MAX_HELDOUT_SCENARIOS,
    MAX_INRANGE_SCENARIOS,
    MAX_SEEDS,
    MAX_SUITE_SCENARIOS,
)
from shipgym.scenarios.loader import (
    Problem,
    Scenario,
    check_scenario_file,
    composed_config,
    list_scenarios,
    load_scenario,
    yaml_line,
)
from shipgym.scenarios.trials import TrialRandomization
from shipgym_baselines.plugins import ControllerEntry, ControllerSpec, anchored
from shipgym_baselines.records.trials import ALL, LearnedTrials


def _controller_form(value: Any) -> str:
    return "long form" if isinstance(value, dict | ControllerEntry) else "short form"


#: a suite's controller: a string, or the long form (errors name the form they read)
SuiteController = Annotated[
    Annotated[str, Tag("short form")] | Annotated[ControllerEntry, Tag("long form")],
    Discriminator(_controller_form),
]


class SuiteConfig(StrictModel):
    """A suite file.

    ``scenarios``: catalogue names, named test scenarios (``heldout:3``) or YAML paths (a
    relative path is read against the suite file's folder); ``heldout_scenarios`` N adds
    ``heldout:0 … heldout:N-1`` (jumps outside the training ranges) on the first
    ``heldout_seeds`` evaluation seeds (None: all ``seeds``), ``inrange_scenarios`` M adds
    ``inrange:0 … inrange:M-1`` (drawn from the training ranges; each split ranked in its
    own table) on the first ``inrange_seeds``;
    ``controllers``: what ``shipgym evaluate`` accepts
    (registered controllers, installed plug-ins, specs ``module.path:Attr`` /
    ``path/to/file.py:Attr``, shipped learned policies, trained agents' folders, SB3 model
    zips), each a string or the long form ``{controller: SPEC, name: TABLE_NAME, settings:
    {keyword: value}}`` (:class:`~shipgym_baselines.plugins.ControllerEntry`); a relative file path
    among them is read against the suite file's folder.  ``seeds``: evaluation seeds per
    (controller, scenario, training seed); ``learned_trials``: ``all`` (every training seed
    of a learned agent plays every seed) or ``shared`` (each seed is played by one training
    seed, :func:`~shipgym_baselines.records.trials.dealt_seeds`).  ``twins``: every
    competitor and the ``oracle`` also play each changing scenario's no-change twin on the
    same trials (:mod:`shipgym_baselines.leaderboard.twins`; what steering and what the
    change cost are apart).  ``randomize``: what each
    evaluation seed draws for its trial of a scenario
    (:class:`~shipgym.scenarios.trials.TrialRandomization`: start offset and heading
    error, jump-time jitter, current speed and direction; the sensor noise varies with the
    seed anyway); absent: every seed runs the scenario as written.
    """

    name: Name
    description: str = ""
    scenarios: list[str] = Field(default_factory=list, max_length=MAX_SUITE_SCENARIOS)
    heldout_scenarios: int = Field(0, ge=0, le=MAX_HELDOUT_SCENARIOS)
    heldout_seeds: int | None = Field(None, ge=1, le=MAX_SEEDS)
    inrange_scenarios: int = Field(0, ge=0, le=MAX_INRANGE_SCENARIOS)
    inrange_seeds: int | None = Field(None, ge=1, le=MAX_SEEDS)
    controllers: list[SuiteController] = Field(min_length=1)
    seeds: int = Field(5, ge=1, le=MAX_SEEDS)
    learned_trials: LearnedTrials = ALL
    twins: bool = True
    randomize: TrialRandomization | None = None

    @field_validator("scenarios")
    @classmethod
    def _scenarios_given_once(cls, scenarios: list[str]) -> list[str]:
        repeated = sorted({s for s in scenarios if scenarios.count(s) > 1})
        if repeated:
            raise ValueError(f"scenarios listed more than once: {repeated}")
        return scenarios

    @model_validator(mode="after")
    def _some_scenarios(self) -> SuiteConfig:
        if not self.scenarios and not self.heldout_scenarios and not self.inrange_scenarios:
            raise ValueError(
                "a suite needs 'scenarios' or 'heldout_scenarios' (or 'inrange_scenarios')"
            )
        return self

    def all_scenarios(self) -> list[str]:
        """The suite's scenarios followed by ``heldout:0 … heldout:N-1`` and
        ``inrange:0 … inrange:M-1``."""
        return [
            *self.scenarios,
            *(f"heldout:{i}" for i in range(self.heldout_scenarios)),
            *(f"inrange:{i}" for i in range(self.inrange_scenarios)),
        ]

    def scenario_seeds(self, seeds: Sequence[int]) -> dict[str, list[int]]:
        """The scenarios that run on fewer evaluation seeds than ``seeds`` (the run's), with
        theirs: each held-out scenario on the first ``heldout_seeds``, each in-range one on
        the first ``inrange_seeds``; empty when none do."""
        fewer: dict[str, list[int]] = {}
        for split, count, first in (
            ("heldout", self.heldout_scenarios, self.heldout_seeds),
            ("inrange", self.inrange_scenarios, self.inrange_seeds),
        ):
            if first is not None and first < len(seeds):
                fewer |= {f"{split}:{i}": list(seeds[:first]) for i in range(count)}
        return fewer


def list_suites() -> list[str]:
    """Names of the packaged suites."""
    return list_names("suites")


def _scenario_entry(entry: str, file: ConfigFile, index: int) -> str:
    """A suite's scenario as the leaderboard loads it: a relative path anchored at the suite's
    folder; a catalogue name checked (named test scenarios are checked when loaded)."""
    if ":" in entry and not is_path(entry):
        return entry
    anchor = file if isinstance(file, Path) else None
    try:
        found = resolve("scenarios", entry, relative_to=anchor, error=ConfigError)
    except ConfigError as exc:
        raise ConfigError(f"{file}: key 'scenarios.{index}': {exc}") from None
    return str(found) if is_path(entry) else entry


def load_suite(name_or_path: str | os.PathLike) -> SuiteConfig:
    """A suite by name (``configs/suites/<name>.yaml``) or YAML path; errors name the file
    and the key (a scenario file's ``name:`` that cannot be its table name too:
    :func:`scenario_names`)."""
    file = resolve("suites", name_or_path, error=ConfigError)
    suite = load_yaml_model(file, SuiteConfig, ConfigError)
    scenarios = [_scenario_entry(s, file, i) for i, s in enumerate(suite.scenarios)]
    scenario_names(scenarios, load_scenario, where=f"{file}: ")  # before any episode
    controllers = [_controller_entry(c, file) for c in suite.controllers]
    return suite.model_copy(update={"scenarios": scenarios, "controllers": controllers})


def _controller_entry(entry: ControllerSpec, file: ConfigFile) -> ControllerSpec:
    """A suite's controller with a relative file path anchored at the suite's folder."""
    if not isinstance(file, Path):  # a packaged suite names its controllers
        return entry
    folder = file.resolve().parent
    if isinstance(entry, str):
        return anchored(entry, folder)
    return entry.model_copy(update={"controller": anchored(entry.controller, folder)})


# --- how a suite's scenarios are named in the tables -----------------------------------------


@dataclasses.dataclass(frozen=True)
class ScenarioNames:
    """How a suite's scenario entries are named in its tables.

    ``names``: entry (as :func:`load_suite` gives it) → table name: a catalogue or held-out
    name as written, a YAML file's ``name:``; ``files``: table name → YAML file of the
    suite's own scenarios (a file that is a catalogue scenario, content for content, is
    named and grouped as that one); ``problems``: (entry index, message) of the names that
    cannot be table names (a clash with a catalogue scenario or another entry).
    """

    names: dict[str, str]
    files: dict[str, str]
    problems: list[tuple[int, str]]


def name_scenarios(entries: Sequence[str], load: Callable[[str], Scenario]) -> ScenarioNames:
    """The table names of a suite's scenario ``entries`` (:class:`ScenarioNames`); ``load``
    loads a YAML entry (the leaderboard's cached loader)."""
    catalogue = set(list_scenarios())
    names: dict[str, str] = {}
    files: dict[str, str] = {}
    problems: list[tuple[int, str]] = []
    taken: dict[str, str] = {}  # table name -> the entry that took it
    for index, entry in enumerate(entries):
        name = entry
        if is_path(entry):
            name = load(entry).name
            problem = _file_name_problem(entry, name, load, catalogue)
            if problem is not None:
                problems.append((index, problem))
                continue
            if name not in catalogue:
                files[name] = entry
        if name in taken:
            first = taken[name]
            what = "scenario files" if is_path(first) and is_path(entry) else "scenarios"
            problems.append(
                (
                    index,
                    f"{what} {first} and {entry} are both named {name!r}: each scenario of a "
                    "suite needs its own name (a file's `name:` key)",
                )
            )
            continue
        taken[name] = entry
        names[entry] = name
    return ScenarioNames(names, files, problems)


def _file_name_problem(
    entry: str, name: str, load: Callable[[str], Scenario], catalogue: set[str]
) -> str | None:
    """Why a scenario file's ``name:`` cannot name its table rows, or None."""
    if is_path(name) or ":" in name or not name.strip():
        return (
            f"scenario file {entry} is named {name!r}: a table name has no '/' or ':' and "
            "does not end in .yaml (give the file another `name:`)"
        )
    if name in catalogue and load(name).config != load(entry).config:
        return (
            f"scenario file {entry} is named {name!r}, as the catalogue's scenario "
            f"configs/scenarios/{name}.yaml, but its settings differ: give the file its own "
            "`name:`"
        )
    return None


def scenario_names(
    entries: Sequence[str], load: Callable[[str], Scenario], where: str = ""
) -> ScenarioNames:
    """:func:`name_scenarios`, a :class:`ConfigError` listing every problem when there is any
    (each line starting with ``where``, e.g. the suite file)."""
    found = name_scenarios(entries, load)
    if found.problems:
        lines = (f"{where}key 'scenarios.{i}': {text}" for i, text in found.problems)
        raise ConfigError("\n".join(lines))
    return found


# --- checking a suite file (``shipgym scenarios --validate``) --------------------------------

#: top-level keys that make a YAML file a suite (a scenario file has none of them)
SUITE_KEYS = ("controllers", "scenarios", "heldout_scenarios", "inrange_scenarios")


def is_suite_file(name_or_path: str | os.PathLike) -> bool:
    """Whether ``name_or_path`` is a suite: a packaged suite's name (that is no catalogue
    scenario's), or a YAML file whose top level has one of :data:`SUITE_KEYS`."""
    text = os.fspath(name_or_path)
    if not is_path(text):
        return text not in list_scenarios() and text in list_suites()
    try:
        data = read_yaml(Path(text).expanduser())
    except ShipgymError:
        return False  # unreadable: the scenario check names why
    return isinstance(data, Mapping) and any(key in data for key in SUITE_KEYS)


def check_suite_file(name_or_path: str | os.PathLike) -> list[Problem]:
    """Every problem of a suite file, each with its key and line (empty: valid).

    The schema's problems (types, ranges, unknown keys), then each scenario (a catalogue
    name, a held-out test scenario, a YAML file checked as ``shipgym scenarios --validate``
    checks it, its table name) and each controller (resolvable, its settings accepted by
    its factory, one table name each), whatever the schema found elsewhere."""
    composed = composed_config("suites", name_or_path, ConfigError)
    if isinstance(composed, Problem):
        return [composed]
    file, text, root = composed
    data = parse_yaml(text)
    if not isinstance(data, Mapping):
        return [Problem("", f"expected a mapping at the top level, got {type(data).__name__}")]
    problems: list[Problem] = []
    try:
        SuiteConfig.model_validate(data)
    except ValidationError as exc:
        for item in exc.errors():
            parts = [str(p) for p in item["loc"] if p not in ("short form", "long form")]
            problems.append(Problem(".".join(parts), error_message(item, SuiteConfig)))
    anchor = file if isinstance(file, Path) else None
    problems += _scenario_problems(data.get("scenarios"), anchor)
    problems += _controller_problems(data.get("controllers"), anchor)
    return [dataclasses.replace(p, line=yaml_line(root, p.key)) for p in problems]


def _scenario_problems(entries: Any, anchor: Path | None) -> list[Problem]:
    """The problems of a suite's ``scenarios`` list (entries that are not strings are the
    schema's)."""
    if not isinstance(entries, list) or len(entries) > MAX_SUITE_SCENARIOS:
        return []  # too many: the schema names it, before any is loaded
    problems: list[Problem] = []
    good: dict[int, str] = {}  # index -> the entry as the leaderboard loads it
    for i, entry in enumerate(entries):
        if not isinstance(entry, str):
            continue
        key = f"scenarios.{i}"
        if ":" in entry and not is_path(entry):
            try:
                load_scenario(entry)
            except ShipgymError as exc:
                problems.append(Problem(key, str(exc)))
            else:
                good[i] = entry
            continue
        try:
            found = resolve("scenarios", entry, relative_to=anchor, error=ConfigError)
        except ConfigError as exc:
            problems.append(Problem(key, str(exc)))
            continue
        if not is_path(entry):
            good[i] = entry
            continue
        inner = check_scenario_file(found)
        problems += [Problem(key, p.text(str(found))) for p in inner]
        if not inner:
            good[i] = str(found)
    indices = list(good)
    named = name_scenarios([good[i] for i in indices], load_scenario)
    problems += [Problem(f"scenarios.{indices[j]}", text) for j, text in named.problems]
    return sorted(problems, key=lambda p: int(p.key.split(".")[1]))  # in the file's order


def _controller_problems(entries: Any, anchor: Path | None) -> list[Problem]:
    """The problems of a suite's ``controllers`` list: each resolved as a run resolves it
    (entries of the wrong shape are the schema's), then their table names."""
    from shipgym_baselines.registry import controller_label

    if not isinstance(entries, list):
        return []
    labels: dict[str, int] = {}
    problems: list[Problem] = []
    for i, raw in enumerate(entries):
        try:
            entry: ControllerSpec = (
                raw if isinstance(raw, str) else ControllerEntry.model_validate(raw)
            )
        except ValidationError:
            continue  # the schema names it
        if anchor is not None:
            entry = _controller_entry(entry, anchor)
        try:
            label = controller_label(entry)
        except ShipgymError as exc:
            problems.append(Problem(f"controllers.{i}", str(exc)))
            continue
        if label in labels:
            problems.append(
                Problem(
                    f"controllers.{i}",
                    f"table name {label!r} is also controllers.{labels[label]}'s: give each "
                    "its own name (the long form {controller: ..., name: ...})",
                )
            )
        labels.setdefault(label, i)
    return problems
