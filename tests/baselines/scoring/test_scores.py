"""Each episode's score: failures, the (runs, tasks) matrix and the scenarios a controller
is rated on (the cost ratio itself: test_ranking.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym_baselines.scoring.scores import (
    is_failure,
    ranked_scenarios,
    rated_scenarios,
    refused_trials,
    run_matrix,
    scored_episodes,
)


@pytest.mark.parametrize(
    ("episode", "failed"),
    [
        ({"termination_reason": "goal", "cost": 3.0}, False),
        ({"termination_reason": "corridor", "cost": 3.0}, True),
        ({"termination_reason": "controller_timeout", "cost": 3.0}, True),
        ({"termination_reason": "goal", "cost": math.inf}, True),
        ({"termination_reason": "goal", "cost": None}, True),
    ],
)
def test_a_failure_ends_badly_or_has_no_finite_cost(episode: dict, failed: bool) -> None:
    assert is_failure(episode) is failed


def _episode(scenario: str, controller: str, seed: int, cost: float, training_seed=None) -> dict:
    return {
        "scenario": scenario,
        "controller": controller,
        "seed": seed,
        "training_seed": training_seed,
        "cost": cost,
        "termination_reason": "goal",
    }


def test_the_run_matrix_has_a_row_per_run_and_a_column_per_scenario() -> None:
    eps = [_episode(s, "oracle", seed, 10.0) for s in ("a", "b") for seed in (1, 2)]
    eps += [_episode("a", "x", seed, 10.0 * seed, t) for seed in (1, 2) for t in (0, 1)]
    eps += [_episode("b", "x", seed, 30.0, t) for seed in (1, 2) for t in (0, 1)]
    scored = scored_episodes(eps)
    matrix = run_matrix(scored, "x", ["a", "b"])
    # runs ordered (training seed, evaluation seed): (0, 1), (0, 2), (1, 1), (1, 2)
    np.testing.assert_allclose(matrix, [[1.0, 3.0], [2.0, 3.0], [1.0, 3.0], [2.0, 3.0]])
    with pytest.raises(ValueError, match="every scenario needs the same seeds"):
        run_matrix([e for e in scored if e["seed"] != 2 or e["scenario"] != "b"], "x", ["a", "b"])


def test_a_controller_is_rated_where_every_episode_has_a_cost_ratio() -> None:
    eps = [_episode(s, "oracle", 1, 10.0) for s in ("a", "b", "c")]
    eps += [_episode("a", "x", 1, 12.0), _episode("b", "x", 1, math.nan)]
    scored = scored_episodes(eps)
    assert rated_scenarios(scored, "x", {"a", "b", "c"}) == ["a"]
    assert ranked_scenarios(scored, ["c", "a"]) == ["a", "c"]


def test_a_trial_whose_oracle_episode_failed_is_not_scored() -> None:
    """The oracle timed out on seed 1 (a penalty cost of 1400): no episode of that trial
    gets a cost ratio, the scenario is ranked on no controller, and one line names it."""
    timed_out = {
        **_episode("s", "oracle", 1, 1400.0),
        "termination_reason": "controller_timeout",
        "error": "the call ran 0.01 s of CPU time, over the limit of 0.002 s",
    }
    episodes = [
        {**_episode("s", "oracle", 0, 20.0), "termination_reason": "goal"},
        timed_out,
        {**_episode("s", "pid_los", 0, 160.0), "termination_reason": "goal"},
        {**_episode("s", "pid_los", 1, 180.0), "termination_reason": "goal"},
    ]
    scored = {(e["controller"], e["seed"]): e["cost_ratio"] for e in scored_episodes(episodes)}
    assert scored == {
        ("oracle", 0): 1.0,
        ("oracle", 1): None,
        ("pid_los", 0): 8.0,
        ("pid_los", 1): None,
    }
    assert ranked_scenarios(scored_episodes(episodes), ["s"]) == []
    assert refused_trials(episodes) == [
        "shipgym: oracle on s seed 1 ended controller_timeout (the call ran 0.01 s of CPU "
        "time, over the limit of 0.002 s) with cost 1400: that trial is not scored"
    ]
