"""The intervals' statistics: the stratified bootstrap and the fast estimators."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym_baselines.leaderboard.intervals import (
    interquartile_mean,
    probability_of_improvement,
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


def test_the_fast_metrics_give_rliables_bits() -> None:
    """interquartile_mean and probability_of_improvement (vectorised) equal rliable's
    aggregate_iqm and probability_of_improvement exactly, ties and equal columns included."""
    from rliable import metrics as rmetrics

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
