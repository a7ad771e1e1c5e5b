"""The cost-ratio ranking on synthetic data with known answers (the bootstrap: test_intervals.py,
the frozen optimum and the headroom: test_headroom.py)."""

from __future__ import annotations

import json
import math
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

from shipgym_baselines.scoring.ranking import (
    AGGREGATE_FIELDS,
    aggregate_ranking,
    performance_profiles,
    resolution,
    scenario_scores,
)
from shipgym_baselines.scoring.scores import scored_episodes

ORACLE_COST = 100.0
KINDS = {"oracle": "reference", "zero_rudder": "reference", "agent": "learned"}


def _episodes(
    ratios: dict[str, list[float]],
    scenarios=("a", "b"),
    training_seeds=None,
    fail: dict[str, set[int]] | None = None,
) -> list[dict]:
    """Episodes whose cost is ``ratio × the oracle's`` (the oracle's cost: 100 + seed, × the
    scenario's number); ``fail``: controller → seeds whose episodes leave the corridor."""
    eps = []
    for s_i, scenario in enumerate(scenarios):
        for controller, values in {"oracle": None, **ratios}.items():
            values = values or [1.0] * len(next(iter(ratios.values())))
            runs = (
                training_seeds if KINDS.get(controller) == "learned" and training_seeds else [None]
            )
            for seed, ratio in enumerate(values):
                for t in runs:
                    oracle = (ORACLE_COST + seed) * (1 + s_i)
                    failed = seed in (fail or {}).get(controller, set())
                    eps.append(
                        {
                            "scenario": scenario,
                            "controller": controller,
                            "kind": KINDS.get(controller, "classical"),
                            "seed": 10_000 + seed,
                            "training_seed": t,
                            "cost": ratio * oracle,
                            "termination_reason": "corridor" if failed else "goal",
                        }
                    )
    return eps


def test_the_cost_ratio_divides_by_the_oracle_on_the_same_scenario_and_trial() -> None:
    eps = _episodes({"pid_los": [1.5, 2.0]}, fail={"pid_los": {1}})
    scored = {(e["controller"], e["scenario"], e["seed"]): e for e in scored_episodes(eps)}
    assert scored[("oracle", "b", 10_001)]["cost_ratio"] == 1.0  # exactly, by definition
    assert scored[("pid_los", "a", 10_000)]["cost_ratio"] == pytest.approx(1.5)
    assert scored[("pid_los", "b", 10_001)]["cost_ratio"] == pytest.approx(2.0)
    assert scored[("pid_los", "b", 10_001)]["failure"] == 1.0
    assert scored[("pid_los", "b", 10_000)]["failure"] == 0.0
    without = [e for e in eps if not (e["controller"] == "oracle" and e["seed"] == 10_000)]
    lonely = [e for e in scored_episodes(without) if e["seed"] == 10_000]
    assert {e["cost_ratio"] for e in lonely} == {None}  # no oracle on that trial: no ratio
    assert aggregate_ranking([e for e in eps if e["controller"] != "oracle"], {"a": "x"}) == []


