"""Interval estimates and the cost-ratio ranking on synthetic data with known answers."""

from __future__ import annotations

import json
import math
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

from shipgym_baselines.leaderboard.ranking import (
    AGGREGATE_FIELDS,
    aggregate_ranking,
    performance_profiles,
    resolution,
    row_intervals,
    scenario_scores,
    scored_episodes,
    stratified_bootstrap_ci,
)


def test_a_constant_sample_has_a_point_interval_and_non_finite_values_none() -> None:
    assert stratified_bootstrap_ci([[2.5] * 10]) == [2.5, 2.5]
    assert stratified_bootstrap_ci([[1.0, math.inf]]) is None
    assert stratified_bootstrap_ci([]) is None


def test_percentile_interval_covers_the_true_mean_95_percent_of_the_time() -> None:
    rng = np.random.default_rng(1)
    hits = 0
    trials = 300
    for i in range(trials):
        sample = rng.normal(3.0, 2.0, 40)
        low, high = stratified_bootstrap_ci([sample], reps=1000, seed=i)
        hits += low <= 3.0 <= high
    assert 0.90 <= hits / trials <= 0.99  # binomial spread of 300 trials at p = 0.95: ±0.025


def test_stratified_interval_width_matches_the_stratified_standard_error() -> None:
    """Two training seeds with different means: the stratified bootstrap's half-width is
    1.96·sqrt(Σ n_k s_k²)/N (s_k the plug-in std within stratum k), not the pooled one."""
    rng = np.random.default_rng(2)
    strata = [rng.normal(0.0, 1.0, 200), rng.normal(10.0, 3.0, 200)]
    low, high = stratified_bootstrap_ci(strata, reps=20000)
    n = sum(len(s) for s in strata)
    se = math.sqrt(sum(len(s) * np.var(s) for s in strata)) / n
    assert (high - low) / 2 == pytest.approx(1.96 * se, rel=0.05)
    pooled = np.concatenate(strata)
    assert (high - low) / 2 < 0.5 * 1.96 * np.std(pooled) / math.sqrt(n)  # strata matter
    assert low < np.mean(pooled) < high


def test_row_intervals_stratify_by_training_seed_and_name_the_metric() -> None:
    episodes = [
        {"training_seed": t, "seed": s, "ace": 1.0 + t, "t_c": math.inf}
        for t in (0, 1, 2)
        for s in range(10)
    ]
    out = row_intervals(episodes, ["ace", "t_c"])
    # within each training seed the values are constant: every resample keeps the mean
    assert out["ace_ci95"] == pytest.approx([2.0, 2.0])
    assert out["t_c_ci95"] is None


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
    from shipgym_baselines.leaderboard import ranking_tables
    from shipgym_baselines.leaderboard.page import ranking_tables as page_tables

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


def test_the_fast_metrics_give_rliables_bits() -> None:
    """interquartile_mean and probability_of_improvement (vectorised) equal rliable's
    aggregate_iqm and probability_of_improvement exactly, ties and equal columns included."""
    from rliable import metrics as rmetrics

    from shipgym_baselines.leaderboard.ranking import interquartile_mean, probability_of_improvement

    rng = np.random.default_rng(3)
    for trial in range(200):
        m, n, tasks = rng.integers(1, 12, 3)
        digits = int(rng.integers(0, 3))  # coarse rounding makes ties
        x = np.round(rng.normal(1.0, 0.3, (m, tasks)), digits)
        y = x.copy() if trial % 7 == 0 else np.round(rng.normal(1.0, 0.3, (n, tasks)), digits)
        assert interquartile_mean(x) == rmetrics.aggregate_iqm(x)
        assert probability_of_improvement(x, y) == rmetrics.probability_of_improvement(x, y)


