"""Interval estimates and the aggregate ranking of the leaderboard (issue 13).

After Agarwal et al. (2021), "Deep RL at the edge of the statistical precipice" (the
``rliable`` library):

* **Row intervals** — every (scenario, controller) row carries, for each reported metric,
  a 95 % percentile-bootstrap interval of its mean over the row's episodes, stratified over
  training seeds for learned agents (each bootstrap sample redraws the evaluation episodes
  within each training seed, so every training run stays represented):
  :func:`row_intervals`, vectorised numpy (one row costs ≈ 1 ms).
* **Normalised score** per episode, from the return (the same reward for every
  controller): 0 = ``zero_rudder``, 1 = ``pid_los`` on the same scenario and seed,
  score = (R − R_zero) / (R_pid − R_zero) (:func:`normalised_scores`).
* **Aggregate ranking** per controller and split (catalogue / held-out), over the scenarios
  the controller applies to: mean and interquartile mean (IQM) of the scores with 95 %
  stratified-bootstrap intervals, and the probability of improvement over ``pid_los``
  P(score > pid_los's on the same scenario and seed) with its interval, computed with
  ``rliable`` (:func:`aggregate_ranking`; runs = training seeds × evaluation seeds, tasks =
  scenarios).  The performance profile (fraction of runs with score > τ) comes from
  ``rliable`` too (:func:`performance_profiles`).
"""

from __future__ import annotations

import contextlib
import math
import warnings
from collections import defaultdict
from collections.abc import Iterable, Iterator, Mapping, Sequence
from typing import Any

import numpy as np

#: the two reference controllers of the normalised score
SCORE_ZERO = "zero_rudder"
SCORE_ONE = "pid_los"
#: 95 % intervals
CONFIDENCE = 0.95
#: bootstrap replications of row intervals (numpy) and of the aggregate (rliable)
ROW_REPS = 4000
AGGREGATE_REPS = 2000