def test_aggregate_ranking_known_answers() -> None:
    """Constant ratios give exact IQM, geometric mean and point intervals; lower cost is the
    improvement; references are not ranked; ranked by IQM ascending; exactly the fields."""
    eps = _episodes(
        {
            "zero_rudder": [8.0] * 5,
            "pid_los": [1.5] * 5,
            "double": [2.0] * 5,
            "agent": [1.25] * 5,  # better than pid_los everywhere
        },
        training_seeds=[0, 1, 2],
        fail={"double": {0}},  # one trial in five leaves the corridor
    )
    splits = {"a": "catalogue", "b": "heldout"}
    rows = aggregate_ranking(eps, splits, KINDS, reps=500)
    assert all(tuple(r) == AGGREGATE_FIELDS for r in rows)
    by = {(r["controller"], r["split"]): r for r in rows}
    assert {c for c, _ in by} == {"pid_los", "double", "agent"}  # no reference ranked
    double = by[("double", "catalogue")]
    assert double["cost_ratio_iqm"] == pytest.approx(2.0)
    assert double["cost_ratio_gmean"] == pytest.approx(2.0)
    assert double["cost_ratio_iqm_ci95"] == pytest.approx([2.0, 2.0])
    assert double["prob_improvement_over_pid_los"] == 0.0  # always costlier than pid_los
    assert double["failure_rate"] == pytest.approx(0.2)
    low, high = double["failure_rate_ci95"]
    assert 0.0 <= low < 0.2 < high <= 1.0
    assert by[("pid_los", "heldout")]["prob_improvement_over_pid_los"] is None  # not itself
    assert by[("pid_los", "heldout")]["prob_improvement_over_pid_los_ci95"] is None
    agent = by[("agent", "catalogue")]
    assert agent["kind"] == "learned" and agent["training_seeds"] == 3 and agent["runs"] == 15
    assert agent["cost_ratio_iqm"] == pytest.approx(1.25) and agent["scenarios"] == ["a"]
    assert agent["prob_improvement_over_pid_los"] == 1.0
    assert agent["failure_rate"] == 0.0 and agent["failure_rate_ci95"] == [0.0, 0.0]
    catalogue = [r["controller"] for r in rows if r["split"] == "catalogue"]
    assert catalogue == ["agent", "pid_los", "double"]  # lowest cost ratio first


def test_the_aggregate_is_rliables_stratified_bootstrap_with_its_seed() -> None:
    """On random ratios the row's numbers are rliable's own: IQM and its interval from
    ``get_interval_estimates`` (global generator seeded with 0), the geometric mean is
    scipy's, the probability of improvement rliable's on the negated ratios."""
    from rliable import library as rly
    from rliable import metrics as rmetrics
    from scipy.stats import gmean

    rng = np.random.default_rng(5)
    ratios = {"pid_los": list(rng.lognormal(0.4, 0.3, 7)), "x": list(rng.lognormal(0.2, 0.5, 7))}
    eps = _episodes(ratios, scenarios=("a", "b", "c"))
    (row,) = [
        r
        for r in aggregate_ranking(eps, {"a": "s", "b": "s", "c": "s"}, reps=300)
        if r["controller"] == "x"
    ]
    scored = scored_episodes(eps)
    x = np.array(
        [
            [e["cost_ratio"] for e in scored if e["controller"] == "x" and e["scenario"] == s]
            for s in "abc"
        ]
    ).T
    y = np.array(
        [
            [e["cost_ratio"] for e in scored if e["controller"] == "pid_los" and e["scenario"] == s]
            for s in "abc"
        ]
    ).T
    np.random.seed(0)  # noqa: NPY002 (what rliable draws from)
    point, interval = rly.get_interval_estimates(
        {"x": x}, lambda m: np.array([rmetrics.aggregate_iqm(m), gmean(m, axis=None)]), reps=300
    )
    assert row["cost_ratio_iqm"] == pytest.approx(point["x"][0], rel=1e-12)
    assert row["cost_ratio_gmean"] == pytest.approx(point["x"][1], rel=1e-12)
    assert row["cost_ratio_iqm_ci95"] == pytest.approx(list(interval["x"][:, 0]), rel=1e-12)
    assert row["cost_ratio_gmean_ci95"] == pytest.approx(list(interval["x"][:, 1]), rel=1e-12)
    np.random.seed(0)  # noqa: NPY002
    p_point, p_interval = rly.get_interval_estimates(
        {"x": [-x, -y]}, rmetrics.probability_of_improvement, reps=300
    )
    assert row["prob_improvement_over_pid_los"] == pytest.approx(float(p_point["x"]), rel=1e-12)
    assert row["prob_improvement_over_pid_los_ci95"] == pytest.approx(
        list(np.ravel(p_interval["x"])), rel=1e-12
    )


def _ranking_json(eps: list[dict]) -> str:
    return json.dumps(aggregate_ranking(eps, {"a": "catalogue", "b": "catalogue"}, reps=200))


