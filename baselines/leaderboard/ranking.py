"""Interval estimates and the aggregate ranking of the leaderboard (issues 13 and 17).

After Agarwal et al. (2021), "Deep RL at the edge of the statistical precipice" (the
``rliable`` library):

* **Row intervals** — every (scenario, controller) row carries, for each reported metric,
  a 95 % percentile-bootstrap interval of its mean over the row's episodes, stratified over
  training seeds for learned agents (each bootstrap sample redraws the evaluation episodes
  within each training seed, so every training run stays represented):
  :func:`row_intervals`, vectorised numpy (one row costs ≈ 1 ms).
* **Cost ratio** per episode: the episode's cost C (the metric ``cost``: the step costs and
  any corridor penalty, the return without the goal bonus) over the cost of the reference
  controller ``oracle`` (a privileged NMPC on the true plant) on the same scenario and trial
  (evaluation seed): C / C_oracle, 1 = as good as the oracle, lower is better
  (:func:`scored_episodes`).  An episode *fails* when it ends outside the corridor, with a
  non-finite state or by its controller's error or timeout (``termination_reason``,
  :data:`FAILURE_REASONS`), or its cost is not finite.
* **Aggregate ranking** per controller and split (catalogue / held-out / in-range / yours),
  over the scenarios of the split that have the oracle's episodes: the interquartile mean
  (IQM) and the geometric mean of the cost ratios, the probability of improvement over ``pid_los``
  P(ratio < pid_los's ratio on a scenario) + ½ P(equal) (rliable's probability of
  improvement of the negated ratios: lower cost is the improvement; None for ``pid_los``
  itself and where ``pid_los`` lacks a scenario of the row) and the failure rate,
  each with a 95 % stratified-bootstrap interval (runs = training seeds × evaluation seeds,
  tasks = scenarios; :func:`aggregate_ranking`), ranked by the IQM, ascending.  References
  (kind ``reference``: ``oracle``, ``oracle_frozen``, ``zero_rudder``, ``random``) are not
  ranked.  Every competitor of the main table of a split is ranked on the same scenarios;
  one that lacks some (it does not apply to a ship) is ranked on its own scenarios in the
  separate table ``split`` = ``"<split>:partial"``.  The performance profile (fraction of
  runs with ratio > τ) comes from ``rliable`` too (:func:`performance_profiles`).
* **What adaptation is worth**: the second reference ``oracle_frozen`` is the same NMPC
  with its truth frozen at the episode's start (the optimum that never adapts).  Per trial,
  ``headroom`` = C_frozen / C_oracle (:func:`trial_headroom`): what knowing the change is
  worth.  Per controller and split (:func:`ranking_row`, the same bootstrap as the rest):
  the geometric mean of C_frozen / C (``adaptation_gain_gmean``: > 1, better than never
  adapting), P(C < C_frozen) + ½ P(C = C_frozen) over the trials
  (``prob_beats_frozen``) and the IQM of the gap closed, log(C_frozen / C) /
  log(C_frozen / C_oracle), over the trials whose headroom is at least
  :data:`GAP_HEADROOM` (``gap_closed_iqm``: 0 = no better than never adapting, 1 = the
  oracle; ``gap_trials`` of them).  The gap's run matrix holds NaN on the trials that do
  not qualify and its IQM is over the finite entries, so each bootstrap sample redraws
  the qualifying trials with the rest (the interval is None if one sample draws none).
  :func:`headroom_table`: the headroom per ship × change family.

**Reproducible**: rliable 1.2's bootstraps draw from numpy's *global* generator (its
``update_indices`` calls ``np.random.choice``; the ``random_state`` it hands to arch is
never used), so every rliable call here runs inside :func:`seeded_global_rng`: the global
state seeded, and restored afterwards.  The same episodes give the same numbers in any
process and order.
"""

from __future__ import annotations

import contextlib
import math
from collections import defaultdict
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from typing import Any

import numpy as np

# the references: ORACLE (its cost is the cost ratio's denominator) and ORACLE_FROZEN
from shipgym_baselines.privileged import ORACLE, ORACLE_FROZEN

# an episode its controller ended is told by its record, in records.episodes; these names
# stay importable from here
from shipgym_baselines.records.episodes import CONTROLLER_ERROR as CONTROLLER_ERROR
from shipgym_baselines.records.episodes import CONTROLLER_FAILURES
from shipgym_baselines.records.episodes import CONTROLLER_TIMEOUT as CONTROLLER_TIMEOUT
from shipgym_baselines.records.episodes import controller_failed as controller_failed

