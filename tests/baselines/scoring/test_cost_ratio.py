"""The cost ratio C / C_oracle has one definition (:func:`~shipgym_baselines.scoring.scores.
cost_ratio`): the leaderboard, the tuner and model selection give the same numbers on the same
trials."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from shipgym_baselines.evaluation import evaluate
from shipgym_baselines.privileged import ORACLE
from shipgym_baselines.scoring.intervals import geometric_mean
from shipgym_baselines.scoring.scores import (
    FAILED_RATIO,
    cost_ratio,
    objective_ratio,
    scored_episodes,
)
from shipgym_baselines.training.selection import geometric_mean_ratio
from shipgym_baselines.tuning.objective import controller_ratios
from shipgym_baselines.tuning.validation import oracle_costs, validation_trials


@pytest.mark.parametrize(
    ("cost", "reference", "ratio"),
    [
        (3.0, 2.0, 1.5),
        (2.0, 2.0, 1.0),
        (math.inf, 2.0, None),  # a diverged episode has no ratio
        (math.nan, 2.0, None),
        (None, 2.0, None),
        (3.0, 0.0, None),  # a reference that costs nothing is no denominator
        (3.0, -1.0, None),
        (3.0, math.inf, None),
        (3.0, None, None),
    ],
)
def test_a_ratio_exists_only_for_finite_costs_over_a_positive_reference(
    cost: float | None, reference: float | None, ratio: float | None
) -> None:
    assert cost_ratio(cost, reference) == ratio
    assert objective_ratio(cost, reference) == (FAILED_RATIO if ratio is None else ratio)


def test_the_tuner_and_model_selection_score_the_leaderboards_ratios(tmp_path: Path) -> None:
    """On the same validation trials, the tuner's ratios are the leaderboard's
    ``cost_ratio`` of the same episodes, bit for bit; the objective and model selection's
    geometric mean are the geometric mean of those ratios."""
    trials = validation_trials(ship="nomoto2", per_ship=2)
    oracle = oracle_costs(trials, cache_dir=tmp_path)
    tuner = controller_ratios("pid_los", {}, trials, oracle)

    episodes = []
    for trial, c_oracle in zip(trials, oracle, strict=True):
        (result,) = evaluate("pid_los", trial.scenario, [trial.seed])
        for controller, cost in (("pid_los", result.metrics["cost"]), (ORACLE, c_oracle)):
            episodes.append(
                {
                    "scenario": trial.name,
                    "controller": controller,
                    "seed": trial.seed,
                    "cost": cost,
                    "termination_reason": "goal",
                }
            )
    board = [e["cost_ratio"] for e in scored_episodes(episodes) if e["controller"] == "pid_los"]

    assert tuner == board
    assert all(r is not None and r > 0 for r in board)
    costs = [e["cost"] for e in episodes if e["controller"] == "pid_los"]
    assert geometric_mean(tuner) == geometric_mean(board)
    assert geometric_mean_ratio(costs, oracle) == geometric_mean(board)


def test_model_selection_never_picks_a_checkpoint_with_a_diverged_episode() -> None:
    assert geometric_mean_ratio([2.0, 2000.0], [1.0, 1000.0]) == pytest.approx(2.0)
    assert geometric_mean_ratio([1.0, math.inf], [1.0, 1.0]) == math.inf
