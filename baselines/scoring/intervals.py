"""The statistics of the leaderboard's intervals: the percentile bootstrap of a row's
means (stratified over training seeds), the aggregate estimators (interquartile mean,
geometric mean, probability of improvement) and rliable's stratified bootstrap of them,
reproducible (:func:`seeded_global_rng`; the method: :mod:`.ranking`)."""

from __future__ import annotations

import contextlib
import math
from collections import defaultdict
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from typing import Any

import numpy as np

#: 95 % intervals
CONFIDENCE = 0.95
#: bootstrap replications of row intervals (numpy) and of the aggregate (rliable)
ROW_REPS = 4000
AGGREGATE_REPS = 2000


@contextlib.contextmanager
def seeded_global_rng(seed: int) -> Iterator[None]:
    """numpy's global generator seeded with ``seed`` inside, restored afterwards (rliable
    draws its bootstrap indices from it: module doc)."""
    state = np.random.get_state()  # noqa: NPY002
    np.random.seed(seed)  # noqa: NPY002
    try:
        yield
    finally:
        np.random.set_state(state)  # noqa: NPY002


def _rng(seed: int) -> np.random.Generator:
    return np.random.default_rng(seed)


def stratified_bootstrap_ci(
    strata: Sequence[Sequence[float]],
    reps: int = ROW_REPS,
    confidence: float = CONFIDENCE,
    seed: int = 0,
    indices: Sequence[np.ndarray] | None = None,
) -> list[float] | None:
    """Percentile-bootstrap interval [low, high] of the mean over all values.

    ``strata``: the values grouped by stratum (e.g. one list per training seed); each
    bootstrap sample redraws every stratum's values with replacement, keeping its size.
    None if a value is not finite (e.g. t_c = ∞) or there are none.  ``indices``: the
    resamples of each non-empty stratum (:func:`bootstrap_indices` of their sizes, ``reps``
    and ``seed``), to share one draw between the metrics of one set of episodes.
    """
    groups = [np.asarray(g, dtype=np.float64) for g in strata if len(g)]
    if not groups or not all(np.all(np.isfinite(g)) for g in groups):
        return None
    if indices is None:
        indices = bootstrap_indices([g.size for g in groups], reps, seed)
    total = np.zeros(reps)
    count = 0
    for g, idx in zip(groups, indices, strict=True):
        total += g[idx].sum(axis=1)
        count += g.size
    means = total / count
    alpha = 0.5 * (1.0 - confidence)
    low, high = np.quantile(means, [alpha, 1.0 - alpha])
    return [float(low), float(high)]


def bootstrap_indices(sizes: Sequence[int], reps: int = ROW_REPS, seed: int = 0) -> list:
    """The resample indices of strata of ``sizes`` (each (reps, size)), drawn in order from
    one generator seeded with ``seed``: what :func:`stratified_bootstrap_ci` draws."""
    rng = _rng(seed)
    return [rng.integers(0, size, size=(reps, size)) for size in sizes]


def row_intervals(
    episodes: Sequence[Mapping[str, Any]], metrics: Iterable[str], seed: int = 0
) -> dict[str, list[float] | None]:
    """``{f"{metric}_ci95": [low, high] | None}`` for one row's episodes (dicts with the
    metrics and, for learned agents, ``training_seed``): stratified over training seeds
    when every training seed played the same evaluation seeds (:func:`row_strata`), else
    the row's episodes resampled as one pool."""
    strata = row_strata(episodes)
    # every metric resamples the same episodes: one draw serves them all (the same numbers)
    indices = bootstrap_indices([len(group) for group in strata], seed=seed)
    out: dict[str, list[float] | None] = {}
    for metric in metrics:
        values = [[float_or_nan(ep.get(metric)) for ep in group] for group in strata]
        out[f"{metric}_ci95"] = stratified_bootstrap_ci(values, seed=seed, indices=indices)
    return out


def row_strata(episodes: Sequence[Mapping[str, Any]]) -> list[list[Mapping[str, Any]]]:
    """The strata a row's interval resamples within: one per training seed when each
    played the same evaluation seeds (every training seed × every trial), else one of all
    the episodes (trials dealt among the training seeds: a stratum per training seed would
    hold one or two episodes, and an interval of one trial has no width)."""
    by_run: dict[Any, list[Mapping[str, Any]]] = defaultdict(list)
    for ep in episodes:
        by_run[ep.get("training_seed")].append(ep)
    runs = sorted(by_run, key=lambda s: (s is None, s))
    trials = {frozenset(int(ep["seed"]) for ep in by_run[run]) for run in runs}
    if len(trials) > 1:
        return [list(episodes)]
    return [by_run[run] for run in runs]


