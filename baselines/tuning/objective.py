"""The objective of every study: the cost ratio to the oracle on the validation trials.

Per trial, the ratio C / C_oracle of the episode cost (the leaderboard's ``cost``: the step
costs and any corridor penalty) to the oracle's cost on the same trial
(:mod:`~shipgym_baselines.tuning.validation`); the objective is their geometric mean over
the trials (1 = as good as the oracle, lower is better), as the leaderboard's
``cost_ratio_gmean``: the ratio and the mean are the leaderboard's own
(:func:`~shipgym_baselines.scoring.scores.objective_ratio`,
:func:`~shipgym_baselines.scoring.intervals.geometric_mean`). An episode whose cost is not
finite counts as :data:`~shipgym_baselines.scoring.scores.FAILED_RATIO`.
:func:`chunked_ratios` scores the trials a chunk at a time and hands the running geometric
mean to ``report`` after each chunk (the pruner's intermediate values)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from shipgym_baselines.plugins import ControllerEntry
from shipgym_baselines.scoring.intervals import geometric_mean
from shipgym_baselines.scoring.scores import objective_ratio
from shipgym_baselines.tuning.validation import ValidationTrial


def controller_ratios(
    controller: str,
    settings: dict[str, Any],
    trials: Sequence[ValidationTrial],
    oracle: Sequence[float],
) -> list[float]:
    """The cost ratio of ``controller`` made with ``settings`` on each of ``trials``."""
    from shipgym_baselines.evaluation import evaluate_batch

    entry = ControllerEntry(controller=controller, settings=settings)
    results = evaluate_batch(entry, [t.scenario for t in trials], [t.seed for t in trials])
    return [objective_ratio(r.metrics.get("cost"), c) for r, c in zip(results, oracle, strict=True)]


def chunked_ratios(
    score: Callable[[Sequence[ValidationTrial], Sequence[float]], list[float]],
    trials: Sequence[ValidationTrial],
    oracle: Sequence[float],
    chunk: int,
    report: Callable[[float, int], None] | None = None,
) -> list[float]:
    """``score(trials, oracle)`` a ``chunk`` of trials at a time; after each chunk
    ``report(running geometric mean, trials scored)`` (it may raise to stop: pruning)."""
    ratios: list[float] = []
    for start in range(0, len(trials), chunk):
        part = slice(start, start + chunk)
        ratios += score(trials[part], oracle[part])
        if report is not None:
            report(geometric_mean(ratios), len(ratios))
    return ratios
