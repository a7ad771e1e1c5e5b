"""The leaderboard's rows: episodes aggregated per (scenario, controller), the episodes the
ranking reads and the generalisation means (the scenario splits: :mod:`.splits`)."""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Collection, Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from shipgym.metrics import aggregate
from shipgym_baselines.records.episodes import CONTROLLER_STATS, EpisodeResult
from shipgym_baselines.registry import controller_kind
from shipgym_baselines.scoring.intervals import row_intervals

# the splits are defined in .splits; these names stay importable from here
from shipgym_baselines.scoring.splits import (
    ALWAYS_GENERALISED,
    GENERALISATION_SPLITS,
    scenario_split,
)

COLUMNS = (
    "ace",
    "ace_L",
    "t_c",
    "return",
    "cost",
    "rudder_travel",
    "J",
    "success",
    "compute_ms",
    "mean_abs_cross_track",
    "max_abs_cross_track",
)

#: training-cost columns, present for learned agents only (mean and std over training seeds)
TRAINING_COLUMNS = ("train_env_steps", "train_wall_s")

AGGREGATE_FILE = "aggregate.json"
SCENARIO_SCORES_FILE = "scenario_scores.json"


def episode_rows(results: Iterable[EpisodeResult]) -> list[dict[str, Any]]:
    """The episodes as the ranking reads them: every metric, ``training_seed`` and keys."""
    return [{**r.row(), "training_seed": r.training_seed} for r in results]


def aggregate_results(
    results: list[EpisodeResult],
    scenarios: list[str],
    controllers: list[str],
    kinds: Mapping[str, str] | None = None,
    not_applicable: set[tuple[str, str]] | None = None,
    splits: Mapping[str, str] | None = None,
) -> list[dict[str, Any]]:
    """One row per (scenario, controller) over its episodes (training seeds × evaluation
    seeds): means, ``*_std`` and 95 % ``*_ci95`` intervals ``[low, high]`` (bootstrap,
    stratified over training seeds: :func:`shipgym_baselines.scoring.ranking.row_intervals`;
    None where a metric is not finite in every episode, e.g. t_c when a seed never converged),
    or "does not apply".  ``seeds``: the evaluation seeds; ``training_seeds``: how many training
    seeds (0 for a controller that is not trained), ``training_seed_list`` which;
    ``episodes``: their product.  ``kinds``: controller kinds (default: the registry's);
    ``not_applicable``: the (scenario, controller) pairs that do not apply (None: every pair
    without episodes); a pair without episodes that is not listed has no row (a partial or
    merged record); ``splits``: scenario → split (default: :func:`scenario_split`)."""
    groups: dict[tuple[str, str], list[EpisodeResult]] = defaultdict(list)
    for r in results:
        groups[(r.scenario, r.controller)].append(r)
    rows = []
    for scenario in scenarios:
        for controller in controllers:
            group = groups.get((scenario, controller), [])
            listed = not_applicable is None or (scenario, controller) in not_applicable
            if not group and not listed:
                continue  # not run (yet): no row
            head = {
                "scenario": scenario,
                "split": (splits or {}).get(scenario) or scenario_split(scenario),
                "controller": controller,
                "kind": group[0].kind
                if group
                else (kinds or {}).get(controller) or controller_kind(controller),
                "applies": bool(group),
            }
            if not group:  # the controller does not apply to this scenario's ship: shown
                rows.append({**head, **_counts([]), **_metric_cells(COLUMNS, None, None)})
                continue
            metrics = [with_training_cost(r.metrics) for r in group]
            keys = COLUMNS + tuple(k for k in TRAINING_COLUMNS if k in metrics[0])
            agg = aggregate(metrics, keys)
            cis = row_intervals(episode_rows(group), COLUMNS)
            rows.append({**head, **_counts(group), **_metric_cells(keys, agg, cis)})
    return rows


def with_training_cost(metrics: Mapping[str, Any]) -> dict[str, Any]:
    """An episode's metrics with its learned agent's training cost
    (:data:`TRAINING_COLUMNS`, which the agent reports among its own figures,
    :data:`~shipgym_baselines.records.episodes.CONTROLLER_STATS`) beside them; a record of
    an earlier version holds it beside them already."""
    figures = metrics.get(CONTROLLER_STATS) or {}
    cost = {k: figures[k] for k in TRAINING_COLUMNS if k not in metrics and _number(figures.get(k))}
    return {**metrics, **cost}