def pooled_bootstrap_ci(
    values: np.ndarray,
    statistic: Callable[[np.ndarray], np.ndarray],
    reps: int = ROW_REPS,
    confidence: float = CONFIDENCE,
    seed: int = 0,
) -> list[float] | None:
    """Percentile-bootstrap interval [low, high] of ``statistic`` over ``values`` resampled
    with replacement as one pool; ``statistic`` maps a (reps, n) array of resamples to
    their (reps,) values (e.g. :func:`iqm_rows`).  None without finite values."""
    a = np.asarray(values, dtype=np.float64).ravel()
    if not a.size or not np.all(np.isfinite(a)):
        return None
    (idx,) = bootstrap_indices([a.size], reps, seed)
    return percentile_interval(statistic(a[idx]), confidence)


def float_or_nan(value: Any) -> float:
    if value is None:
        return math.nan
    return float(value)


def interquartile_mean(scores: np.ndarray) -> float:
    """rliable's ``metrics.aggregate_iqm`` (scipy's 25 % ``trim_mean`` over all runs and
    tasks), with the same bits: scipy's partition and mean without its per-call argument
    checks (≈ 0.13 ms of each bootstrap sample)."""
    a = np.asarray(scores, dtype=np.float64).ravel()
    low = int(0.25 * a.size)
    high = a.size - low
    return np.mean(np.partition(a, (low, high - 1))[low:high])


def nan_iqm_rows(samples: np.ndarray) -> np.ndarray:
    """The interquartile mean of the finite entries of each row of ``samples``
    (:func:`interquartile_mean`'s trim of each row's n finite values: ⌊n/4⌋ off each end);
    NaN for a row without one."""
    a = np.sort(np.asarray(samples, dtype=np.float64), axis=-1)  # NaN sorts last
    n = np.isfinite(a).sum(axis=-1)
    low = (0.25 * n).astype(np.int64)
    high = n - low
    sums = np.concatenate([np.zeros((*a.shape[:-1], 1)), np.cumsum(np.nan_to_num(a), -1)], -1)
    inner = np.take_along_axis(sums, high[..., None], -1) - np.take_along_axis(
        sums, low[..., None], -1
    )
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, inner[..., 0] / (high - low), np.nan)


