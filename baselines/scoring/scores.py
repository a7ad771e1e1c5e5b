"""Each episode's score: its cost ratio C / C_oracle and whether it failed, the
(runs, tasks) matrices rliable reads, and which scenarios a controller can be ranked on
(the method: :mod:`.ranking`).

:func:`cost_ratio` is the one definition of the ratio: the leaderboard's
(:func:`scored_episodes`), the tuner's objective and model selection's
(:func:`objective_ratio`, which counts an episode without a ratio as :data:`FAILED_RATIO`)."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from shipgym_baselines.privileged import ORACLE, ORACLE_FROZEN
from shipgym_baselines.records.episodes import CONTROLLER_FAILURES
from shipgym_baselines.scoring.intervals import float_or_nan

#: the kind of the controllers shown on every scenario but never ranked
REFERENCE_KIND = "reference"
#: the ``termination_reason`` values of a failed episode
FAILURE_REASONS = ("corridor", "non_finite_state", *CONTROLLER_FAILURES)
#: what a failed episode is, in the words of the tables and the verdict
FAILED_EPISODES = (
    "episodes ending outside the corridor, non-finite or by a controller error or timeout"
)


#: the ratio an objective (a tuning study's, model selection's) counts for an episode whose
#: cost is not finite (a diverged simulation): the leaderboard does not score that episode
FAILED_RATIO = 1.0e6


def cost_ratio(cost: Any, reference: Any) -> float | None:
    """C / C_ref of one trial [–]: the episode's cost over the reference's (the oracle's)
    on the same trial.  None where either cost is not finite or the reference's is not
    positive: that trial has no ratio."""
    c, c_ref = float_or_nan(cost), float_or_nan(reference)
    if math.isfinite(c_ref) and c_ref > 0.0 and math.isfinite(c):
        return c / c_ref
    return None


def objective_ratio(cost: Any, reference: Any) -> float:
    """:func:`cost_ratio`, or :data:`FAILED_RATIO` where the trial has none: what a tuning
    study's objective and model selection average (a geometric mean)."""
    ratio = cost_ratio(cost, reference)
    return FAILED_RATIO if ratio is None else ratio


def is_failure(episode: Mapping[str, Any]) -> bool:
    """The episode ended outside the corridor, non-finite or by its controller's error or
    timeout (:data:`FAILURE_REASONS`), or its cost is not finite."""
    return episode.get("termination_reason") in FAILURE_REASONS or not math.isfinite(
        float_or_nan(episode.get("cost"))
    )


def scored_episodes(
    episodes: Sequence[Mapping[str, Any]], oracle: str = ORACLE
) -> list[dict[str, Any]]:
    """Copies of the episodes with ``cost_ratio`` = C / C_oracle (the oracle's episode of the
    same scenario and seed; exactly 1 for the oracle's own) and ``failure`` (0 or 1,
    :func:`is_failure`).  ``cost_ratio`` is None where the oracle has no episode, where its
    episode failed (:func:`is_failure`: never a denominator, :func:`refused_trials`), or
    where either cost is not finite or the oracle's is not positive."""
    ref: dict[tuple[str, int], float] = {}
    for ep in episodes:
        if ep["controller"] == oracle:
            cost = math.nan if is_failure(ep) else float_or_nan(ep.get("cost"))
            ref[(ep["scenario"], int(ep["seed"]))] = cost
    return [
        {
            **ep,
            "cost_ratio": cost_ratio(ep.get("cost"), ref.get((ep["scenario"], int(ep["seed"])))),
            "failure": float(is_failure(ep)),
        }
        for ep in episodes
    ]


def refused_trials(episodes: Iterable[Mapping[str, Any]], oracle: str = ORACLE) -> list[str]:
    """One line per trial whose reference episode failed or has no finite positive cost:
    no episode of that trial is scored (:func:`scored_episodes`), so a reference's failure
    is never a denominator."""
    lines = []
    for ep in episodes:
        if ep["controller"] != oracle:
            continue
        cost = float_or_nan(ep.get("cost"))
        if is_failure(ep) or not cost > 0.0:
            why = ep.get("termination_reason") or "no end"
            error = ep.get("error")
            lines.append(
                f"shipgym: {oracle} on {ep['scenario']} seed {ep['seed']} ended {why}"
                f"{f' ({error})' if error else ''} with cost {cost:.6g}: that trial is "
                "not scored"
            )
    return lines


def run_keys(
    scored: Sequence[Mapping[str, Any]], controller: str, scenarios: Sequence[str]
) -> dict[str, list[tuple[Any, int]]]:
    """Per scenario, the (training seed, evaluation seed) runs of ``controller``'s episodes
    that have a cost ratio, in :func:`run_matrix`'s order (training seed, then seed).
    Raises ValueError if a scenario has more or fewer runs than another (unequal seeds)."""
    cells: dict[str, set[tuple[Any, int]]] = {s: set() for s in scenarios}
    for ep in scored:
        if ep["controller"] == controller and ep["scenario"] in cells:
            if ep.get("cost_ratio") is not None:
                cells[ep["scenario"]].add((ep.get("training_seed"), int(ep["seed"])))
    order = {s: sorted(cells[s], key=lambda r: (r[0] is None, r[0] or 0, r[1])) for s in cells}
    first = order[scenarios[0]]
    for s in scenarios:
        if len(order[s]) != len(first):
            raise ValueError(
                f"{controller}: scenario {s!r} has runs {order[s]} but "
                f"{scenarios[0]!r} has {first}: every scenario needs the same seeds"
            )
    return order


def run_matrix(
    scored: Sequence[Mapping[str, Any]],
    controller: str,
    scenarios: Sequence[str],
    key: str = "cost_ratio",
) -> np.ndarray:
    """(runs, tasks) values ``key`` of one controller's episodes that have a cost ratio: a
    run is a (training seed, evaluation seed) pair, a task a scenario (rliable's layout);
    each task's runs in the order (training seed, evaluation seed) (:func:`run_keys`).  The
    runs of a row are rliable's independent samples per task (its stratified bootstrap
    resamples each task on its own): where the training seeds share the trials, each task
    has its own pairs.  Raises ValueError if a scenario has more or fewer runs than another
    (unequal seeds)."""
    values: dict[tuple[str, Any, int], Any] = {}
    for ep in scored:
        if ep["controller"] == controller and ep.get("cost_ratio") is not None:
            values[(ep["scenario"], ep.get("training_seed"), int(ep["seed"]))] = ep[key]
    order = run_keys(scored, controller, scenarios)
    runs = len(order[scenarios[0]])
    return np.array(
        [[values[(s, *order[s][i])] for s in scenarios] for i in range(runs)], dtype=np.float64
    )


def rated_scenarios(
    scored: Sequence[Mapping[str, Any]], controller: str, scenarios: set[str]
) -> list[str]:
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


def ranked_scenarios(
    scored: Sequence[Mapping[str, Any]], split_scenarios: Iterable[str]
) -> list[str]:
    """The scenarios of a split that can be ranked: those with the oracle's episodes."""
    return rated_scenarios(scored, ORACLE, set(split_scenarios))