# the controller of the probability of improvement
from shipgym_baselines.registry import BASELINE

#: the kind of the controllers shown on every scenario but never ranked
REFERENCE_KIND = "reference"
#: the ``termination_reason`` values of a failed episode
FAILURE_REASONS = ("corridor", "non_finite_state", *CONTROLLER_FAILURES)
#: what a failed episode is, in the words of the tables and the verdict
FAILED_EPISODES = (
    "episodes ending outside the corridor, non-finite or by a controller error or timeout"
)
#: the split label's suffix of the table of controllers ranked on fewer scenarios
PARTIAL = ":partial"
#: 95 % intervals
CONFIDENCE = 0.95
#: bootstrap replications of row intervals (numpy) and of the aggregate (rliable)
ROW_REPS = 4000
AGGREGATE_REPS = 2000
#: the gap closed is averaged over the trials where knowing the change is worth at least
#: this factor (headroom C_frozen / C_oracle)
GAP_HEADROOM = 1.2
#: an aggregate row's probability of improvement over ``pid_los`` (None: no comparison)
PROB = f"prob_improvement_over_{BASELINE}"
#: the fields of an ``aggregate.json`` object, in order
AGGREGATE_FIELDS = (
    "controller",
    "kind",
    "split",
    "scenarios",
    "runs",
    "training_seeds",
    "cost_ratio_iqm",
    "cost_ratio_iqm_ci95",
    "cost_ratio_gmean",
    "cost_ratio_gmean_ci95",
    PROB,
    f"{PROB}_ci95",
    "failure_rate",
    "failure_rate_ci95",
    "adaptation_gain_gmean",
    "adaptation_gain_gmean_ci95",
    "prob_beats_frozen",
    "prob_beats_frozen_ci95",
    "gap_closed_iqm",
    "gap_closed_iqm_ci95",
    "gap_trials",
)
#: an aggregate row's adaptation gain (None: no frozen optimum's episodes)
GAIN = "adaptation_gain_gmean"
#: what the headroom table and the gap columns mean (leaderboard.md and the page)
HEADROOM_EXPLAINED = (
    f"What knowing the change is worth: the cost of {ORACLE_FROZEN} (the same NMPC as "
    f"{ORACLE}, its truth frozen at the episode's start: the optimum that never adapts) "
    f"over {ORACLE}'s, geometric mean over the catalogue scenarios' trials of each ship "
    "and change family (how many below). 1: adapting is worth nothing. In the ranking: the "
    "adaptation gain C_frozen / C (geometric mean; above 1: better than the optimum that "
    "never adapts), P(C < C_frozen) over the trials (ties count half) and the gap closed, "
    "log(C_frozen / C) / log(C_frozen / C_oracle) (0 = never adapting, 1 = the oracle), "
    f"its IQM over the trials worth {GAP_HEADROOM:g}× or more."
)
#: the gap fields of a row without the frozen optimum's episodes
NO_GAP: dict[str, Any] = {
    key: None for key in AGGREGATE_FIELDS[AGGREGATE_FIELDS.index("adaptation_gain_gmean") :]
}


#: leaderboard.md's two sentences on the score
SCORE_EXPLAINED = (
    "An episode's cost is the sum of its step costs and any corridor penalty (its return "
    f"without the goal bonus), and its cost ratio divides it by the cost of `{ORACLE}` (an "
    "NMPC that knows the true plant, a reference) on the same scenario and trial, so 1 is "
    "the oracle's cost and lower is better. Per controller and split: the interquartile "
    "mean (IQM) and the geometric mean of the ratios over runs (training seeds × "
    f"evaluation seeds) and scenarios, P(its ratio is below {BASELINE}'s on a scenario) and "
    f"the failure rate ({FAILED_EPISODES}), each with a 95 % "
    "stratified-bootstrap interval (rliable; Agarwal et al. 2021), ranked by IQM, lowest "
    "first."
)
#: what leaderboard.md, the page and the terminal say without the oracle's episodes
NO_RANKING = (
    f"No ranking: the cost ratio needs the episodes of the reference `{ORACLE}` on the same "
    "scenarios and trials, and this record has none. To get one, run with the references "
    f"(without `--no-references`, or with `{ORACLE}` among `--controllers` or the suite's "
    "controllers): its episodes are read from the shipped reference table."
)
#: what they say when the oracle ran but every controller is a reference
NOTHING_TO_RANK = (
    f"Nothing to rank: every controller of this record is a reference (`{ORACLE}` and the "
    "controllers of kind `reference`, shown on every scenario but never ranked). Add a "
    f"controller to rank, e.g. `shipgym leaderboard --controllers {BASELINE} MINE` or "
    "`shipgym evaluate MINE` (the references are added)."
)