# ------------------------------------------------------------ the frozen optimum and the gap
#: one scenario, five trials: (C_oracle, C_frozen, C of "x"), by hand
#:   trial 0: headroom 400/100 = 4,   gain 400/200 = 2,       gap log 2 / log 4 = 0.5, beats
#:   trial 1: headroom 2,             gain 200/100 = 2,       gap log 2 / log 2 = 1,   beats
#:   trial 2: headroom 1.1 (< 1.2: no gap), gain 110/121 = 10/11,                      loses
#:   trial 3: headroom 1.5,           gain 150/150 = 1,       gap log 1 / log 1.5 = 0, tie: ½
#:   trial 4: headroom 10,            gain 1000/10000 = 0.1,  gap log 0.1 / log 10 = −1, loses
#: gain: geometric mean (2 · 2 · 10/11 · 1 · 0.1)^(1/5) = (4/11)^(1/5)
#: P(C < C_frozen): (1 + 1 + 0 + ½ + 0) / 5 = 0.5
#: gap closed: 4 trials qualify, sorted −1, 0, 0.5, 1; the IQM drops int(0.25·4) = 1 at each
#: end: (0 + 0.5) / 2 = 0.25
HAND = [(100.0, 400.0, 200.0), (100.0, 200.0, 100.0), (100.0, 110.0, 121.0)]
HAND += [(100.0, 150.0, 150.0), (100.0, 1000.0, 10000.0)]


def _hand_episodes(
    trials: list[tuple[float, float, float]] = HAND, frozen: bool = True, learned: bool = False
) -> list[dict]:
    eps = []
    for k, (c_oracle, c_frozen, c_x) in enumerate(trials):
        costs = [("oracle", "reference", c_oracle, None), ("x", "classical", c_x, None)]
        costs += [("oracle_frozen", "reference", c_frozen, None)] if frozen else []
        # a learned agent: three training seeds, each costing x's on the trial
        costs += [("agent", "learned", c_x, t) for t in (0, 1, 2)] if learned else []
        for controller, kind, cost, training_seed in costs:
            eps.append(
                {
                    "scenario": "a",
                    "controller": controller,
                    "kind": kind,
                    "seed": 10_000 + k,
                    "training_seed": training_seed,
                    "cost": cost,
                    "termination_reason": "goal",
                }
            )
    return eps


def test_the_gap_fields_against_a_hand_computed_case() -> None:
    rows = aggregate_ranking(_hand_episodes(learned=True), {"a": "catalogue"}, reps=300)
    assert all(tuple(r) == AGGREGATE_FIELDS for r in rows)
    assert [r["controller"] for r in rows] == ["agent", "x"]  # oracle_frozen is not ranked
    by = {r["controller"]: r for r in rows}
    for name in ("x", "agent"):
        row = by[name]
        assert row["adaptation_gain_gmean"] == pytest.approx((4 / 11) ** 0.2, rel=1e-12)
        assert row["prob_beats_frozen"] == 0.5
        assert row["gap_closed_iqm"] == pytest.approx(0.25, abs=1e-12)
        assert row["gap_trials"] == 4  # trials (scenario, seed), not runs
        low, high = row["gap_closed_iqm_ci95"]
        assert -1.0 - 1e-12 <= low <= 0.25 <= high <= 1.0 + 1e-12
        low, high = row["adaptation_gain_gmean_ci95"]
        assert 0.1 <= low < (4 / 11) ** 0.2 < high <= 2.0
        low, high = row["prob_beats_frozen_ci95"]
        assert 0.0 <= low < 0.5 < high <= 1.0
    assert by["x"]["runs"] == 5 and by["agent"]["runs"] == 15


def test_the_gap_matrices_per_trial() -> None:
    from shipgym_baselines.leaderboard.ranking import gap_matrices, trial_headroom

    scored = scored_episodes(_hand_episodes())
    assert trial_headroom(scored) == pytest.approx(
        {("a", 10_000 + k): h for k, h in enumerate([4.0, 2.0, 1.1, 1.5, 10.0])}
    )
    m = gap_matrices(scored, "x", ["a"])
    assert m is not None
    np.testing.assert_allclose(m["gain"][:, 0], [2.0, 2.0, 10 / 11, 1.0, 0.1])
    np.testing.assert_array_equal(m["beats"][:, 0], [1.0, 1.0, 0.0, 0.5, 0.0])
    np.testing.assert_allclose(m["gap"][:, 0], [0.5, 1.0, np.nan, 0.0, -1.0], atol=1e-12)
    # the frozen optimum's own costs: gain 1 everywhere, a tie on every trial
    frozen = gap_matrices(scored, "oracle_frozen", ["a"])
    assert frozen is not None and set(frozen["beats"].ravel()) == {0.5}


