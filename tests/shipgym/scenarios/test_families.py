"""The change families: one record each, a ``family:`` key in every catalogue file, checked
against the registry, kept out of every dump."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from shipgym.identification.adaptation import QUANTITIES
from shipgym.scenarios.families import (
    CHANGES,
    FAMILIES,
    NOMINAL,
    OTHER,
    TARGETS,
    check_family,
    family_label,
)
from shipgym.scenarios.loader import (
    Scenario,
    ScenarioError,
    catalogue_dir,
    check_scenario_file,
    list_scenarios,
    load_scenario,
    load_scenario_file,
)
from shipgym.scenarios.twins import nominal_twin

BASE = "path: {waypoints: [[0, 0], [10, 0]]}\ntime_limit: 10.0\n"


def change_targets(scenario: Scenario) -> set[str]:
    """What the scenario's change moves (:data:`TARGETS`): each event parameter (the
    steering gear's: the ship's servo and rate quantities; nomoto2's d0: the yaw bias; any
    other: the hull) and a two-phase current."""
    gear = {
        p for q in QUANTITIES[scenario.model.name] if q.name in ("servo", "rate") for p in q.params
    }
    moved = {
        "steering_gear" if p in gear else "yaw_bias" if p == "d0" else "hull"
        for event in scenario.config.events
        for p in event.params
    }
    if getattr(scenario.config.disturbances.current, "kind", None) == "two_phase":
        moved.add("current")
    return moved


def test_each_family_is_registered_once_in_table_order() -> None:
    assert list(FAMILIES) == [
        NOMINAL,
        "rudder_aging",
        "current_shift",
        "maneuverability_change",
        OTHER,
    ]
    assert CHANGES == ("rudder_aging", "current_shift", "maneuverability_change")
    for name, family in FAMILIES.items():
        assert family.name == name and family.changes
        assert family.targets is None or family.targets <= set(TARGETS)
    assert family_label("maneuverability_change") == "maneuverability change"
    with pytest.raises(ValueError, match="'rudder'; valid: nominal, rudder_aging"):
        check_family("rudder")


@pytest.mark.parametrize("name", list_scenarios())
def test_every_catalogue_file_states_its_family(name: str) -> None:
    """The key is required in the catalogue (a user's file may leave it out: ``other``)."""
    raw = yaml.safe_load(catalogue_dir().joinpath(f"{name}.yaml").read_text())
    assert raw.get("family") in FAMILIES, f"configs/scenarios/{name}.yaml: no family: key"
    assert load_scenario(name).family == raw["family"]


@pytest.mark.parametrize("name", list_scenarios())
def test_a_catalogue_scenario_changes_only_what_its_family_moves(name: str) -> None:
    scenario = load_scenario(name)
    targets = FAMILIES[scenario.family].targets
    if targets is None:  # other: anything
        return
    moved = change_targets(scenario)
    assert moved <= targets, (scenario.family, moved)
    assert bool(moved) == bool(targets), (scenario.family, moved)


def test_a_file_without_a_family_is_other_and_a_bad_one_is_named(tmp_path: Path) -> None:
    mine = tmp_path / "mine.yaml"
    mine.write_text(f"name: mine\n{BASE}")
    assert load_scenario_file(mine).family == OTHER
    bad = tmp_path / "bad.yaml"
    bad.write_text(f"name: bad\nfamily: rudder_agin\n{BASE}")
    with pytest.raises(ScenarioError, match=r"bad\.yaml.*family.*'rudder_agin'.*valid: "):
        load_scenario_file(bad)
    (problem,) = check_scenario_file(bad)
    assert (problem.key, problem.line) == ("family", 2)
    assert "unknown change family 'rudder_agin'" in problem.message


def test_no_dump_holds_the_family_and_overrides_keep_it() -> None:
    """The recorded settings (``run.json``) and a trial's identity are the plant's: a
    scenario's dump is the same whatever its family."""
    scenario = load_scenario("mariner_rudder_aging")
    assert scenario.family == "rudder_aging"
    assert "family" not in scenario.config.model_dump(mode="json")
    assert "family" not in scenario.config.model_dump()
    assert scenario.with_overrides({"time_limit": 500.0}).family == "rudder_aging"
    assert scenario.with_overrides({"family": "other"}).family == OTHER
    twin = nominal_twin(scenario)
    assert twin is not None and twin.family == NOMINAL


def test_a_sampled_scenario_is_other() -> None:
    """A distribution's scenarios name no family (their jump kinds are free names, some
    combine two changes): the leaderboard's held-out and in-range rows are ``other``."""
    assert load_scenario("heldout:1").family == OTHER