def no_ranking(scores: Sequence[Mapping[str, Any]]) -> str:
    """Why a record has no ranking: :data:`NOTHING_TO_RANK` when it has the oracle's episodes
    (``scores``: :func:`scenario_scores`, one entry per scenario with them), else
    :data:`NO_RANKING`."""
    return NOTHING_TO_RANK if scores else NO_RANKING


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
    metrics and, for learned agents, ``training_seed``): stratified over training seeds."""
    by_run: dict[Any, list[Mapping[str, Any]]] = defaultdict(list)
    for ep in episodes:
        by_run[ep.get("training_seed")].append(ep)
    runs = sorted(by_run, key=lambda s: (s is None, s))
    # every metric resamples the same episodes: one draw serves them all (the same numbers)
    indices = bootstrap_indices([len(by_run[run]) for run in runs if by_run[run]], seed=seed)
    out: dict[str, list[float] | None] = {}
    for metric in metrics:
        strata = [[_number(ep.get(metric)) for ep in by_run[run]] for run in runs]
        out[f"{metric}_ci95"] = stratified_bootstrap_ci(strata, seed=seed, indices=indices)
    return out


def _number(value: Any) -> float:
    if value is None:
        return math.nan
    return float(value)


# ---------------------------------------------------------------------------------- scores
def is_failure(episode: Mapping[str, Any]) -> bool:
    """The episode ended outside the corridor, non-finite or by its controller's error or
    timeout (:data:`FAILURE_REASONS`), or its cost is not finite."""
    return episode.get("termination_reason") in FAILURE_REASONS or not math.isfinite(
        _number(episode.get("cost"))
    )


def scored_episodes(
    episodes: Sequence[Mapping[str, Any]], oracle: str = ORACLE
) -> list[dict[str, Any]]:
    """Copies of the episodes with ``cost_ratio`` = C / C_oracle (the oracle's episode of the
    same scenario and seed; exactly 1 for the oracle's own) and ``failure`` (0 or 1,
    :func:`is_failure`).  ``cost_ratio`` is None where the oracle has no episode, or where
    either cost is not finite or the oracle's is not positive."""
    ref: dict[tuple[str, int], float] = {}
    for ep in episodes:
        if ep["controller"] == oracle:
            ref[(ep["scenario"], int(ep["seed"]))] = _number(ep.get("cost"))
    out = []
    for ep in episodes:
        c_ref = ref.get((ep["scenario"], int(ep["seed"])), math.nan)
        cost = _number(ep.get("cost"))
        ratio = None
        if math.isfinite(c_ref) and c_ref > 0.0 and math.isfinite(cost):
            ratio = 1.0 if ep["controller"] == oracle else cost / c_ref
        out.append({**ep, "cost_ratio": ratio, "failure": float(is_failure(ep))})
    return out


def run_matrix(
    scored: Sequence[Mapping[str, Any]],
    controller: str,
    scenarios: Sequence[str],
    key: str = "cost_ratio",
) -> np.ndarray:
    """(runs, tasks) values ``key`` of one controller's episodes that have a cost ratio: a
    run is a (training seed, evaluation seed) pair, a task a scenario (rliable's layout);
    each task's runs in the order (training seed, evaluation seed).  The runs of a row are
    rliable's independent samples per task (its stratified bootstrap resamples each task on
    its own): where the training seeds share the trials, each task has its own pairs.
    Raises ValueError if a scenario has more or fewer runs than another (unequal seeds)."""
    cells: dict[str, dict[tuple[Any, int], float]] = {s: {} for s in scenarios}
    for ep in scored:
        if ep["controller"] == controller and ep["scenario"] in cells:
            if ep.get("cost_ratio") is not None:
                cells[ep["scenario"]][(ep.get("training_seed"), int(ep["seed"]))] = ep[key]
    order = {s: sorted(cells[s], key=lambda r: (r[0] is None, r[0] or 0, r[1])) for s in cells}
    first = order[scenarios[0]]
    for s in scenarios:
        if len(order[s]) != len(first):
            raise ValueError(
                f"{controller}: scenario {s!r} has runs {order[s]} but "
                f"{scenarios[0]!r} has {first}: every scenario needs the same seeds"
            )
    return np.array(
        [[cells[s][order[s][i]] for s in scenarios] for i in range(len(first))], dtype=np.float64
    )


