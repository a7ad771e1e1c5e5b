"""Benchmark suites (``configs/suites``): the scenarios, controllers and seeds of a
leaderboard run (SPEC §9), validated when the file is read."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Annotated, Any

from pydantic import Discriminator, Field, Tag, model_validator

from shipgym.config import ConfigFile, StrictModel, is_path, list_names, load_yaml_model, resolve
from shipgym.limits import MAX_HELDOUT_SCENARIOS, MAX_SEEDS
from shipgym.scenarios.trials import TrialRandomization
from shipgym_baselines.errors import ConfigError
from shipgym_baselines.plugins import ControllerEntry, ControllerSpec, anchored


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
    ``heldout:0 … heldout:N-1``; ``controllers``: what ``shipgym evaluate`` accepts
    (registered controllers, installed plug-ins, specs ``module.path:Attr`` /
    ``path/to/file.py:Attr``, shipped learned policies, trained agents' folders, SB3 model
    zips), each a string or the long form ``{controller: SPEC, name: TABLE_NAME, settings:
    {keyword: value}}`` (:class:`~shipgym_baselines.plugins.ControllerEntry`); a relative file path
    among them is read against the suite file's folder.  ``seeds``: evaluation seeds per
    (controller, scenario, training seed).  ``randomize``: what each evaluation seed draws
    for its trial of a scenario (:class:`~shipgym.scenarios.trials.TrialRandomization`:
    start offset and heading error, jump-time jitter, current speed and direction; the
    sensor noise varies with the seed anyway); absent: every seed runs the scenario as
    written.
    """

    name: str
    description: str = ""
    scenarios: list[str] = Field(default_factory=list)
    heldout_scenarios: int = Field(0, ge=0, le=MAX_HELDOUT_SCENARIOS)
    controllers: list[SuiteController] = Field(min_length=1)
    seeds: int = Field(5, ge=1, le=MAX_SEEDS)
    randomize: TrialRandomization | None = None

    @model_validator(mode="after")
    def _scenarios_given_once(self) -> SuiteConfig:
        if not self.scenarios and not self.heldout_scenarios:
            raise ValueError("a suite needs 'scenarios' or 'heldout_scenarios'")
        repeated = sorted({s for s in self.scenarios if self.scenarios.count(s) > 1})
        if repeated:
            raise ValueError(f"scenarios listed more than once: {repeated}")
        return self

    def all_scenarios(self) -> list[str]:
        """The suite's scenarios followed by ``heldout:0 … heldout:N-1``."""
        return [*self.scenarios, *(f"heldout:{i}" for i in range(self.heldout_scenarios))]


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
    and the key."""
    file = resolve("suites", name_or_path, error=ConfigError)
    suite = load_yaml_model(file, SuiteConfig, ConfigError)
    scenarios = [_scenario_entry(s, file, i) for i, s in enumerate(suite.scenarios)]
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
