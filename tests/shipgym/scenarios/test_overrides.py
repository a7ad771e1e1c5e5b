"""Tests for Scenario.with_overrides: the same config as editing the YAML dict by hand."""

from __future__ import annotations

import copy
from typing import Any

import pytest
import yaml

from shipgym.disturbance_config import SensorConfig
from shipgym.scenarios.loader import (
    ScenarioError,
    catalogue_dir,
    list_scenarios,
    load_scenario,
    scenario_from_dict,
)

NOMOTO = [n for n in list_scenarios() if load_scenario(n).model.name == "nomoto2"]


def raw(name: str) -> dict[str, Any]:
    return yaml.safe_load((catalogue_dir() / f"{name}.yaml").read_text())


@pytest.mark.parametrize("name", NOMOTO)
@pytest.mark.parametrize(("unit_reading", "noise_free"), [("degrees", False), (None, True)])
def test_variant_equals_the_edited_yaml(name: str, unit_reading: str | None, noise_free: bool):
    """The old route of shipgym_baselines.reproduce.variants: edit the catalogue file's dict,
    then load it."""
    data = copy.deepcopy(raw(name))
    overrides: dict[str, Any] = {}
    drop = []
    if unit_reading is not None:
        data.setdefault("ship", {})["unit_reading"] = unit_reading
        overrides["ship"] = {"unit_reading": unit_reading}
    if noise_free:
        data.pop("sensors", None)
        drop.append("sensors")
    data["name"] = f"{name}[variant]"
    by_dict = scenario_from_dict(data)
    by_overrides = load_scenario(name).with_overrides(overrides, name=data["name"], drop=drop)
    assert by_overrides.config == by_dict.config
    assert by_overrides.nominal_params == by_dict.nominal_params
    assert by_overrides.schedule.final == by_dict.schedule.final


@pytest.mark.parametrize("name", ["mariner_track", "osaka_stochastic_current"])
def test_shorter_episode_equals_the_edited_dump(name: str) -> None:
    """The reproductions' route (borkowski2018, xu2021): model_dump, set time_limit, load."""
    scenario = load_scenario(name)
    data = scenario.config.model_dump()
    data["time_limit"] = 120.0
    shorter = scenario.with_overrides({"time_limit": 120.0})
    assert shorter.config == scenario_from_dict(data).config
    assert shorter.name == name and shorter.config.time_limit == 120.0


def test_nested_edits_equal_the_edited_dump() -> None:
    """The xu2020 route: variant, merged ship parameters, an initial state, the current."""
    base = load_scenario("osaka_curved")
    data = base.config.model_dump()
    data["name"] = "xu2020_curved"
    data["source"] = "Xu & Guedes Soares (2020) §6.2 (route and current assumed)"
    data["path"]["type"] = "pchip"
    data["ship"]["variant"] = "literal"
    data["ship"]["params"] = {**data["ship"]["params"], "rudder_rate": 100.0}
    data["initial_state"]["states"] = {**data["initial_state"]["states"], "u": 0.1}
    data["time_limit"] = 300.0
    data["disturbances"]["current"]["speed"] = 0.05
    by_overrides = base.with_overrides(
        {
            "source": "Xu & Guedes Soares (2020) §6.2 (route and current assumed)",
            "path": {"type": "pchip"},
            "ship": {"variant": "literal", "params": {"rudder_rate": 100.0}},
            "initial_state": {"states": {"u": 0.1}},
            "time_limit": 300.0,
            "disturbances": {"current": {"speed": 0.05}},
        },
        name="xu2020_curved",
    )
    assert by_overrides.config == scenario_from_dict(data).config
    assert by_overrides.model.variant == "literal"


def test_the_base_scenario_is_untouched() -> None:
    base = load_scenario("maneuverability_change")
    before = base.config.model_dump()
    quiet = base.with_overrides({"ship": {"params": {"Tc": 0.2}}}, drop=["sensors", "events"])
    assert base.config.model_dump() == before
    assert quiet.config.sensors == SensorConfig() and quiet.schedule.events == []
    assert quiet.config.ship.params == {**base.config.ship.params, "Tc": 0.2}
    assert quiet.name == base.name


def test_dropping_a_section_then_replacing_it() -> None:
    """A constant current replaced by a Gauss–Markov one: drop it, then give the new one."""
    base = load_scenario("current_shift")
    gm = {"kind": "gauss_markov", "speed": 0.1, "sigma": 0.0}
    with pytest.raises(ScenarioError, match=r"disturbances\.current"):
        base.with_overrides({"disturbances": {"current": {"kind": "two_phase", "bad": 1}}})
    new = base.with_overrides({"disturbances": {"current": gm}}, drop=["disturbances.current"])
    assert new.config.disturbances.current.kind == "gauss_markov"


@pytest.mark.parametrize(
    ("overrides", "drop", "match"),
    [
        ({"ship": {"params": {"Tc": -1.0}}}, (), r"key 'ship\.params'.*Tc"),
        ({"sensors": {"heading_noise": 1.0}}, (), r"key 'sensors\.heading_noise'"),
        ({"time_limit": "long"}, (), r"key 'time_limit'"),
        (None, ("sensor",), "cannot drop 'sensor'"),
    ],
)
def test_bad_overrides_name_the_key(overrides: Any, drop: tuple, match: str) -> None:
    with pytest.raises(ScenarioError, match=match) as info:
        load_scenario("rudder_aging").with_overrides(overrides, name="mine", drop=drop)
    assert str(info.value).startswith("mine: ")