def interquartile_mean(scores: np.ndarray) -> float:
    """rliable's ``metrics.aggregate_iqm`` (scipy's 25 % ``trim_mean`` over all runs and
    tasks), with the same bits: scipy's partition and mean without its per-call argument
    checks (≈ 0.13 ms of each bootstrap sample)."""
    a = np.asarray(scores, dtype=np.float64).ravel()
    low = int(0.25 * a.size)
    high = a.size - low
    return np.mean(np.partition(a, (low, high - 1))[low:high])


def geometric_mean(ratios: np.ndarray) -> float:
    """exp(mean(log r)) over all runs and tasks (the mean of ratios on a log scale)."""
    with np.errstate(divide="ignore"):
        return np.exp(np.mean(np.log(np.asarray(ratios, dtype=np.float64))))


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


def _ratio_estimates(ratios: np.ndarray) -> np.ndarray:
    return np.array([interquartile_mean(ratios), geometric_mean(ratios)])


def _failure_estimate(failures: np.ndarray) -> np.ndarray:
    return np.array([np.mean(failures)])


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


def _tasks(scored: Sequence[Mapping[str, Any]], controller: str, scenarios: set[str]) -> list[str]:
    """The scenarios of ``scenarios`` on which every episode of ``controller`` has a cost
    ratio (one whose cost, or its oracle's, is not finite has none: its scenario is left
    out of the controller's main table, so every ranked row keeps all its runs)."""
    rated, unrated = set(), set()
    for ep in scored:
        if ep["controller"] == controller and ep["scenario"] in scenarios:
            (rated if ep.get("cost_ratio") is not None else unrated).add(ep["scenario"])
    return sorted(rated - unrated)


def controller_kinds(
    episodes: Iterable[Mapping[str, Any]], kinds: Mapping[str, str] | None = None
) -> dict[str, str]:
    """controller → kind: ``kinds`` first, else the episodes' ``kind`` (``classical`` when
    neither says); the two oracles are references whatever they are called elsewhere."""
    out = {ep["controller"]: ep.get("kind") or "classical" for ep in episodes}
    out.update({c: k for c, k in (kinds or {}).items() if c in out})
    for reference in (ORACLE, ORACLE_FROZEN):
        if reference in out:
            out[reference] = REFERENCE_KIND
    return out


def _pairs(values: np.ndarray, i: int) -> list[float]:
    return [float(values[0, i]), float(values[1, i])]


def _finite_pairs(values: np.ndarray, i: int) -> list[float] | None:
    """:func:`_pairs`, None when a bound is not finite (a bootstrap sample without a value)."""
    pair = _pairs(values, i)
    return pair if all(math.isfinite(v) for v in pair) else None


