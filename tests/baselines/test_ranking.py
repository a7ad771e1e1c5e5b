"""Interval estimates and the aggregate ranking on synthetic data with known answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from baselines.ranking import (
    aggregate_ranking,
    normalised_scores,
    performance_profiles,
    row_intervals,
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


def _episodes(returns: dict[str, list[float]], scenarios=("a", "b"), training_seeds=None):
    eps = []
    for s_i, scenario in enumerate(scenarios):
        for controller, values in returns.items():
            for seed, value in enumerate(values):
                runs = training_seeds if controller == "agent" and training_seeds else [None]
                for t in runs:
                    eps.append(
                        {
                            "scenario": scenario,
                            "controller": controller,
                            "seed": seed,
                            "training_seed": t,
                            "return": value * (1 + s_i) + (0 if t is None else 0.0),
                        }
                    )
    return eps


def test_scores_are_exactly_zero_and_one_for_the_references_and_affine_between() -> None:
    eps = _episodes({"zero_rudder": [-100, -80], "pid_los": [-20, -10], "x": [-60, -45]})
    scored = {
        (e["controller"], e["scenario"], e["seed"]): e["score"] for e in normalised_scores(eps)
    }
    assert scored[("pid_los", "a", 0)] == 1.0 and scored[("zero_rudder", "b", 1)] == 0.0
    assert scored[("x", "a", 0)] == pytest.approx(0.5)  # halfway from −100 to −20
    assert scored[("x", "b", 1)] == pytest.approx((-90 + 160) / (-20 + 160))


def test_aggregate_ranking_known_answers() -> None:
    """A controller halfway between the references everywhere scores 0.5 (mean and IQM,
    point intervals), never beats pid_los; pid_los itself ties with itself (P = ½)."""
    eps = _episodes(
        {
            "zero_rudder": [-100.0] * 5,
            "pid_los": [-20.0] * 5,
            "half": [-60.0] * 5,
            "agent": [-10.0] * 5,  # better than pid_los: score 1.125
        },
        training_seeds=[0, 1, 2],
    )
    splits = {"a": "catalogue", "b": "heldout"}
    rows = aggregate_ranking(eps, splits, {"agent": "learned"}, reps=500)
    by = {(r["controller"], r["split"]): r for r in rows}
    half = by[("half", "catalogue")]
    assert half["score_mean"] == pytest.approx(0.5) and half["score_iqm"] == pytest.approx(0.5)
    assert half["score_mean_ci95"] == pytest.approx([0.5, 0.5])
    assert half["prob_improvement_over_pid_los"] == 0.0
    assert by[("pid_los", "heldout")]["prob_improvement_over_pid_los"] == pytest.approx(0.5)
    agent = by[("agent", "catalogue")]
    assert agent["kind"] == "learned" and agent["training_seeds"] == 3 and agent["runs"] == 15
    assert agent["score_iqm"] == pytest.approx(1.125)
    assert agent["prob_improvement_over_pid_los"] == 1.0
    assert agent["scenarios"] == ["a"]
    # ranked by IQM within a split
    catalogue = [r["controller"] for r in rows if r["split"] == "catalogue"]
    assert catalogue == ["agent", "pid_los", "half", "zero_rudder"]


def test_aggregate_intervals_shrink_with_more_seeds_and_cover_the_truth() -> None:
    rng = np.random.default_rng(3)

    def run(n: int):
        returns = {
            "zero_rudder": [-100.0] * n,
            "pid_los": [-20.0] * n,
            "noisy": list(-60.0 + rng.normal(0.0, 8.0, n)),  # true mean score 0.5
        }
        rows = aggregate_ranking(
            _episodes(returns), {"a": "catalogue", "b": "catalogue"}, {}, reps=300
        )
        return next(r for r in rows if r["controller"] == "noisy")

    small, large = run(10), run(90)
    w_small = small["score_mean_ci95"][1] - small["score_mean_ci95"][0]
    w_large = large["score_mean_ci95"][1] - large["score_mean_ci95"][0]
    assert w_large < 0.5 * w_small  # width ∝ 1/√n: 9× the seeds, a third
    assert large["score_mean_ci95"][0] < 0.5 < large["score_mean_ci95"][1]


def test_performance_profile_is_the_fraction_of_runs_above_tau() -> None:
    eps = _episodes({"zero_rudder": [-100.0] * 4, "pid_los": [-20.0] * 4, "half": [-60.0] * 4})
    profiles, intervals = performance_profiles(
        eps, {"a": "catalogue"}, "catalogue", np.array([0.25, 0.75]), reps=100
    )
    np.testing.assert_allclose(profiles["half"], [1.0, 0.0])
    np.testing.assert_allclose(profiles["pid_los"], [1.0, 1.0])
    assert intervals["half"].shape == (2, 2)


def test_scenario_scores_give_each_cell_its_mean_and_interval() -> None:
    from baselines.ranking import scenario_scores

    eps = _episodes({"zero_rudder": [-100.0] * 4, "pid_los": [-20.0] * 4, "half": [-60.0] * 4})
    cells = {(c["controller"], c["scenario"]): c for c in scenario_scores(eps, {"a": "catalogue"})}
    assert cells[("half", "a")]["score_mean"] == pytest.approx(0.5)
    assert cells[("half", "a")]["score_ci95"] == pytest.approx([0.5, 0.5])
    assert cells[("pid_los", "b")]["split"] == "catalogue"  # unknown scenarios: catalogue
    assert cells[("zero_rudder", "a")]["episodes"] == 4


def test_the_fast_metrics_give_rliables_bits() -> None:
    """interquartile_mean and probability_of_improvement (vectorised) equal rliable's
    aggregate_iqm and probability_of_improvement exactly, ties and equal columns included."""
    from rliable import metrics as rmetrics

    from baselines.ranking import interquartile_mean, probability_of_improvement

    rng = np.random.default_rng(3)
    for trial in range(200):
        m, n, tasks = rng.integers(1, 12, 3)
        digits = int(rng.integers(0, 3))  # coarse rounding makes ties
        x = np.round(rng.normal(1.0, 0.3, (m, tasks)), digits)
        y = x.copy() if trial % 7 == 0 else np.round(rng.normal(1.0, 0.3, (n, tasks)), digits)
        assert interquartile_mean(x) == rmetrics.aggregate_iqm(x)
        assert probability_of_improvement(x, y) == rmetrics.probability_of_improvement(x, y)