def test_the_gap_interval_is_rliables_bootstrap_with_nan_where_a_trial_does_not_qualify() -> None:
    """The gap closed's interval: rliable's stratified bootstrap of the run matrix (NaN on
    the trials with headroom < 1.2) with the IQM over the finite entries, the global
    generator seeded with 0, as the other fields."""
    from rliable import library as rly
    from rliable import metrics as rmetrics

    from shipgym_baselines.leaderboard.ranking import gap_matrices

    rng = np.random.default_rng(11)
    trials = [(100.0, 100.0 * h, 100.0 * h * g) for h, g in rng.lognormal(0.3, 0.6, (12, 2))]
    eps = _hand_episodes(trials)
    (row,) = aggregate_ranking(eps, {"a": "catalogue"}, reps=300)
    m = gap_matrices(scored_episodes(eps), "x", ["a"])
    assert m is not None and 0 < np.isfinite(m["gap"]).sum() < 12  # some do not qualify

    def finite_iqm(x: np.ndarray) -> np.ndarray:
        return np.array([rmetrics.aggregate_iqm(x[np.isfinite(x)])])

    np.random.seed(0)  # noqa: NPY002 (what rliable draws from)
    point, interval = rly.get_interval_estimates({"x": m["gap"]}, finite_iqm, reps=300)
    assert row["gap_closed_iqm"] == pytest.approx(point["x"][0], rel=1e-12)
    assert row["gap_closed_iqm_ci95"] == pytest.approx(list(interval["x"][:, 0]), rel=1e-12)
    assert row["gap_trials"] == int(np.isfinite(m["gap"]).sum())


def test_the_gap_fields_are_none_without_the_frozen_optimum_or_a_trial_worth_it() -> None:
    gap_keys = AGGREGATE_FIELDS[AGGREGATE_FIELDS.index("adaptation_gain_gmean") :]
    (row,) = aggregate_ranking(_hand_episodes(frozen=False), {"a": "catalogue"}, reps=100)
    assert {row[k] for k in gap_keys} == {None}
    assert row["cost_ratio_iqm"] is not None  # the ranking is the same without it
    # every headroom below 1.2: the gain and P(beats) are there, no gap closed
    flat = [(100.0, 110.0, c) for c in (90.0, 110.0, 120.0)]
    (row,) = aggregate_ranking(_hand_episodes(flat), {"a": "catalogue"}, reps=100)
    assert row["prob_beats_frozen"] == pytest.approx(0.5)  # beats, ties, loses: (1 + ½ + 0) / 3
    assert row["adaptation_gain_gmean"] == pytest.approx((110 / 90 * 1.0 * 110 / 120) ** (1 / 3))
    assert row["gap_closed_iqm"] is None and row["gap_closed_iqm_ci95"] is None
    assert row["gap_trials"] == 0


def test_the_gap_fields_are_reproducible_in_any_order_of_episodes() -> None:
    rng = np.random.default_rng(13)
    trials = [(100.0, 100.0 * h, 100.0 * h * g) for h, g in rng.lognormal(0.3, 0.6, (8, 2))]
    eps = _hand_episodes(trials, learned=True)
    first = json.dumps(aggregate_ranking(eps, {"a": "catalogue"}, reps=200))
    assert json.dumps(aggregate_ranking(eps, {"a": "catalogue"}, reps=200)) == first
    shuffled = [eps[i] for i in rng.permutation(len(eps))]
    assert json.dumps(aggregate_ranking(shuffled, {"a": "catalogue"}, reps=200)) == first
    assert '"gap_closed_iqm": null' not in first


def test_scenario_scores_give_the_frozen_optimums_cost_and_the_headroom() -> None:
    eps = _hand_episodes()
    (entry,) = scenario_scores(eps, {"a": "catalogue"})
    # mean of 400, 200, 110, 150, 1000; headroom (4 · 2 · 1.1 · 1.5 · 10)^(1/5) = 132^(1/5)
    assert entry["oracle_frozen_cost"] == pytest.approx(372.0)
    low, high = entry["oracle_frozen_cost_ci95"]
    assert 110.0 <= low < 372.0 < high <= 1000.0
    assert entry["headroom"] == pytest.approx(132**0.2)
    low, high = entry["headroom_ci95"]
    assert 1.1 <= low < 132**0.2 < high <= 10.0
    cells = {c["controller"]: c for c in entry["controllers"]}
    assert cells["oracle_frozen"]["kind"] == "reference"  # a reference cell, like zero_rudder
    assert cells["oracle_frozen"]["cost_ratio_gmean"] == pytest.approx(entry["headroom"])
    (bare,) = scenario_scores(_hand_episodes(frozen=False), {"a": "catalogue"})
    assert [bare[k] for k in ("oracle_frozen_cost", "oracle_frozen_cost_ci95")] == [None, None]
    assert [bare[k] for k in ("headroom", "headroom_ci95")] == [None, None]


