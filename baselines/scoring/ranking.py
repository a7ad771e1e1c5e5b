"""Interval estimates and the aggregate ranking of the leaderboard.

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
  :data:`~shipgym_baselines.scoring.scores.FAILURE_REASONS`), or its cost is not finite.
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
  ``headroom`` = C_frozen / C_oracle (:func:`~shipgym_baselines.scoring.headroom.trial_headroom`):
  what knowing the change is
  worth.  Per controller and split (:func:`ranking_row`, the same bootstrap as the rest):
  the geometric mean of C_frozen / C (``cost_vs_frozen_gmean``: > 1, better than never
  adapting), P(C < C_frozen) + ½ P(C = C_frozen) over the trials
  (``prob_beats_frozen``) and the IQM of the gap closed, log(C_frozen / C) /
  log(C_frozen / C_oracle), over the trials whose headroom is at least
  :data:`~shipgym_baselines.scoring.headroom.GAP_HEADROOM` (``gap_closed_iqm``: 0 = no better than
  never adapting, 1 = the
  oracle; ``gap_trials`` of them).  The gap's run matrix holds NaN on the trials that do
  not qualify and its IQM is over the finite entries, so each bootstrap sample redraws
  the qualifying trials with the rest (the interval is None if one sample draws none).
  :func:`~shipgym_baselines.scoring.headroom.headroom_table`: the headroom per ship × change family.
* **Steering and adapting, apart** (:mod:`.change_share`): with each changing trial's
  no-change twin, the nominal ratio C(twin) / C_oracle(twin) (``nominal_cost_ratio_gmean``)
  and the change share (``change_share_iqm``) of each row, same bootstrap.

**Reproducible**: rliable 1.2's bootstraps draw from numpy's *global* generator (its
``update_indices`` calls ``np.random.choice``; the ``random_state`` it hands to arch is
never used), so every rliable call here runs inside :func:`seeded_global_rng`: the global
state seeded, and restored afterwards.  The same episodes give the same numbers in any
process and order.

The statistics live in :mod:`.intervals`, each episode's score in :mod:`.scores`, what
adaptation is worth in :mod:`.headroom`; this module assembles the ranking's rows
(``aggregate.json``, ``scenario_scores.json``).
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

# the references: ORACLE (its cost is the cost ratio's denominator) and ORACLE_FROZEN
from shipgym_baselines.privileged import ORACLE, ORACLE_FROZEN

# stay importable from here
# the controller of the probability of improvement
from shipgym_baselines.registry import BASELINE
from shipgym_baselines.scoring.change_share import TWIN_FIELDS, episode_costs, twin_fields

# the statistics, the episodes' scores and what adaptation is worth have their own
# modules (intervals, scores, headroom); their names stay importable from here
from shipgym_baselines.scoring.headroom import GAP_FIELDS, gap_fields
from shipgym_baselines.scoring.intervals import (
    AGGREGATE_REPS,
    bounds,
    geometric_mean,
    interquartile_mean,
    interval_estimate,
    probability_of_lower_ratio,
    row_intervals,
    seeded_global_rng,
)
from shipgym_baselines.scoring.scores import (
    FAILED_EPISODES,
    REFERENCE_KIND,
    controller_kinds,
    ranked_scenarios,
    rated_scenarios,
    run_matrix,
    scored_episodes,
)

PARTIAL = ":partial"
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
    *GAP_FIELDS,
    *TWIN_FIELDS,
)


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


def _ratio_estimates(ratios: np.ndarray) -> np.ndarray:
    return np.array([interquartile_mean(ratios), geometric_mean(ratios)])


def _failure_estimate(failures: np.ndarray) -> np.ndarray:
    return np.array([np.mean(failures)])


def ranking_row(
    scored: Sequence[Mapping[str, Any]],
    controller: str,
    kind: str,
    split: str,
    tasks: list[str],
    reps: int = AGGREGATE_REPS,
    seed: int = 0,
    twins: Mapping[str, str] | None = None,
    costs: dict | None = None,
) -> dict[str, Any]:
    """One ``aggregate.json`` object (:data:`AGGREGATE_FIELDS`): ``controller`` over
    ``tasks``; the probability of improvement is None for ``pid_los`` itself (no comparison
    with itself) and where ``pid_los`` lacks a task (not ranked in this run, or not there);
    ``twins``: changing scenario → its twin (None: no twin fields); ``costs``: the
    episodes' costs (:func:`~.change_share.episode_costs`, computed once per table)."""
    ratios = run_matrix(scored, controller, tasks)
    point, interval = interval_estimate(ratios, _ratio_estimates, reps, seed)
    fail_point, fail_interval = interval_estimate(
        run_matrix(scored, controller, tasks, "failure"), _failure_estimate, reps, seed
    )
    prob: float | None = None
    prob_ci: list[float] | None = None
    if controller != BASELINE and set(tasks) <= set(rated_scenarios(scored, BASELINE, set(tasks))):
        pair = [ratios, run_matrix(scored, BASELINE, tasks)]
        p_point, p_interval = interval_estimate(pair, probability_of_lower_ratio, reps, seed)
        prob, prob_ci = float(p_point[0]), bounds(p_interval, 0)
    trained = {ep.get("training_seed") for ep in scored if ep["controller"] == controller}
    return {
        "controller": controller,
        "kind": kind,
        "split": split,
        "scenarios": tasks,
        "runs": int(ratios.shape[0]),
        "training_seeds": len(trained - {None}),
        "cost_ratio_iqm": float(point[0]),
        "cost_ratio_iqm_ci95": bounds(interval, 0),
        "cost_ratio_gmean": float(point[1]),
        "cost_ratio_gmean_ci95": bounds(interval, 1),
        PROB: prob,
        f"{PROB}_ci95": prob_ci,
        "failure_rate": float(fail_point[0]),
        "failure_rate_ci95": bounds(fail_interval, 0),
        **gap_fields(scored, controller, tasks, reps, seed),
        **twin_fields(scored, controller, tasks, twins or {}, reps, seed, costs),
    }