def nan_gmean_rows(samples: np.ndarray) -> np.ndarray:
    """The geometric mean of the finite positive entries of each row of ``samples`` (NaN
    for a row without one)."""
    a = np.asarray(samples, dtype=np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        logs = np.where(np.isfinite(a) & (a > 0.0), np.log(np.where(a > 0.0, a, 1.0)), np.nan)
        counts = np.isfinite(logs).sum(axis=-1)
        return np.where(counts > 0, np.exp(np.nansum(logs, axis=-1) / counts), np.nan)


def stratified_nan_ci(
    matrix: np.ndarray,
    statistic: Callable[[np.ndarray], np.ndarray],
    reps: int = AGGREGATE_REPS,
    confidence: float = CONFIDENCE,
    seed: int = 0,
) -> list[float] | None:
    """Percentile interval [low, high] of ``statistic`` over a (runs, tasks) matrix with NaN
    cells (those a statistic leaves out, e.g. trials not worth a gap): each resample redraws
    every task's runs with replacement (rliable's stratified bootstrap); ``statistic`` maps
    (reps, cells) resamples to (reps,) values ignoring NaN (:func:`nan_iqm_rows`,
    :func:`nan_gmean_rows`).  A resample without a finite value is left out (it is rare:
    it draws none of a task's counted runs on every task); None when every one is."""
    m = np.asarray(matrix, dtype=np.float64)
    runs, tasks = m.shape
    idx = _rng(seed).integers(0, runs, size=(reps, runs, tasks))
    values = statistic(m[idx, np.arange(tasks)].reshape(reps, -1))
    return percentile_interval(values[np.isfinite(values)], confidence)


def percentile_interval(samples: np.ndarray, confidence: float = CONFIDENCE) -> list[float] | None:
    """The central ``confidence`` interval [low, high] of bootstrap ``samples`` (None:
    none)."""
    if not np.size(samples):
        return None
    alpha = 0.5 * (1.0 - confidence)
    low, high = np.quantile(samples, [alpha, 1.0 - alpha])
    return [float(low), float(high)]


def iqm_rows(samples: np.ndarray) -> np.ndarray:
    """The interquartile mean of each row of ``samples`` (:func:`interquartile_mean`'s trim:
    ⌊n/4⌋ values off each end of each sorted row)."""
    a = np.sort(np.asarray(samples, dtype=np.float64), axis=-1)
    low = int(0.25 * a.shape[-1])
    return a[..., low : a.shape[-1] - low].mean(axis=-1)


def gmean_rows(samples: np.ndarray) -> np.ndarray:
    """The geometric mean of each row of positive ``samples``."""
    return np.exp(np.log(np.asarray(samples, dtype=np.float64)).mean(axis=-1))


def finite_iqm(values: np.ndarray) -> float:
    """:func:`interquartile_mean` over the finite entries (NaN: none)."""
    a = np.asarray(values, dtype=np.float64).ravel()
    a = a[np.isfinite(a)]
    return float(interquartile_mean(a)) if a.size else math.nan


def finite_gmean(ratios: np.ndarray) -> float:
    """The geometric mean over the finite positive entries (NaN: none)."""
    a = np.asarray(ratios, dtype=np.float64).ravel()
    a = a[np.isfinite(a) & (a > 0.0)]
    return float(np.exp(np.mean(np.log(a)))) if a.size else math.nan


def geometric_mean(ratios: Sequence[float] | np.ndarray) -> float:
    """exp(mean(log r)) of positive ratios [–], over all runs and tasks (the mean of ratios
    on a log scale): the leaderboard's, the tuner's and model selection's.  A ValueError
    without ratios or with one that is not positive."""
    values = np.asarray(ratios, dtype=np.float64)
    if values.size == 0 or np.any(values <= 0):
        raise ValueError(f"a geometric mean needs positive ratios, got {values.ravel().tolist()}")
    return float(np.exp(np.mean(np.log(values))))


def probability_of_improvement(scores_x: np.ndarray, scores_y: np.ndarray) -> float:
    """rliable's ``metrics.probability_of_improvement`` (the Mann-Whitney U statistic per
    task, U / (m·n) = P(X > Y) + ½ P(X = Y), averaged over tasks), with the same bits,
    vectorised: rliable calls scipy once per task and bootstrap sample (≈ 14 s per
    controller for 14 tasks × 2000 samples; this: ≈ 0.1 s)."""
    x, y = scores_x[:, None, :], scores_y[None, :, :]
    u = (x > y).sum(axis=(0, 1)) + 0.5 * (x == y).sum(axis=(0, 1))
    per_task = u / (scores_x.shape[0] * scores_y.shape[0])
    same = [np.array_equal(scores_x[:, t], scores_y[:, t]) for t in range(scores_x.shape[1])]
    return np.mean(np.where(same, 0.5, per_task))


def probability_of_lower_ratio(ratios_x: np.ndarray, ratios_y: np.ndarray) -> float:
    """P(X < Y) + ½ P(X = Y) per task, averaged over tasks: the probability of improvement
    when lower is better (:func:`probability_of_improvement` of the negated ratios)."""
    return probability_of_improvement(-ratios_x, -ratios_y)


def interval_estimate(
    scores: np.ndarray | list[np.ndarray],
    func: Callable[..., np.ndarray],
    reps: int = AGGREGATE_REPS,
    seed: int = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """(point, [low, high] per entry of ``func``'s result): rliable's stratified bootstrap
    (``get_interval_estimates``; a list of matrices: independent resampling of each), drawn
    from the global generator seeded with ``seed`` (module doc)."""
    from rliable import library as rly

    with seeded_global_rng(seed):
        point, interval = rly.get_interval_estimates({"x": scores}, func, reps=reps)
    low_high = np.asarray(interval["x"], dtype=np.float64).reshape(2, -1)
    return np.atleast_1d(np.asarray(point["x"], dtype=np.float64)), low_high


def bounds(values: np.ndarray, i: int) -> list[float]:
    return [float(values[0, i]), float(values[1, i])]


def finite_bounds(values: np.ndarray, i: int) -> list[float] | None:
    """:func:`bounds`, None when a bound is not finite (a bootstrap sample without a value)."""
    pair = bounds(values, i)
    return pair if all(math.isfinite(v) for v in pair) else None


def finite_or_none(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None