def _finite_or_none(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


# --------------------------------------------------------------- what adaptation is worth
def _trial_costs(episodes: Iterable[Mapping[str, Any]], controller: str) -> dict:
    """(scenario, seed) → the cost of ``controller``'s episode of that trial (a reference's:
    one per trial)."""
    return {
        (ep["scenario"], int(ep["seed"])): _number(ep.get("cost"))
        for ep in episodes
        if ep["controller"] == controller
    }


def trial_headroom(episodes: Iterable[Mapping[str, Any]]) -> dict[tuple[str, int], float]:
    """(scenario, seed) → headroom C_frozen / C_oracle of every trial with both references'
    episodes, both costs finite and positive: what knowing the change is worth there."""
    episodes = list(episodes)
    oracle = _trial_costs(episodes, ORACLE)
    out = {}
    for trial, frozen in _trial_costs(episodes, ORACLE_FROZEN).items():
        c_ref = oracle.get(trial, math.nan)
        if math.isfinite(c_ref) and c_ref > 0.0 and math.isfinite(frozen) and frozen > 0.0:
            out[trial] = frozen / c_ref
    return out


def gmean_headroom(
    headroom: Mapping[tuple[str, int], float], scenarios: Iterable[str]
) -> tuple[float, int] | None:
    """(geometric mean of the headroom, trials) over the trials of ``scenarios`` in
    ``headroom`` (:func:`trial_headroom`); None without any."""
    wanted = set(scenarios)
    values = [h for (s, _), h in headroom.items() if s in wanted]
    if not values:
        return None
    return float(geometric_mean(np.array(values))), len(values)


def _finite_iqm(scores: np.ndarray) -> float:
    """:func:`interquartile_mean` over the finite entries (NaN: none)."""
    a = np.asarray(scores, dtype=np.float64)
    a = a[np.isfinite(a)]
    return interquartile_mean(a) if a.size else math.nan


def _gain_estimates(gains: np.ndarray) -> np.ndarray:
    """[geometric mean of C_frozen / C, P(C < C_frozen) + ½ P(C = C_frozen)]: for positive
    finite costs C_frozen / C > 1 exactly when C < C_frozen and = 1 exactly when equal
    (IEEE division is correctly rounded), so one matrix gives both."""
    beats = np.mean((gains > 1.0) + 0.5 * (gains == 1.0))
    return np.array([geometric_mean(gains), beats])


def _gap_estimate(gaps: np.ndarray) -> np.ndarray:
    return np.array([_finite_iqm(gaps)])


def gap_matrices(
    scored: Sequence[Mapping[str, Any]], controller: str, tasks: list[str]
) -> dict[str, np.ndarray] | None:
    """The (runs, tasks) matrices of ``controller`` against the frozen optimum, runs as
    :func:`run_matrix` orders them: ``gain`` C_frozen / C, ``beats`` 1 where C < C_frozen
    (½ where equal, else 0), ``gap`` log(C_frozen / C) / log(C_frozen / C_oracle) where the
    trial's headroom is at least :data:`GAP_HEADROOM` (NaN elsewhere) and ``seed`` the
    evaluation seeds.  None unless ``oracle_frozen`` has every trial of the row with a
    finite positive cost."""
    headroom = trial_headroom(scored)
    frozen_cost = _trial_costs(scored, ORACLE_FROZEN)
    seeds = run_matrix(scored, controller, tasks, "seed").astype(np.int64)
    keys = [[(task, int(seed)) for task, seed in zip(tasks, row, strict=True)] for row in seeds]
    if not all(key in headroom for row in keys for key in row):
        return None
    cost = run_matrix(scored, controller, tasks, "cost")
    frozen = np.array([[frozen_cost[key] for key in row] for row in keys], dtype=np.float64)
    room = np.array([[headroom[key] for key in row] for row in keys], dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        gain = frozen / cost
        gap = np.where(room >= GAP_HEADROOM, np.log(gain) / np.log(room), math.nan)
    beats = (cost < frozen) + 0.5 * (cost == frozen)
    return {"gain": gain, "beats": beats.astype(np.float64), "gap": gap, "seed": seeds}


def gap_fields(
    scored: Sequence[Mapping[str, Any]],
    controller: str,
    tasks: list[str],
    reps: int = AGGREGATE_REPS,
    seed: int = 0,
) -> dict[str, Any]:
    """The gap fields of an ``aggregate.json`` row (module doc; :data:`NO_GAP` without the
    frozen optimum's episodes on every trial of the row): each with rliable's stratified
    bootstrap (the same seed and so the same resamples as the row's other fields)."""
    m = gap_matrices(scored, controller, tasks)
    if m is None:
        return dict(NO_GAP)
    point, interval = interval_estimate(m["gain"], _gain_estimates, reps, seed)
    qualified = np.isfinite(m["gap"])
    out = {
        "adaptation_gain_gmean": _finite_or_none(point[0]),
        "adaptation_gain_gmean_ci95": _finite_pairs(interval, 0),
        "prob_beats_frozen": float(point[1]),
        "prob_beats_frozen_ci95": _pairs(interval, 1),
        "gap_closed_iqm": None,
        "gap_closed_iqm_ci95": None,
        "gap_trials": 0,
    }
    if qualified.any():
        gap_point, gap_interval = interval_estimate(m["gap"], _gap_estimate, reps, seed)
        trials = {(t, int(s)) for t, s, q in _cells(tasks, m["seed"], qualified) if q}
        out["gap_closed_iqm"] = _finite_or_none(gap_point[0])
        out["gap_closed_iqm_ci95"] = _finite_pairs(gap_interval, 0)
        out["gap_trials"] = len(trials)
    return out


def _cells(tasks: list[str], seeds: np.ndarray, mask: np.ndarray) -> Iterator[tuple]:
    """(task, seed, mask value) of every cell of a (runs, tasks) matrix."""
    for r in range(seeds.shape[0]):
        for c, task in enumerate(tasks):
            yield task, seeds[r, c], bool(mask[r, c])


def ranking_row(
    scored: Sequence[Mapping[str, Any]],
    controller: str,
    kind: str,
    split: str,
    tasks: list[str],
    reps: int = AGGREGATE_REPS,
    seed: int = 0,
) -> dict[str, Any]:
    """One ``aggregate.json`` object (:data:`AGGREGATE_FIELDS`): ``controller`` over
    ``tasks``; the probability of improvement is None for ``pid_los`` itself (no comparison
    with itself) and where ``pid_los`` lacks a task (not ranked in this run, or not there)."""
    ratios = run_matrix(scored, controller, tasks)
    point, interval = interval_estimate(ratios, _ratio_estimates, reps, seed)
    fail_point, fail_interval = interval_estimate(
        run_matrix(scored, controller, tasks, "failure"), _failure_estimate, reps, seed
    )
    prob: float | None = None
    prob_ci: list[float] | None = None
    if controller != BASELINE and set(tasks) <= set(_tasks(scored, BASELINE, set(tasks))):
        pair = [ratios, run_matrix(scored, BASELINE, tasks)]
        p_point, p_interval = interval_estimate(pair, probability_of_lower_ratio, reps, seed)
        prob, prob_ci = float(p_point[0]), _pairs(p_interval, 0)
    trained = {ep.get("training_seed") for ep in scored if ep["controller"] == controller}
    return {
        "controller": controller,
        "kind": kind,
        "split": split,
        "scenarios": tasks,
        "runs": int(ratios.shape[0]),
        "training_seeds": len(trained - {None}),
        "cost_ratio_iqm": float(point[0]),
        "cost_ratio_iqm_ci95": _pairs(interval, 0),
        "cost_ratio_gmean": float(point[1]),
        "cost_ratio_gmean_ci95": _pairs(interval, 1),
        PROB: prob,
        f"{PROB}_ci95": prob_ci,
        "failure_rate": float(fail_point[0]),
        "failure_rate_ci95": _pairs(fail_interval, 0),
        **gap_fields(scored, controller, tasks, reps, seed),
    }


def ranked_scenarios(
    scored: Sequence[Mapping[str, Any]], split_scenarios: Iterable[str]
) -> list[str]:
    """The scenarios of a split that can be ranked: those with the oracle's episodes."""
    return _tasks(scored, ORACLE, set(split_scenarios))


def aggregate_ranking(
    episodes: Sequence[Mapping[str, Any]],
    splits: Mapping[str, str],
    kinds: Mapping[str, str] | None = None,
    reps: int = AGGREGATE_REPS,
    seed: int = 0,
) -> list[dict[str, Any]]:
    """The ``aggregate.json`` rows (module doc): per split, every competing controller (kind
    not ``reference``) on the same scenarios (those with the oracle's episodes), ranked by
    the cost ratio's IQM, ascending; a competitor without ratios on some of them is ranked on
    its own in the split ``"<split>:partial"``.  ``splits``: scenario → "catalogue" |
    "heldout" | "inrange" | "yours"; ``kinds``: controller → kind (default: the episodes').
    Empty without the oracle's episodes."""
    scored = scored_episodes(episodes)
    kind_of = controller_kinds(episodes, kinds)
    competitors = sorted(c for c, k in kind_of.items() if k != REFERENCE_KIND)
    rows: list[dict[str, Any]] = []
    for split in sorted(set(splits.values())):
        common = ranked_scenarios(scored, [s for s, sp in splits.items() if sp == split])
        for controller in competitors:
            tasks = _tasks(scored, controller, set(common))
            if tasks:
                label = split if tasks == common else split + PARTIAL
                rows.append(
                    ranking_row(scored, controller, kind_of[controller], label, tasks, reps, seed)
                )
    rows.sort(key=lambda r: (r["split"], r["cost_ratio_iqm"], r["controller"]))
    return rows


def is_partial(split: str) -> bool:
    """Whether ``split`` labels a table of controllers ranked on fewer scenarios."""
    return split.endswith(PARTIAL)


def resolution(board: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """Per main table of ``board`` (aggregate rows): how well the ranking separates its
    controllers — the median width of the ``cost_ratio_iqm`` intervals, the range (max − min)
    of ``cost_ratio_iqm`` over the competitors and whether the width is below a fifth of the
    range (``resolved``: the ranking tells its controllers apart)."""
    out = []
    for split in dict.fromkeys(r["split"] for r in board):
        if is_partial(split):
            continue
        mine = [r for r in board if r["split"] == split]
        widths = [r["cost_ratio_iqm_ci95"][1] - r["cost_ratio_iqm_ci95"][0] for r in mine]
        iqms = [r["cost_ratio_iqm"] for r in mine]
        width, spread = float(np.median(widths)), float(max(iqms) - min(iqms))
        out.append(
            {
                "split": split,
                "controllers": len(mine),
                "median_ci_width": width,
                "iqm_range": spread,
                "resolved": width < spread / 5.0,
            }
        )
    return out


def resolution_lines(board: Sequence[Mapping[str, Any]]) -> list[str]:
    """Per main table: the median width of the IQM intervals against the range of the IQM
    over its competitors (:func:`resolution`; target: width < range / 5)."""
    lines = []
    for res in resolution(board):
        verdict = "met" if res["resolved"] else "not met"
        lines.append(
            f"Resolution, {res['split']}: median width of the cost-ratio IQM intervals "
            f"{res['median_ci_width']:.3f}, range of the IQM over the {res['controllers']} "
            f"competing controller(s) {res['iqm_range']:.3f} (target width < range / 5: "
            f"{verdict})."
        )
    return [*lines, ""] if lines else []


def _log_ratio_cell(eps: Sequence[Mapping[str, Any]], seed: int) -> dict[str, Any]:
    """The geometric mean of the cell's ratios and its interval (the exp of the stratified
    bootstrap interval of the mean log ratio: exp is monotone)."""
    with np.errstate(divide="ignore"):
        logs = np.log([ep["cost_ratio"] for ep in eps])
    rows = [{**ep, "log_ratio": v} for ep, v in zip(eps, logs, strict=True)]
    ci = row_intervals(rows, ["log_ratio"], seed=seed)["log_ratio_ci95"]
    return {
        "cost_ratio_gmean": float(np.exp(np.mean(logs))),
        "cost_ratio_gmean_ci95": None if ci is None else [math.exp(v) for v in ci],
    }


def scenario_scores(
    episodes: Sequence[Mapping[str, Any]],
    splits: Mapping[str, str],
    kinds: Mapping[str, str] | None = None,
    seed: int = 0,
) -> list[dict[str, Any]]:
    """``scenario_scores.json``: per scenario with the oracle's episodes, the oracle's mean
    cost with its 95 % interval, the frozen optimum's (``oracle_frozen_cost``, None without
    its episodes) and the headroom (the geometric mean of C_frozen / C_oracle over the
    scenario's trials, with its interval as a cell's), and, per other controller
    (references included), its mean cost and the geometric mean of its cost ratios with a
    95 % interval (stratified over training seeds), over the row's episodes."""
    scored = scored_episodes(episodes)
    kind_of = controller_kinds(episodes, kinds)
    groups: dict[tuple[str, str], list[dict[str, Any]]] = defaultdict(list)
    for ep in scored:
        if ep["cost_ratio"] is not None:
            groups[(ep["scenario"], ep["controller"])].append(ep)
    out = []
    for scenario in sorted({s for s, c in groups if c == ORACLE}):
        oracle = groups[(scenario, ORACLE)]
        cells = []
        for controller in sorted(c for s, c in groups if s == scenario and c != ORACLE):
            eps = groups[(scenario, controller)]
            cells.append(
                {
                    "controller": controller,
                    "kind": kind_of[controller],
                    "cost": float(np.mean([ep["cost"] for ep in eps])),
                    **_log_ratio_cell(eps, seed),
                    "episodes": len(eps),
                }
            )
        out.append(
            {
                "scenario": scenario,
                "split": splits.get(scenario, "catalogue"),
                "oracle_cost": float(np.mean([ep["cost"] for ep in oracle])),
                "oracle_cost_ci95": row_intervals(oracle, ["cost"], seed=seed)["cost_ci95"],
                "oracle_episodes": len(oracle),
                **_frozen_cells(groups.get((scenario, ORACLE_FROZEN), []), seed),
                "controllers": cells,
            }
        )
    return out


def _frozen_cells(frozen: Sequence[Mapping[str, Any]], seed: int) -> dict[str, Any]:
    """A scenario's ``oracle_frozen_cost`` (mean, 95 % interval) and ``headroom`` (the
    geometric mean of its cost ratios C_frozen / C_oracle, 95 % interval), None without
    its episodes."""
    if not frozen:
        return {
            "oracle_frozen_cost": None,
            "oracle_frozen_cost_ci95": None,
            "headroom": None,
            "headroom_ci95": None,
        }
    cell = _log_ratio_cell(frozen, seed)
    return {
        "oracle_frozen_cost": float(np.mean([ep["cost"] for ep in frozen])),
        "oracle_frozen_cost_ci95": row_intervals(frozen, ["cost"], seed=seed)["cost_ci95"],
        "headroom": cell["cost_ratio_gmean"],
        "headroom_ci95": cell["cost_ratio_gmean_ci95"],
    }


#: the change families of the catalogue's scenario names, in the headroom table's order
#: (``{ship}_{family}[_{variant}]``; nomoto2's without the ship: ``{family}[_{variant}]``)
CHANGE_FAMILIES = ("nominal", "rudder_aging", "current_shift", "maneuverability_change")
#: the family of a scenario whose name has none of them (e.g. ``osaka_curved``)
OTHER_FAMILY = "other"


def change_family(scenario: str) -> str:
    """The change family a scenario's name states (:data:`CHANGE_FAMILIES`, by the
    catalogue's naming rule: the family as a whole ``_``-separated part of the name), else
    :data:`OTHER_FAMILY`."""
    parts = f"_{scenario}_"
    for family in CHANGE_FAMILIES:
        if f"_{family}_" in parts:
            return family
    return OTHER_FAMILY


def scenario_ships(settings: Mapping[str, Mapping[str, Any]]) -> dict[str, str]:
    """scenario → its ship (the model's name) from scenario settings as ``run.json`` keeps
    them (``scenarios``: name → the scenario's settings, ``ship.model``)."""
    out = {}
    for name, config in settings.items():
        ship = config.get("ship") if isinstance(config, Mapping) else None
        if not isinstance(ship, Mapping) or not isinstance(ship.get("model"), str):
            raise ValueError(f"scenario {name!r}: its settings name no ship model (ship.model)")
        out[name] = ship["model"]
    return out


def headroom_table(
    episodes: Sequence[Mapping[str, Any]],
    ships: Mapping[str, str],
    splits: Mapping[str, str],
    split: str = "catalogue",
) -> list[dict[str, Any]]:
    """The headroom per ship × change family over the trials of ``split``'s scenarios:
    rows ``ship``, ``family`` (:func:`change_family`), ``scenarios`` (their names),
    ``trials`` and ``headroom_gmean`` (the geometric mean of C_frozen / C_oracle over the
    trials, :func:`trial_headroom`); ships in the order of ``ships``, families in
    :data:`CHANGE_FAMILIES` order then :data:`OTHER_FAMILY`.  ``ships``: scenario → ship
    (:func:`scenario_ships`); a scenario of the split missing from it raises ValueError.
    Empty without both references' episodes."""
    headroom = trial_headroom(episodes)
    mine = sorted({s for s, _ in headroom if splits.get(s, "catalogue") == split})
    missing = [s for s in mine if s not in ships]
    if missing:
        raise ValueError(f"headroom_table: no ship for scenario(s) {', '.join(missing)}")
    order = list(dict.fromkeys(ships.values()))
    families = (*CHANGE_FAMILIES, OTHER_FAMILY)
    cells: dict[tuple[str, str], list[str]] = defaultdict(list)
    for s in mine:
        cells[(ships[s], change_family(s))].append(s)
    rows = []
    for ship, family in sorted(cells, key=lambda k: (order.index(k[0]), families.index(k[1]))):
        names = cells[(ship, family)]
        gmean, trials = gmean_headroom(headroom, names) or (math.nan, 0)
        rows.append(
            {
                "ship": ship,
                "family": family,
                "scenarios": names,
                "trials": trials,
                "headroom_gmean": gmean,
            }
        )
    return rows


def headroom_grid(
    headroom: Sequence[Mapping[str, Any]],
) -> tuple[list[str], list[str], dict[tuple[str, str], Mapping[str, Any]]]:
    """The layout of :func:`headroom_table`'s rows as a table: the ships in row order, the
    families present in :data:`CHANGE_FAMILIES` order (then :data:`OTHER_FAMILY`) and the
    row of each (ship, family)."""
    present = {r["family"] for r in headroom}
    families = [f for f in (*CHANGE_FAMILIES, OTHER_FAMILY) if f in present]
    ships = list(dict.fromkeys(r["ship"] for r in headroom))
    return ships, families, {(r["ship"], r["family"]): r for r in headroom}


def performance_profiles(
    episodes: Sequence[Mapping[str, Any]],
    splits: Mapping[str, str],
    split: str,
    taus: np.ndarray,
    reps: int = 500,
    seed: int = 0,
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """rliable's run-score distributions of the cost ratio (fraction of runs with ratio > τ;
    lower curves are better) and their 95 % intervals, per controller, over its scenarios of
    ``split`` that have the oracle's episodes."""
    from rliable import library as rly

    scored = scored_episodes(episodes)
    common = set(ranked_scenarios(scored, [s for s, sp in splits.items() if sp == split]))
    matrices = {}
    for controller in sorted({ep["controller"] for ep in scored}):
        tasks = _tasks(scored, controller, common)
        if tasks:
            matrices[controller] = run_matrix(scored, controller, tasks)
    with seeded_global_rng(seed):
        return rly.create_performance_profile(matrices, taus, reps=reps)