def aggregate_ranking(
    episodes: Sequence[Mapping[str, Any]],
    splits: Mapping[str, str],
    kinds: Mapping[str, str] | None = None,
    reps: int = AGGREGATE_REPS,
    seed: int = 0,
    twins: Mapping[str, str] | None = None,
) -> list[dict[str, Any]]:
    """The ``aggregate.json`` rows (module doc): per split, every competing controller (kind
    not ``reference``) on the same scenarios (those with the oracle's episodes), ranked by
    the cost ratio's IQM, ascending; a competitor without ratios on some of them is ranked on
    its own in the split ``"<split>:partial"``.  ``splits``: scenario → "catalogue" |
    "heldout" | "inrange" | "yours"; ``kinds``: controller → kind (default: the episodes');
    ``episodes`` may hold the twins' (``twins``: changing scenario → its twin's table name;
    the twins are no split's).  Empty without the oracle's episodes."""
    scored = scored_episodes(episodes)
    costs = episode_costs(scored)
    kind_of = controller_kinds(episodes, kinds)
    competitors = sorted(c for c, k in kind_of.items() if k != REFERENCE_KIND)
    rows: list[dict[str, Any]] = []
    for split in sorted(set(splits.values())):
        common = ranked_scenarios(scored, [s for s, sp in splits.items() if sp == split])
        for controller in competitors:
            tasks = rated_scenarios(scored, controller, set(common))
            if tasks:
                label = split if tasks == common else split + PARTIAL
                kind = kind_of[controller]
                rows.append(
                    ranking_row(scored, controller, kind, label, tasks, reps, seed, twins, costs)
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
        tasks = rated_scenarios(scored, controller, common)
        if tasks:
            matrices[controller] = run_matrix(scored, controller, tasks)
    with seeded_global_rng(seed):
        return rly.create_performance_profile(matrices, taus, reps=reps)
