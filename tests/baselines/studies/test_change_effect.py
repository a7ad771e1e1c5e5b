"""Each change of the scenario matrix matters (docs/scenario-matrix.md): pid_los, a non-adaptive
controller, pays ≥ 1.3× per step after the change what it pays on the nominal twin over
the same time window, averaged over the first three leaderboard trials."""

from __future__ import annotations

import numpy as np
import pytest

from shipgym.scenarios.loader import load_scenario
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET, run_episode
from shipgym_baselines.registry import make_controller
from shipgym_baselines.studies.change_effect import (
    MATTERS,
    change_effect,
    change_time,
    matrix_scenarios,
    step_costs,
    twin,
)


def test_matrix_scenarios_are_the_three_ships_times_three_families_times_two_routes() -> None:
    names = matrix_scenarios()
    assert len(names) == 18 and len(set(names)) == 18
    assert "mariner_rudder_aging_curved" in names and "blanke_current_shift" in names


def test_episode_cost_is_minus_the_return_without_the_goal_bonus() -> None:
    """C = Σ step costs = −return + goal bonus (if reached): the corridor penalty stays in."""
    sc = load_scenario("blanke_rudder_aging")
    _, cost = step_costs(sc, "pid_los", EVAL_SEED_OFFSET)
    policy, mode = make_controller("pid_los")
    result = run_episode(policy, sc, EVAL_SEED_OFFSET, mode)
    assert result.metrics["termination_reason"] == "goal"
    assert cost.sum() == pytest.approx(-result.metrics["return"] + 10.0, rel=1e-12)
    assert np.all(cost >= 0.0)


def test_the_twin_has_no_change_and_the_same_route() -> None:
    sc = load_scenario("mariner_current_shift_curved")
    nominal = twin(sc)
    assert change_time(sc) == pytest.approx(89.4)
    assert change_time(nominal) is None and nominal.schedule.events == []
    assert nominal.config.path == sc.config.path
    assert nominal.config.initial_state == sc.config.initial_state


@pytest.mark.parametrize("name", matrix_scenarios())
def test_each_change_matters_to_a_non_adaptive_controller(name: str) -> None:
    """pid_los's paper design (pole-placed on the nominal model's Nomoto fit, never re-tuned:
    it applies to every ship) after the change vs on the twin."""
    effect = change_effect(name, "pid_los")
    assert effect.ratio >= MATTERS, effect.row()
