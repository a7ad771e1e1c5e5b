"""The intervals' statistics: the stratified bootstrap and the fast estimators."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym_baselines.scoring.intervals import (
    gmean_rows,
    interquartile_mean,
    iqm_rows,
    nan_gmean_rows,
    nan_iqm_rows,
    probability_of_improvement,
    row_intervals,
    row_strata,
    stratified_bootstrap_ci,
    stratified_nan_ci,
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


def _dealt(values: list[float]) -> list[dict]:
    """A learned row whose trials are dealt: seed i played by training seed i % 3 alone."""
    return [{"seed": 10_000 + i, "training_seed": i % 3, "cost": v} for i, v in enumerate(values)]


def test_dealt_trials_are_resampled_as_one_pool_not_strata_of_one_episode() -> None:
    """Three training seeds, one trial each: strata of one episode would give a point
    interval; the row's interval resamples its trials and has the width their spread
    gives (the pooled bootstrap's), and none where they are equal."""
    values = [7.0, 5.0, 9.0]
    ci = row_intervals(_dealt(values), ["cost"])["cost_ci95"]
    assert ci is not None and ci[0] < np.mean(values) < ci[1]
    assert ci == stratified_bootstrap_ci([values])  # one stratum: the trials
    assert row_strata(_dealt(values)) == [_dealt(values)]
    assert row_intervals(_dealt([4.0, 4.0, 4.0]), ["cost"])["cost_ci95"] == [4.0, 4.0]


def test_every_training_seed_on_every_trial_stays_stratified() -> None:
    eps = [
        {"seed": 10_000 + i, "training_seed": k, "cost": float(k * 10 + i)}
        for k in range(3)
        for i in range(4)
    ]
    strata = [[float(k * 10 + i) for i in range(4)] for k in range(3)]
    assert row_intervals(eps, ["cost"])["cost_ci95"] == stratified_bootstrap_ci(strata)
    assert len(row_strata(eps)) == 3


def test_the_vectorised_row_statistics_are_the_scalar_ones() -> None:
    rng = np.random.default_rng(4)
    for n in range(1, 13):
        rows = rng.lognormal(size=(5, n))
        rows[0, : n // 2] = np.nan  # left out by the NaN-aware ones
        for row in rows:
            finite = row[np.isfinite(row)]
            if np.isfinite(row).all():
                assert iqm_rows(row[None])[0] == pytest.approx(interquartile_mean(row))
                assert gmean_rows(row[None])[0] == pytest.approx(np.exp(np.log(row).mean()))
            assert nan_iqm_rows(row[None])[0] == pytest.approx(interquartile_mean(finite))
            assert nan_gmean_rows(row[None])[0] == pytest.approx(np.exp(np.log(finite).mean()))
    assert np.isnan(nan_iqm_rows(np.full((1, 3), np.nan))[0])


def test_the_stratified_interval_with_cells_left_out() -> None:
    """NaN cells are left out of each resample's statistic; the interval of a matrix
    without NaN matches the percentile bootstrap's spread, and covers the point."""
    rng = np.random.default_rng(5)
    matrix = rng.normal(1.0, 0.2, size=(8, 20))
    low, high = stratified_nan_ci(matrix, nan_iqm_rows)
    assert low < interquartile_mean(matrix) < high
    holed = matrix.copy()
    holed[::2, :] = np.nan
    low2, high2 = stratified_nan_ci(holed, nan_iqm_rows)
    assert low2 < np.nanmean(holed) < high2 and high2 - low2 > high - low  # fewer cells
    assert stratified_nan_ci(np.full((3, 2), np.nan), nan_iqm_rows) is None
