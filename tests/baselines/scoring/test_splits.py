"""The scenario splits: which split a scenario falls in, and each split's titles."""

from __future__ import annotations

from pathlib import Path

import pytest

from shipgym_baselines.scoring.splits import (
    GENERALISATION_SPLITS,
    SPLIT_TITLES,
    SPLITS,
    TEST_SPLITS,
    UNSEEN_HULL,
    YOURS,
    figure_title,
    scenario_split,
    split_label,
    suite_families,
    table_title,
    unseen_hull_scenarios,
)


@pytest.mark.parametrize(
    ("scenario", "own", "split"),
    [
        ("heldout:3", (), "heldout"),
        ("inrange:0", (), "inrange"),
        ("mariner_rudder_aging", (), "catalogue"),
        ("my_harbour", ("my_harbour",), YOURS),
        ("scenarios/mine.yaml", (), YOURS),
        ("kvlcc2_rudder_aging", (), UNSEEN_HULL),
        ("kvlcc2_rudder_aging", ("kvlcc2_rudder_aging",), YOURS),  # a suite's own file
    ],
)
def test_a_scenario_falls_in_its_split(scenario: str, own: tuple[str, ...], split: str) -> None:
    assert scenario_split(scenario, own, unseen={"kvlcc2_rudder_aging"}) == split


def test_the_unseen_hull_scenarios_are_those_on_an_unseen_hull() -> None:
    """A run's scenarios on the KVLCC2 (shipgym.models.UNSEEN_HULLS), read from their
    recorded settings, whatever their name."""
    from shipgym.scenarios.loader import load_scenario

    settings = {
        name: load_scenario(name).config.model_dump(mode="json")
        for name in ("kvlcc2_nominal", "esso_osaka_nominal", "nominal")
    }
    settings["renamed"] = settings["kvlcc2_nominal"]
    assert unseen_hull_scenarios(settings) == {"kvlcc2_nominal", "renamed"}


def test_a_runs_families_are_its_files_family_keys(tmp_path: Path) -> None:
    """Each scenario's family is the ``family:`` of the file it was read from (the catalogue's
    of its name, or the suite's own file), never its name: a file named like a family but
    filed under another keeps its key, one without the key and a test scenario are
    ``other``, and so is a suite's file that is gone."""
    mine = tmp_path / "mine.yaml"
    base = "path: {waypoints: [[0, 0], [10, 0]]}\ntime_limit: 10.0\n"
    mine.write_text(f"name: my_rudder_aging\nfamily: current_shift\n{base}")
    bare = tmp_path / "bare.yaml"
    bare.write_text(f"name: rudder_aging_mine\n{base}")
    names = "mariner_rudder_aging osaka_curved heldout:3 my_rudder_aging gone rudder_aging_mine"
    suite = {
        "scenarios": dict.fromkeys(names.split()),
        "scenario_files": {
            "my_rudder_aging": str(mine),
            "rudder_aging_mine": str(bare),
            "gone": str(tmp_path / "gone.yaml"),
        },
    }
    assert suite_families(suite) == {
        "mariner_rudder_aging": "rudder_aging",
        "osaka_curved": "other",
        "heldout:3": "other",
        "my_rudder_aging": "current_shift",
        "gone": "other",
        "rudder_aging_mine": "other",
    }


def test_the_test_splits_are_the_named_test_scenarios_in_order() -> None:
    assert TEST_SPLITS == ("heldout", "inrange")
    assert GENERALISATION_SPLITS == ("catalogue", "heldout", "inrange", UNSEEN_HULL)


def test_each_split_has_its_titles_in_one_entry() -> None:
    """The tables, the figures and the sentences read one entry per split."""
    assert SPLIT_TITLES == {name: split.table for name, split in SPLITS.items()}
    assert table_title("heldout") == "Held-out scenarios"
    assert figure_title("inrange") == "in-range scenarios"
    assert split_label("heldout") == "held-out"
    assert figure_title(YOURS) == "your scenarios"


def test_an_unknown_split_is_titled_by_its_name() -> None:
    assert table_title("some_split") == figure_title("some_split") == "some_split"
    assert split_label("some_split") == "some_split"
