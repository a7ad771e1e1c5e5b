"""Tests for the typed suite model (configs/suites) and its loader."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
import yaml

from shipgym.config import ConfigError, list_names
from shipgym.limits import MAX_SUITE_SCENARIOS
from shipgym_baselines.suite import SuiteConfig, list_suites, load_suite


def write(tmp_path: Path, text: str, name: str = "suite.yaml") -> Path:
    file = tmp_path / name
    file.parent.mkdir(parents=True, exist_ok=True)
    file.write_text(text)
    return file


def assert_suite_error(tmp_path: Path, text: str, match: str) -> None:
    """Loading a suite file of ``text`` is a ConfigError matching ``match``."""
    file = write(tmp_path, text)
    with pytest.raises(ConfigError, match=match):
        load_suite(file)


def test_packaged_suites_load() -> None:
    assert list_suites() == list_names("suites") == ["default", "paper_settings", "quick", "smoke"]
    smoke = load_suite("smoke")
    assert smoke == SuiteConfig(
        name="smoke",
        scenarios=["rudder_aging", "mariner_track"],
        heldout_scenarios=1,
        controllers=[
            "nmpc_lambda_lssvm",
            "pid_los",
            "ppo",
            "oracle",
            "oracle_frozen",
            "zero_rudder",
        ],
        seeds=2,
        randomize=smoke.randomize,
    )
    assert smoke.randomize is not None and smoke.randomize.heading_error_deg is not None
    assert smoke.all_scenarios() == ["rudder_aging", "mariner_track", "heldout:0"]


def test_default_suite_holds_the_matrix_and_two_held_out_scenarios_a_ship() -> None:
    """The scenario matrix but blanke_current_shift (its 85 L route was a tenth of the run;
    blanke_current_shift_curved keeps the family), Liu et al.'s four nomoto2 scenarios and
    their smooth variants, the five KVLCC2 scenarios of the unseen-hull split, and the
    held-out scenarios heldout:0-7 (two on each ship)."""
    from shipgym.scenarios.loader import load_scenario
    from shipgym_baselines.studies.change_effect import matrix_scenarios

    default = load_suite("default")
    matrix = matrix_scenarios() + [f"{s}_nominal" for s in ("esso_osaka", "mariner", "blanke")]
    assert set(matrix) - set(default.scenarios) == {"blanke_current_shift"}
    assert "blanke_current_shift_curved" in default.scenarios
    assert not [s for s in default.scenarios if s.endswith("_long")]
    assert len(default.scenarios) == 32 and default.heldout_scenarios == 8
    unseen = [s for s in default.scenarios if s.startswith("kvlcc2_")]
    assert unseen == [
        "kvlcc2_nominal",
        "kvlcc2_rudder_aging",
        "kvlcc2_current_shift",
        "kvlcc2_maneuverability_change",
        "kvlcc2_rudder_aging_curved",
    ]
    ships = [load_scenario(f"heldout:{i}").model.name for i in range(8)]
    assert sorted(ships) == sorted(["nomoto2", "esso_osaka", "mariner", "blanke"] * 2)
    # 2 seeds so that the twins and the two NMPC rows on an estimated plant fit
    assert default.seeds == 2 and default.twins


def test_the_in_range_split_follows_the_held_out_one() -> None:
    """The default suite ranks 4 in-range scenarios (inrange:0-3, one on each ship) after
    the 8 held-out ones, both on the suite's first two evaluation seeds; a learned agent's
    training seeds share the trials."""
    default = load_suite("default")
    assert default.inrange_scenarios == 4 and default.inrange_seeds == 2
    assert default.heldout_scenarios == 8 and default.heldout_seeds == 2
    assert default.learned_trials == "shared"
    assert default.all_scenarios()[32:] == [
        *(f"heldout:{i}" for i in range(8)),
        *(f"inrange:{i}" for i in range(4)),
    ]
    seeds = list(range(10_000, 10_005))
    fewer = default.scenario_seeds(seeds)
    assert fewer == {
        **{f"heldout:{i}": seeds[:2] for i in range(8)},
        **{f"inrange:{i}": seeds[:2] for i in range(4)},
    }
    assert default.scenario_seeds(seeds[:2]) == {}  # --seeds 2: every scenario on both
    every = {"inrange_seeds": None, "heldout_seeds": None}
    assert default.model_copy(update=every).scenario_seeds(seeds) == {}
    assert load_suite("smoke").learned_trials == "all"  # the default of a suite file


def test_quick_suite_is_one_scenario_per_ship_and_family() -> None:
    """quick: 3 seeds, the default suite's controllers (and Liu et al.'s three identifier
    rows the default leaves out) and trials, 12 scenarios = 4 ships × (rudder aging,
    current shift, manoeuvrability change)."""
    from shipgym.scenarios.loader import load_scenario

    quick, default = load_suite("quick"), load_suite("default")
    assert quick.seeds == 3 and quick.heldout_scenarios == 0
    liu = {"nmpc_wlssvm", "nmpc_wlssvm_svf", "nmpc_lambda_lssvm"}
    assert [c for c in quick.controllers if c not in liu] == default.controllers
    assert quick.randomize == default.randomize
    assert quick.learned_trials == default.learned_trials == "shared"
    families = ("rudder_aging", "current_shift", "maneuverability_change")
    cells = set()
    for name in quick.scenarios:
        ship = load_scenario(name).model.name
        (family,) = [f for f in families if f in name]
        cells.add((ship, family))
    assert len(cells) == len(quick.scenarios) == 12


def test_a_suite_by_path_equals_the_same_suite_by_name(tmp_path: Path) -> None:
    text = (Path(__file__).resolve().parents[2] / "configs/suites/smoke.yaml").read_text()
    assert load_suite(write(tmp_path, text)) == load_suite("smoke")


def test_relative_scenario_paths_are_read_against_the_suite_folder(
    tmp_path: Path, monkeypatch
) -> None:
    nominal = (Path(__file__).resolve().parents[2] / "configs/scenarios/nominal.yaml").read_text()
    text = nominal.replace("name: nominal", "name: mine")
    scenario = write(tmp_path, text, "suites/scenarios/mine.yaml")
    suite = write(
        tmp_path,
        "name: s\nscenarios: [nominal, scenarios/mine.yaml, heldout:2]\ncontrollers: [pid_los]\n",
        "suites/s.yaml",
    )
    monkeypatch.chdir(tmp_path)
    loaded = load_suite(str(suite))
    assert loaded.scenarios == ["nominal", str(scenario), "heldout:2"]


def test_unknown_key_is_named(tmp_path: Path) -> None:
    assert_suite_error(
        tmp_path,
        "name: s\nscenarios: [nominal]\ncontrollers: [pid_los]\nseed: 3\n",
        r"suite\.yaml: key 'seed': Extra inputs",
    )


@pytest.mark.parametrize("controllers", ["", "controllers: []\n"])
def test_a_suite_without_controllers_is_an_error(tmp_path: Path, controllers: str) -> None:
    assert_suite_error(
        tmp_path, f"name: s\nscenarios: [nominal]\n{controllers}", r"suite\.yaml: key 'controllers'"
    )


def test_a_suite_without_scenarios_is_an_error(tmp_path: Path) -> None:
    assert_suite_error(
        tmp_path, "name: s\ncontrollers: [pid_los]\n", "needs 'scenarios' or 'heldout_scenarios'"
    )
    only_heldout = write(tmp_path, "name: s\nheldout_scenarios: 2\ncontrollers: [pid_los]\n")
    assert load_suite(only_heldout).all_scenarios() == ["heldout:0", "heldout:1"]
    only_inrange = write(tmp_path, "name: s\ninrange_scenarios: 2\ncontrollers: [pid_los]\n")
    assert load_suite(only_inrange).all_scenarios() == ["inrange:0", "inrange:1"]


def test_bad_yaml_names_file_and_line(tmp_path: Path) -> None:
    file = write(tmp_path, "name: s\nscenarios: [nominal\ncontrollers: [pid_los]\n")
    with pytest.raises(ConfigError, match="malformed YAML") as info:
        load_suite(file)
    assert str(info.value).startswith(f"{file}, line 3,")


def test_unknown_scenario_names_suite_key_and_valid_names(tmp_path: Path) -> None:
    file = write(
        tmp_path,
        yaml.safe_dump(
            {"name": "s", "scenarios": ["nominal", "nomnal"], "controllers": ["pid_los"]}
        ),
    )
    with pytest.raises(ConfigError) as info:
        load_suite(file)
    msg = str(info.value)
    assert msg.startswith(f"{file}: key 'scenarios.1': unknown scenario 'nomnal'")
    assert "rudder_aging" in msg


def test_unknown_suite_lists_the_suites() -> None:
    listed = r"unknown suite 'nope'.*valid: default, paper_settings, quick, smoke"
    with pytest.raises(ConfigError, match=listed):
        load_suite("nope")


@pytest.mark.parametrize(
    ("extra", "key"),
    [
        ("seeds: 0\n", "seeds"),
        ("heldout_scenarios: -1\n", "heldout_scenarios"),
        ("inrange_scenarios: -1\n", "inrange_scenarios"),
        ("inrange_scenarios: 1001\n", "inrange_scenarios"),
        ("inrange_seeds: 0\n", "inrange_seeds"),
        ("heldout_seeds: 0\n", "heldout_seeds"),
        ("learned_trials: some\n", "learned_trials"),
    ],
)
def test_counts_are_validated(tmp_path: Path, extra: str, key: str) -> None:
    assert_suite_error(
        tmp_path, f"name: s\nscenarios: [nominal]\ncontrollers: [pid_los]\n{extra}", f"key '{key}'"
    )


def test_a_scenario_listed_twice_is_an_error(tmp_path: Path) -> None:
    assert_suite_error(
        tmp_path,
        "name: s\nscenarios: [nominal, nominal]\ncontrollers: [pid_los]\n",
        "more than once",
    )


def test_a_suite_of_ten_thousand_files_is_refused_within_a_second(tmp_path: Path) -> None:
    """10,000 scenario files (none of them exists): a run refuses them by their count
    before any is read (within a second of CPU), in one line naming the key and the limit;
    ``--validate`` too."""
    from shipgym_baselines.suite import check_suite_file

    entries = "".join(f"  - scenarios/s{i:05d}.yaml\n" for i in range(10_000))
    file = write(tmp_path, f"name: big\ncontrollers: [pid_los]\nscenarios:\n{entries}")
    start = time.process_time()  # CPU time: a loaded machine does not make it slower
    with pytest.raises(ConfigError) as refused:
        load_suite(file)
    assert time.process_time() - start < 1.0
    (problem,) = check_suite_file(file)
    assert str(refused.value) == (
        f"{file}: key 'scenarios': List should have at most {MAX_SUITE_SCENARIOS} items after "
        "validation, not 10000"
    )
    assert problem.key == "scenarios" and problem.line == 3


# --- check_suite_file (shipgym scenarios --validate) -----------------------------------------

NOMINAL = (Path(__file__).resolve().parents[2] / "configs/scenarios/nominal.yaml").read_text()


def test_a_suite_check_lists_schema_and_later_problems_together(tmp_path: Path) -> None:
    from shipgym_baselines.suite import check_suite_file

    scenario = write(tmp_path, NOMINAL.replace("name: nominal", "name: my_turn"), "mine.yaml")
    write(tmp_path, NOMINAL.replace("name: nominal", "name: my_turn"), "twin.yaml")
    file = write(
        tmp_path,
        "name: s\n"
        "scenarios: [nominal, mine.yaml, twin.yaml, heldout:99999]\n"
        "controllers:\n"
        "  - pid_los\n"
        "  - {controller: pid_los, name: pid_los}\n"
        "  - {controller: pid_los, name: stiff, settings: {no_such_setting: 1}}\n"
        "seeds: 0\n",
    )
    found = [(p.line, p.key, p.message) for p in check_suite_file(file)]
    assert [(line, key) for line, key, _ in found] == [
        (7, "seeds"),
        (2, "scenarios.2"),
        (2, "scenarios.3"),
        (5, "controllers.1"),
        (6, "controllers.2"),
    ]
    assert "greater than or equal to 1" in found[0][2]
    assert found[1][2].startswith(
        f"scenario files {scenario} and {tmp_path / 'twin.yaml'} are both named 'my_turn'"
    )
    assert "heldout: index 99999 out of range" in found[2][2]
    assert "table name 'pid_los' is also controllers.0's" in found[3][2]
    assert "no_such_setting" in found[4][2]


def test_a_good_suite_has_no_problems(tmp_path: Path) -> None:
    from shipgym_baselines.suite import check_suite_file, is_suite_file

    for name in list_suites():
        assert is_suite_file(name) and check_suite_file(name) == [], name
    write(tmp_path, NOMINAL.replace("name: nominal", "name: mine"), "scenarios/mine.yaml")
    file = write(tmp_path, "name: s\nscenarios: [scenarios/mine.yaml]\ncontrollers: [pid_los]\n")
    assert is_suite_file(str(file)) and check_suite_file(str(file)) == []
    assert not is_suite_file(str(tmp_path / "scenarios/mine.yaml"))
    assert not is_suite_file("nominal")
