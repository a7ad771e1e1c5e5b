"""The twins a leaderboard run plays: one per changing scenario, shared where the same task,
dealt to the training seeds as their scenarios are, recorded in ``run.json``."""

from __future__ import annotations

from shipgym_baselines.evaluation import EVAL_SEED_OFFSET
from shipgym_baselines.leaderboard.jobs import plan_run, suite_record, suite_scenarios
from shipgym_baselines.leaderboard.twins import plan_twins
from shipgym_baselines.records.trials import deal_names, dealt_owners, twins_of
from shipgym_baselines.suite import load_suite

SEEDS = [EVAL_SEED_OFFSET + i for i in range(8)]


def _default_twins() -> tuple[dict, dict]:
    spec = load_suite("default")
    scenarios = suite_scenarios(spec.all_scenarios())
    fewer = spec.scenario_seeds(SEEDS)
    return plan_twins(scenarios, {s: fewer.get(s, SEEDS) for s in scenarios})


def test_the_default_suites_twins_are_shared_where_the_same_task() -> None:
    twins, new = _default_twins()
    # a parameter change on the nominal route: the nominal scenario is the twin
    assert twins["esso_osaka_rudder_aging"] == "esso_osaka_nominal"
    assert twins["kvlcc2_maneuverability_change"] == "kvlcc2_nominal"
    assert twins["rudder_aging"] == twins["current_shift"] == "nominal"
    # a current shift's time limit is longer than the nominal's: its twin is its own
    assert twins["esso_osaka_current_shift"] == "twin:esso_osaka_current_shift"
    # every held-out and in-range scenario has its own route
    assert all(twins[f"heldout:{i}"] == f"twin:heldout:{i}" for i in range(8))
    assert all(twins[f"inrange:{i}"] == f"twin:inrange:{i}" for i in range(4))
    assert "nominal" not in twins and "esso_osaka_nominal" not in twins  # no change
    assert set(new) == {t for t in twins.values() if t.startswith("twin:")}


def test_a_twin_is_shared_only_on_the_same_seeds() -> None:
    spec = load_suite("default")
    scenarios = suite_scenarios(["rudder_aging_long", "current_shift_long"])
    seeds = {"rudder_aging_long": SEEDS, "current_shift_long": SEEDS[:4]}
    twins, new = plan_twins(scenarios, seeds)
    assert twins == {
        "rudder_aging_long": "twin:rudder_aging_long",
        "current_shift_long": "twin:current_shift_long",
    }
    assert len(new) == 2 and spec.twins
    # on the same seeds the long-leg variants, whose ship starts the same, share one twin
    same = {name: SEEDS for name in scenarios}
    twins, new = plan_twins(scenarios, same)
    assert twins["rudder_aging_long"] == twins["current_shift_long"] == "twin:rudder_aging_long"
    assert len(new) == 1


def test_a_trial_and_its_twin_are_dealt_to_the_same_training_seed() -> None:
    spec = load_suite("default")
    scenarios = suite_scenarios(spec.all_scenarios())
    record = suite_record(spec, list(spec.controllers), scenarios, SEEDS, _seeds_of(spec))
    deal = deal_names(record)
    for scenario, twin in twins_of(record).items():
        assert deal[scenario] == deal[twin] == twin
        seeds = record.get("scenario_seeds", {}).get(scenario, SEEDS)
        assert dealt_owners(deal[scenario], seeds, [0, 1, 2]) == dealt_owners(
            deal[twin], seeds, [0, 1, 2]
        )


def _seeds_of(spec) -> dict:
    from shipgym_baselines.registry import controller_label, training_seeds

    return {controller_label(c): training_seeds(c) for c in spec.controllers}


def test_the_twins_are_played_by_the_competitors_and_the_oracle_only() -> None:
    spec = load_suite("quick").model_copy(update={"learned_trials": "shared"})
    scenarios = suite_scenarios(["esso_osaka_current_shift", "esso_osaka_rudder_aging"])
    names = ["pid_los", "ppo", "oracle", "oracle_frozen", "zero_rudder"]
    seeds_of = _seeds_of(spec) | {"pid_los": [None], "zero_rudder": [None], "oracle": [None]}
    seeds_of |= {"oracle_frozen": [None]}
    record = suite_record(spec, names, scenarios, SEEDS[:2], seeds_of)
    assert record["twin_players"] == ["pid_los", "ppo", "oracle"]
    assert record["twins"] == {
        "esso_osaka_current_shift": "twin:esso_osaka_current_shift",
        "esso_osaka_rudder_aging": "twin:esso_osaka_rudder_aging",  # no nominal in this run
    }
    jobs = plan_run(names, record, seeds_of)
    on_twins = {(j.scenario, j.label.controller) for j in jobs if j.scenario.startswith("twin:")}
    assert {c for _, c in on_twins} == {"pid_los", "ppo", "oracle"}
    by_key = {(j.scenario, j.label.controller): j for j in jobs}
    for scenario, twin in record["twins"].items():
        assert by_key[(scenario, "ppo")].dealt == by_key[(twin, "ppo")].dealt


def test_a_suite_can_run_without_twins() -> None:
    spec = load_suite("quick").model_copy(update={"twins": False})
    scenarios = suite_scenarios(["esso_osaka_current_shift"])
    record = suite_record(spec, ["pid_los"], scenarios, SEEDS[:2], {"pid_los": [None]})
    assert "twins" not in record and "twin_scenarios" not in record
    assert [j.scenario for j in plan_run(["pid_los"], record, {"pid_los": [None]})] == [
        "esso_osaka_current_shift"
    ]


def test_a_report_merges_the_runs_twins_and_refuses_other_ones() -> None:
    import pytest

    from shipgym_baselines.errors import RunError
    from shipgym_baselines.leaderboard.report import merge_twins

    settings = {"name": "twin:a", "time_limit": 90.0}
    run = {"twins": {"a": "twin:a"}, "twin_scenarios": {"twin:a": settings}}
    suite: dict = {}
    first: dict = {}
    merge_twins(suite, run | {"twin_players": ["x", "oracle"]}, "one", first)
    merge_twins(suite, run | {"twin_players": ["y", "oracle"]}, "two", first)
    assert suite == run | {"twin_players": ["x", "oracle", "y"]}
    with pytest.raises(RunError, match="scenario 'a' has the twin 'nominal' in three"):
        merge_twins(suite, {"twins": {"a": "nominal"}}, "three", first)
    other = {"twin_scenarios": {"twin:a": settings | {"time_limit": 80.0}}}
    with pytest.raises(RunError, match="twin 'twin:a' has other settings in four than in one"):
        merge_twins(suite, other, "four", first)
