"""``nmpc_ekf``: the oracle's NMPC on the filter's estimate.  It reads no truth, is the
oracle where the ship does not change, and recovers a change it was not told of."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import pytest

import shipgym  # noqa: F401  (registers the envs)
from shipgym.scenarios.loader import load_scenario
from shipgym_baselines.classical.nmpc_ekf import NmpcEkf
from shipgym_baselines.classical.oracle import OracleSettings
from shipgym_baselines.evaluation import evaluate, run_episode
from shipgym_baselines.registry import resolve_controller


def test_it_is_a_classical_competitor_of_the_nmpc_family() -> None:
    record = resolve_controller("nmpc_ekf")
    assert record.kind == "classical"
    assert NmpcEkf.kind == "classical"


def test_the_spies_see_no_read_of_the_truth(truth_calls: list[str]) -> None:
    """Neither the privileged channel nor the env's truth is called while it plays; the
    same spies see the oracle read both."""
    calls = truth_calls
    (result,) = evaluate("nmpc_ekf", "rudder_aging", seeds=[10_000])
    assert calls == []
    assert result.metrics["termination_reason"] == "goal"
    evaluate("oracle", "rudder_aging", seeds=[10_000])  # the spies work
    assert "reset_with_truth" in calls and "plant_truth" in calls


def test_where_nothing_changes_it_steers_as_the_oracle() -> None:
    """On nomoto2's nominal scenario (no change, no disturbance, exact sensors) the estimate
    is the nominal ship: with the oracle's solver settings the costs agree within 0.5 %,
    and its own one iteration a step stays within 2 % of the oracle's."""
    (oracle,) = evaluate("oracle", "nominal", seeds=[10_000])
    scenario = load_scenario("nominal")
    same = run_episode(NmpcEkf(settings=OracleSettings()), scenario, seed=10_000)
    assert same.metrics["cost"] == pytest.approx(oracle.metrics["cost"], rel=5e-3)
    (own,) = evaluate("nmpc_ekf", "nominal", seeds=[10_000])
    assert own.metrics["cost"] == pytest.approx(oracle.metrics["cost"], rel=2e-2)


def test_it_solves_one_iteration_a_step_by_default() -> None:
    """The real-time iteration: the default solver settings are the oracle's but for one
    Gauss–Newton iteration a control step."""
    assert NmpcEkf().settings == dataclasses.replace(OracleSettings(), max_iter=1)


def test_it_finds_the_aged_servo_it_was_not_told_of() -> None:
    """``rudder_aging``: Tc 0.1 s → 1.0 s at t = 12 s.  At the episode's end the servo's
    estimate is ×10 (0.02 in ln), the other quantities near the nominal ship (0.1)."""
    policy = NmpcEkf(preset="default")
    run_episode(policy, load_scenario("rudder_aging"), seed=10_000)
    names = policy.ekf.adaptation.names
    final = dict(zip(names, policy.estimates[-1], strict=True))
    assert final["servo"] == pytest.approx(math.log(10.0), abs=0.02)
    for name in names:
        if name != "servo":
            assert abs(final[name]) < 0.1, name


@pytest.mark.parametrize(
    ("settings", "match"),
    [
        ({"parameter_walk": -1.0}, "parameter_walk"),
        ({"process_noise": 1.0}, "no setting"),
        ({"servo": "guess"}, "servo"),
    ],
)
def test_bad_settings_are_refused_at_construction(settings: dict[str, Any], match: str) -> None:
    with pytest.raises(ValueError, match=match):
        NmpcEkf(**settings)


def test_the_solvers_objective_is_never_read_at_another_parameter_vector() -> None:
    """The objective of a plan just evaluated is reused only at the same parameters: after
    ``solve`` with new parameters, the first objective of the same plan is the one computed
    afresh (a stale value would be the line search's reference)."""
    import numpy as np

    from shipgym_baselines.classical.oracle import get_solver

    policy = NmpcEkf(preset="default")
    run_episode(policy, load_scenario("rudder_aging"), seed=10_000)
    solver = get_solver(policy.ctx, policy.settings, policy.weights)
    p1 = solver._p.copy()
    p2 = p1.copy()
    p2[1] += 0.5  # another state: the ship half a metre to the side
    plan = np.zeros(solver.n_u)
    solver.cost(plan, p1)
    firsts: list[float] = []
    cost = solver.cost
    solver.cost = lambda u, p: firsts.append(cost(u, p)) or firsts[-1]  # type: ignore[method-assign]
    try:
        solver.solve(p2, plan)
    finally:
        del solver.cost
    solver._fresh = False
    assert firsts[0] == solver.cost(plan, p2) != solver.cost(plan, p1)