def test_the_frozen_optimum_is_a_reference_whatever_its_kind_says() -> None:
    from shipgym_baselines.leaderboard.ranking import controller_kinds

    eps = _hand_episodes()
    for ep in eps:
        ep["kind"] = "classical"
    assert controller_kinds(eps)["oracle_frozen"] == "reference"
    assert controller_kinds(eps, {"oracle_frozen": "learned"})["oracle_frozen"] == "reference"
    assert "oracle_frozen" not in {r["controller"] for r in aggregate_ranking(eps, {"a": "c"})}


def test_change_family_follows_the_catalogues_names() -> None:
    from shipgym_baselines.leaderboard.ranking import change_family

    assert change_family("esso_osaka_current_shift_curved") == "current_shift"
    assert change_family("rudder_aging_long") == "rudder_aging"
    assert change_family("maneuverability_change") == "maneuverability_change"
    assert change_family("blanke_nominal") == "nominal"
    assert change_family("nominal") == "nominal"
    assert change_family("osaka_curved") == "other"
    assert change_family("my_rudder_agingx") == "other"  # a whole part of the name only


def test_the_headroom_table_per_ship_and_change_family() -> None:
    from shipgym_baselines.leaderboard.ranking import headroom_table, scenario_ships

    def trial(scenario: str, seed: int, oracle: float, frozen: float) -> list[dict]:
        return [
            {"scenario": scenario, "controller": c, "seed": seed, "cost": cost}
            for c, cost in (("oracle", oracle), ("oracle_frozen", frozen))
        ]

    eps = trial("rudder_aging", 1, 10.0, 20.0) + trial("rudder_aging_long", 1, 10.0, 80.0)
    eps += trial("rudder_aging_long", 2, 10.0, 10.0)  # headroom 1
    eps += trial("mariner_current_shift_curved", 1, 5.0, 15.0)
    eps += trial("mariner_nominal", 1, 5.0, 5.0) + trial("mariner_track", 1, 5.0, 6.0)
    eps += trial("heldout:0", 1, 1.0, 100.0)  # held out: not the catalogue's
    settings = {
        name: {"ship": {"model": ship}}
        for name, ship in (
            ("mariner_nominal", "mariner"),
            ("rudder_aging", "nomoto2"),
            ("rudder_aging_long", "nomoto2"),
            ("mariner_current_shift_curved", "mariner"),
            ("mariner_track", "mariner"),
            ("heldout:0", "blanke"),
        )
    }
    ships = scenario_ships(settings)
    splits = {s: "heldout" if s.startswith("heldout") else "catalogue" for s in ships}
    rows = headroom_table(eps, ships, splits)
    table = {(r["ship"], r["family"]): (r["headroom_gmean"], r["trials"]) for r in rows}
    assert [(r["ship"], r["family"]) for r in rows] == [  # ships as run.json lists them
        ("mariner", "nominal"),
        ("mariner", "current_shift"),
        ("mariner", "other"),
        ("nomoto2", "rudder_aging"),
    ]
    # nomoto2 rudder aging: headrooms 2, 8 and 1 over three trials: (2 · 8 · 1)^(1/3)
    assert table[("nomoto2", "rudder_aging")] == (pytest.approx(16 ** (1 / 3)), 3)
    assert table[("mariner", "current_shift")] == (pytest.approx(3.0), 1)
    assert table[("mariner", "nominal")] == (pytest.approx(1.0), 1)
    assert table[("mariner", "other")] == (pytest.approx(1.2), 1)
    assert rows[3]["scenarios"] == ["rudder_aging", "rudder_aging_long"]
    with pytest.raises(ValueError, match="mariner_track"):
        headroom_table(eps, {k: v for k, v in ships.items() if k != "mariner_track"}, splits)
    with pytest.raises(ValueError, match=r"'x'.*ship\.model"):
        scenario_ships({"x": {"name": "x"}})
    assert headroom_table([e for e in eps if e["controller"] == "oracle"], ships, splits) == []