def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _counts(group: list[EpisodeResult]) -> dict[str, Any]:
    trained = sorted({r.training_seed for r in group if r.training_seed is not None})
    return {
        "seeds": len({r.seed for r in group}),
        "training_seeds": len(trained),
        "training_seed_list": trained,
        "episodes": len(group),
    }


def _metric_cells(
    keys: Sequence[str], agg: Mapping[str, float] | None, cis: Mapping[str, Any] | None
) -> dict[str, Any]:
    """``key``, ``key_std`` and (for :data:`COLUMNS`) ``key_ci95`` of each metric."""
    cells: dict[str, Any] = {}
    for key in keys:
        cells[key] = None if agg is None else agg[key]
        cells[f"{key}_std"] = None if agg is None else agg[f"{key}_std"]
        if key in COLUMNS:
            cells[f"{key}_ci95"] = None if cis is None else cis[f"{key}_ci95"]
    return cells


def rankable(
    episodes: list[dict[str, Any]],
    scenario_seeds: Mapping[str, Collection[int]] | None = None,
    shared: bool = False,
) -> list[dict[str, Any]]:
    """The episodes the ranking is computed from: those of the scenarios on which every
    controller that ran there has all its runs (each of its training seeds × every
    evaluation seed of the record; with ``shared``, one training seed per evaluation seed,
    :mod:`shipgym_baselines.records.trials`; ``scenario_seeds``: the scenarios run on fewer
    seeds, with theirs).  A complete run keeps them all; an interrupted or merged record
    leaves out the scenarios it holds only in part."""
    every = {int(e["seed"]) for e in episodes}
    fewer = scenario_seeds or {}
    trained: dict[str, set[Any]] = defaultdict(set)
    cells: dict[tuple[str, str], set[tuple[Any, int]]] = defaultdict(set)
    for e in episodes:
        trained[e["controller"]].add(e["training_seed"])
        cells[(e["scenario"], e["controller"])].add((e["training_seed"], int(e["seed"])))
    partial = {
        scenario
        for (scenario, controller), runs in cells.items()
        if len(runs)
        != (1 if shared else len(trained[controller])) * len(fewer.get(scenario, every))
    }
    return [e for e in episodes if e["scenario"] not in partial]


def generalisation_splits(rows: Sequence[Mapping[str, Any]]) -> tuple[str, ...]:
    """The splits of :func:`generalisation`: catalogue and held-out always, in-range and
    unseen-hull when the run has their rows."""
    present = {r["split"] for r in rows}
    return tuple(s for s in GENERALISATION_SPLITS if s in ALWAYS_GENERALISED or s in present)


def generalisation(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per controller: mean ACE/L, return and success on catalogue vs held-out scenarios
    (and in-range ones, ``inrange_*`` keys, when the run has them).

    Means are over the scenarios of each split on which *every* controller of the table
    ran (so that all controllers are compared on the same set; ``*_scenarios`` counts them).
    """
    controllers = list(dict.fromkeys(r["controller"] for r in rows))
    ran = {(r["scenario"], r["controller"]) for r in rows if r.get("applies", True)}
    splits = generalisation_splits(rows)
    common = {}
    for split in splits:
        scenarios = dict.fromkeys(r["scenario"] for r in rows if r["split"] == split)
        common[split] = [s for s in scenarios if all((s, c) in ran for c in controllers)]
    out = []
    for controller in controllers:
        mine = [r for r in rows if r["controller"] == controller]
        entry: dict[str, Any] = {"controller": controller, "kind": mine[0]["kind"]}
        for split in splits:
            group = [r for r in mine if r["scenario"] in common[split]]
            entry[f"{split}_scenarios"] = len(group)
            for key in ("ace_L", "return", "success"):
                values = [r[key] for r in group if isinstance(r[key], float)]
                entry[f"{split}_{key}"] = float(np.mean(values)) if values else math.nan
        out.append(entry)
    return out