def test_the_same_episodes_give_the_same_ranking_in_any_process_and_state() -> None:
    """rliable draws from numpy's global generator: the ranking seeds it and restores it, so
    neither what ran before nor the process changes a bit of it."""
    rng = np.random.default_rng(7)
    eps = _episodes(
        {"pid_los": list(rng.lognormal(0.4, 0.3, 6)), "x": list(rng.lognormal(0.2, 0.5, 6))}
    )
    first = _ranking_json(eps)
    np.random.seed(12345)  # noqa: NPY002 (a caller's own use of the global generator)
    state = np.random.get_state()  # noqa: NPY002
    assert _ranking_json(eps) == first
    after = np.random.get_state()  # noqa: NPY002
    assert all(np.array_equal(a, b) for a, b in zip(state, after, strict=True))  # restored
    with ProcessPoolExecutor(max_workers=2) as pool:
        assert list(pool.map(_ranking_json, [eps, eps])) == [first, first]


def test_a_controller_without_some_scenarios_is_ranked_in_the_partial_table() -> None:
    eps = _episodes({"pid_los": [1.5] * 3, "nmpc": [1.1] * 3}, scenarios=("a", "b", "c"))
    eps = [e for e in eps if not (e["controller"] == "nmpc" and e["scenario"] == "c")]
    rows = aggregate_ranking(eps, {"a": "catalogue", "b": "catalogue", "c": "catalogue"}, reps=100)
    assert [(r["split"], r["controller"], r["scenarios"]) for r in rows] == [
        ("catalogue", "pid_los", ["a", "b", "c"]),
        ("catalogue:partial", "nmpc", ["a", "b"]),
    ]
    assert rows[1]["prob_improvement_over_pid_los"] == 1.0  # against pid_los on its scenarios


@pytest.mark.parametrize("reason", ["controller_error", "controller_timeout"])
def test_an_episode_its_controller_ended_counts_in_the_failure_rate(reason: str) -> None:
    eps = _episodes({"pid_los": [1.5] * 4, "broken": [9.0] * 4})
    for e in eps:
        if e["controller"] == "broken" and e["seed"] != 10_000:
            e["termination_reason"] = reason
    scored = scored_episodes(eps)
    assert {e["failure"] for e in scored if e["controller"] == "broken" and e["seed"] > 10_000} == {
        1.0
    }
    rows = aggregate_ranking(eps, {"a": "catalogue", "b": "catalogue"}, reps=100)
    broken = next(r for r in rows if r["controller"] == "broken")
    assert broken["split"] == "catalogue" and broken["failure_rate"] == pytest.approx(0.75)
    assert broken["cost_ratio_iqm"] == pytest.approx(9.0)  # ranked, last


@pytest.mark.parametrize("cost", [math.inf, math.nan, None])
def test_an_episode_without_a_finite_cost_moves_its_scenario_to_the_partial_table(
    cost: float | None,
) -> None:
    """No ratio for that episode: the row keeps every run of its other scenarios (no
    unequal runs), and the scenario of the episode leaves its main table."""
    eps = _episodes({"pid_los": [1.5] * 3, "broken": [2.0] * 3}, scenarios=("a", "b", "c"))
    for e in eps:
        if (e["controller"], e["scenario"], e["seed"]) == ("broken", "c", 10_001):
            e["cost"] = cost
    rows = aggregate_ranking(eps, {"a": "catalogue", "b": "catalogue", "c": "catalogue"}, reps=100)
    assert [(r["split"], r["controller"], r["scenarios"], r["runs"]) for r in rows] == [
        ("catalogue", "pid_los", ["a", "b", "c"], 3),
        ("catalogue:partial", "broken", ["a", "b"], 3),
    ]
    assert performance_profiles(eps, {"a": "catalogue", "c": "catalogue"}, "catalogue", [1.0])