@contextlib.contextmanager
def _quiet_arch() -> Iterator[None]:
    """rliable passes ``random_state`` to arch's bootstrap, which arch 7 deprecates."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "random_state is deprecated", FutureWarning)
        yield


def _rng(seed: int) -> np.random.Generator:
    return np.random.default_rng(seed)


def stratified_bootstrap_ci(
    strata: Sequence[Sequence[float]],
    reps: int = ROW_REPS,
    confidence: float = CONFIDENCE,
    seed: int = 0,
) -> list[float] | None:
    """Percentile-bootstrap interval [low, high] of the mean over all values.

    ``strata``: the values grouped by stratum (e.g. one list per training seed); each
    bootstrap sample redraws every stratum's values with replacement, keeping its size.
    None if a value is not finite (e.g. t_c = ∞) or there are none.
    """
    groups = [np.asarray(g, dtype=np.float64) for g in strata if len(g)]
    if not groups or not all(np.all(np.isfinite(g)) for g in groups):
        return None
    rng = _rng(seed)
    total = np.zeros(reps)
    count = 0
    for g in groups:
        idx = rng.integers(0, g.size, size=(reps, g.size))
        total += g[idx].sum(axis=1)
        count += g.size
    means = total / count
    alpha = 0.5 * (1.0 - confidence)
    low, high = np.quantile(means, [alpha, 1.0 - alpha])
    return [float(low), float(high)]


def row_intervals(
    episodes: Sequence[Mapping[str, Any]], metrics: Iterable[str], seed: int = 0
) -> dict[str, list[float] | None]:
    """``{f"{metric}_ci95": [low, high] | None}`` for one row's episodes (dicts with the
    metrics and, for learned agents, ``training_seed``): stratified over training seeds."""
    by_run: dict[Any, list[Mapping[str, Any]]] = defaultdict(list)
    for ep in episodes:
        by_run[ep.get("training_seed")].append(ep)
    out: dict[str, list[float] | None] = {}
    for metric in metrics:
        strata = []
        for run in sorted(by_run, key=lambda s: (s is None, s)):
            values = [_number(ep.get(metric)) for ep in by_run[run]]
            strata.append(values)
        out[f"{metric}_ci95"] = stratified_bootstrap_ci(strata, seed=seed)
    return out


def _number(value: Any) -> float:
    if value is None:
        return math.nan
    return float(value)


# ---------------------------------------------------------------------------------- scores
def normalised_scores(
    episodes: Sequence[Mapping[str, Any]],
    zero: str = SCORE_ZERO,
    one: str = SCORE_ONE,
) -> list[dict[str, Any]]:
    """Each episode's score (R − R_zero) / (R_one − R_zero), the references on the same
    scenario and seed; episodes whose references are missing, or whose references tie
    (R_one = R_zero), get ``score`` None.  Returns copies of the episodes with ``score``."""
    ref: dict[tuple[str, str, int], float] = {}
    for ep in episodes:
        if ep["controller"] in (zero, one) and ep.get("return") is not None:
            ref[(ep["controller"], ep["scenario"], int(ep["seed"]))] = float(ep["return"])
    out = []
    for ep in episodes:
        key = (ep["scenario"], int(ep["seed"]))
        low, high = ref.get((zero, *key)), ref.get((one, *key))
        score = None
        if low is not None and high is not None and high != low and ep.get("return") is not None:
            if ep["controller"] == one:
                score = 1.0  # exactly, by definition
            elif ep["controller"] == zero:
                score = 0.0
            else:
                score = (float(ep["return"]) - low) / (high - low)
        out.append({**ep, "score": score})
    return out


def score_matrix(
    scored: Sequence[Mapping[str, Any]], controller: str, scenarios: Sequence[str]
) -> np.ndarray:
    """(runs, tasks) scores of one controller: a run is a (training seed, evaluation seed)
    pair, a task a scenario (rliable's layout).  Raises ValueError if a scenario lacks a
    run the others have (unequal seeds)."""
    cells: dict[str, dict[tuple[Any, int], float]] = {s: {} for s in scenarios}
    for ep in scored:
        if ep["controller"] == controller and ep["scenario"] in cells:
            if ep.get("score") is not None:
                cells[ep["scenario"]][(ep.get("training_seed"), int(ep["seed"]))] = ep["score"]
    runs = sorted(cells[scenarios[0]], key=lambda r: (r[0] is None, r[0], r[1]))
    for s in scenarios:
        if set(cells[s]) != set(runs):
            raise ValueError(
                f"{controller}: scenario {s!r} has runs {sorted(cells[s])} but "
                f"{scenarios[0]!r} has {runs}: every scenario needs the same seeds"
            )
    return np.array([[cells[s][r] for s in scenarios] for r in runs], dtype=np.float64)


def scenario_scores(
    episodes: Sequence[Mapping[str, Any]], splits: Mapping[str, str], seed: int = 0
) -> list[dict[str, Any]]:
    """Per (controller, scenario): the mean normalised score over the row's episodes with its
    95 % interval (stratified over training seeds), for the controller × scenario table."""
    scored = normalised_scores(episodes)
    groups: dict[tuple[str, str], list[Mapping[str, Any]]] = defaultdict(list)
    for ep in scored:
        if ep.get("score") is not None:
            groups[(ep["controller"], ep["scenario"])].append(ep)
    out = []
    for (controller, scenario), eps in sorted(groups.items()):
        ci = row_intervals(eps, ["score"], seed=seed)["score_ci95"]
        out.append(
            {
                "controller": controller,
                "scenario": scenario,
                "split": splits.get(scenario, "catalogue"),
                "score_mean": float(np.mean([ep["score"] for ep in eps])),
                "score_ci95": ci,
                "episodes": len(eps),
            }
        )
    return out


def interquartile_mean(scores: np.ndarray) -> float:
    """rliable's ``metrics.aggregate_iqm`` (scipy's 25 % ``trim_mean`` over all runs and
    tasks), with the same bits: scipy's partition and mean without its per-call argument
    checks (≈ 0.13 ms of each bootstrap sample)."""
    a = np.asarray(scores, dtype=np.float64).ravel()
    low = int(0.25 * a.size)
    high = a.size - low
    return np.mean(np.partition(a, (low, high - 1))[low:high])


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


def _tasks(scored: Sequence[Mapping[str, Any]], controller: str, split_scenarios: set[str]):
    return sorted(
        {
            ep["scenario"]
            for ep in scored
            if ep["controller"] == controller
            and ep["scenario"] in split_scenarios
            and ep.get("score") is not None
        }
    )


def aggregate_ranking(
    episodes: Sequence[Mapping[str, Any]],
    splits: Mapping[str, str],
    kinds: Mapping[str, str],
    reps: int = AGGREGATE_REPS,
    seed: int = 0,
) -> list[dict[str, Any]]:
    """The ``aggregate.json`` rows: per controller and split (module doc), ranked by IQM.

    ``splits``: scenario → "catalogue" | "heldout"; ``kinds``: controller → "classical" |
    "learned".  Scores are NaN-free by construction; a controller without scored episodes
    in a split has no row there.
    """
    from rliable import library as rly
    from rliable import metrics as rmetrics

    scored = normalised_scores(episodes)
    controllers = sorted({ep["controller"] for ep in scored})
    rows: list[dict[str, Any]] = []
    for split in sorted(set(splits.values())):
        in_split = {s for s, sp in splits.items() if sp == split}
        for controller in controllers:
            tasks = _tasks(scored, controller, in_split)
            if not tasks:
                continue
            x = score_matrix(scored, controller, tasks)
            ref = score_matrix(scored, SCORE_ONE, tasks)
            with _quiet_arch():
                point, interval = rly.get_interval_estimates(
                    {controller: x},
                    lambda m: np.array([rmetrics.aggregate_mean(m), interquartile_mean(m)]),
                    reps=reps,
                    random_state=np.random.RandomState(seed),
                )
                p_point, p_interval = rly.get_interval_estimates(
                    {controller: [x, ref]},
                    probability_of_improvement,
                    reps=reps,
                    random_state=np.random.RandomState(seed),
                )
            mean, iqm = point[controller]
            runs = {(ep.get("training_seed")) for ep in scored if ep["controller"] == controller}
            rows.append(
                {
                    "controller": controller,
                    "kind": kinds.get(controller, "classical"),
                    "split": split,
                    "scenarios": tasks,
                    "runs": int(x.shape[0]),
                    "training_seeds": len(runs - {None}),
                    "score_mean": float(mean),
                    "score_mean_ci95": [float(v) for v in interval[controller][:, 0]],
                    "score_iqm": float(iqm),
                    "score_iqm_ci95": [float(v) for v in interval[controller][:, 1]],
                    "prob_improvement_over_pid_los": float(np.asarray(p_point[controller])),
                    "prob_improvement_over_pid_los_ci95": [
                        float(v) for v in np.asarray(p_interval[controller]).ravel()
                    ],
                }
            )
    rows.sort(key=lambda r: (r["split"], -r["score_iqm"], r["controller"]))
    return rows


def performance_profiles(
    episodes: Sequence[Mapping[str, Any]],
    splits: Mapping[str, str],
    split: str,
    taus: np.ndarray,
    reps: int = 500,
    seed: int = 0,
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """rliable's score distributions (fraction of runs with score > τ) and their 95 %
    intervals, per controller, over its scenarios of ``split``."""
    from rliable import library as rly

    scored = normalised_scores(episodes)
    in_split = {s for s, sp in splits.items() if sp == split}
    matrices = {}
    for controller in sorted({ep["controller"] for ep in scored}):
        tasks = _tasks(scored, controller, in_split)
        if tasks:
            matrices[controller] = score_matrix(scored, controller, tasks)
    state = np.random.get_state()  # noqa: NPY002 (rliable's profile bootstrap draws from
    np.random.seed(seed)  # noqa: NPY002 numpy's global generator: seeded, then restored)
    try:
        with _quiet_arch():
            return rly.create_performance_profile(matrices, taus, reps=reps)
    finally:
        np.random.set_state(state)  # noqa: NPY002
