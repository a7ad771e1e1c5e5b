"""The objective of every study: the cost ratio to the oracle on the validation trials.

Per trial, the ratio C / C_oracle of the episode cost (the leaderboard's ``cost``: the
step costs and any corridor penalty) to the oracle's cost on the same trial
(:mod:`~shipgym_baselines.tuning.validation`); the objective is their geometric mean over
the trials (1 = as good as the oracle, lower is better), as the leaderboard's
``cost_ratio_gmean``.  An episode whose cost is not finite counts as
:data:`FAILED_RATIO`.  :func:`chunked_ratios` scores the trials a chunk at a time and
hands the running geometric mean to ``report`` after each chunk (the pruner's
intermediate values).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from shipgym_baselines.plugins import ControllerEntry
from shipgym_baselines.tuning.validation import ValidationTrial

#: the ratio of an episode with a non-finite cost (a diverged simulation)
FAILED_RATIO = 1.0e6


def geometric_mean(ratios: Sequence[float]) -> float:
    """exp(mean(log r)) of positive ratios [–]."""
    values = np.asarray(ratios, dtype=float)
    if values.size == 0 or np.any(values <= 0):
        raise ValueError(f"a geometric mean needs positive ratios, got {list(values)}")
    return float(np.exp(np.mean(np.log(values))))


def cost_ratio(cost: Any, oracle_cost: float) -> float:
    """C / C_oracle of one episode (:data:`FAILED_RATIO` when C is not finite)."""
    value = float(cost)
    if not math.isfinite(value):
        return FAILED_RATIO
    return max(value, 1e-12) / oracle_cost


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
    return [cost_ratio(r.metrics.get("cost"), c) for r, c in zip(results, oracle, strict=True)]


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