def test_without_pid_los_no_row_claims_a_comparison_with_it() -> None:
    """pid_los not ranked: every row's probability of improvement over it is None, and
    leaderboard.md's and the page's tables drop the column."""
    from shipgym_baselines.page.markdown import ranking_tables
    from shipgym_baselines.page.sections import ranking_tables as page_tables

    eps = _episodes({"nmpc": [1.1] * 3, "lqr": [1.3] * 3})
    rows = aggregate_ranking(eps, {"a": "catalogue", "b": "catalogue"}, reps=100)
    assert [r["controller"] for r in rows] == ["nmpc", "lqr"]
    assert {(r["prob_improvement_over_pid_los"], r["prob_improvement_over_pid_los_ci95"])
            for r in rows} == {(None, None)}  # fmt: skip
    assert "pid_los" not in "\n".join(ranking_tables(rows))
    assert "pid_los" not in page_tables(rows)
    with_pid = aggregate_ranking(
        _episodes({"nmpc": [1.1] * 3, "pid_los": [1.5] * 3}), {"a": "catalogue"}, reps=100
    )
    html = page_tables(with_pid)
    assert "P(ratio &lt; pid_los&#x27;s)" in html
    (pid_row,) = [r for r in html.split("<tr>") if "</span>pid_los</td>" in r]
    assert pid_row.split("</td>")[8] == "<td>–"  # no P(improvement) over itself
    (md_row,) = [line for line in ranking_tables(with_pid) if "| pid_los |" in line]
    assert md_row.split(" | ")[7] == "–"


def test_resolution_compares_the_median_interval_width_with_the_iqm_range() -> None:
    def row(name: str, iqm: float, half: float, split: str = "catalogue") -> dict:
        return {
            "controller": name,
            "split": split,
            "cost_ratio_iqm": iqm,
            "cost_ratio_iqm_ci95": [iqm - half, iqm + half],
        }

    board = [
        row("a", 1.0, 0.05),
        row("b", 2.0, 0.1),
        row("c", 3.0, 0.5),
        row("d", 9.0, 5.0, "catalogue:partial"),
    ]
    (res,) = resolution(board)
    assert res["split"] == "catalogue" and res["controllers"] == 3
    assert res["median_ci_width"] == pytest.approx(0.2) and res["iqm_range"] == pytest.approx(2.0)
    assert res["resolved"] is True  # 0.2 < 2.0 / 5


def test_scenario_scores_give_the_oracle_cost_and_each_geometric_mean_ratio() -> None:
    eps = _episodes({"pid_los": [2.0, 8.0], "zero_rudder": [4.0, 4.0]})
    by = {s["scenario"]: s for s in scenario_scores(eps, {"a": "catalogue"}, KINDS)}
    assert by["a"]["oracle_cost"] == pytest.approx(100.5) and by["b"]["split"] == "catalogue"
    assert by["b"]["oracle_cost"] == pytest.approx(201.0) and by["a"]["oracle_episodes"] == 2
    cells = {c["controller"]: c for c in by["a"]["controllers"]}
    assert set(cells) == {"pid_los", "zero_rudder"}  # the oracle's is the cost above
    assert cells["pid_los"]["cost_ratio_gmean"] == pytest.approx(4.0)  # √(2·8)
    low, high = cells["pid_los"]["cost_ratio_gmean_ci95"]
    assert 2.0 <= low < 4.0 < high <= 8.0
    assert cells["zero_rudder"]["cost_ratio_gmean_ci95"] == pytest.approx([4.0, 4.0])
    assert cells["zero_rudder"]["kind"] == "reference" and cells["pid_los"]["episodes"] == 2


def test_performance_profile_is_the_fraction_of_runs_with_a_ratio_above_tau() -> None:
    eps = _episodes({"pid_los": [1.5] * 4, "double": [2.0] * 4})
    profiles, intervals = performance_profiles(
        eps, {"a": "catalogue"}, "catalogue", np.array([1.25, 1.75]), reps=100
    )
    np.testing.assert_allclose(profiles["double"], [1.0, 1.0])
    np.testing.assert_allclose(profiles["pid_los"], [1.0, 0.0])
    np.testing.assert_allclose(profiles["oracle"], [0.0, 0.0])
    assert intervals["double"].shape == (2, 2)
