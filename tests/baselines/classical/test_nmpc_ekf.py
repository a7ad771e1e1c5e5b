"""``nmpc_ekf``: the oracle's NMPC on the filter's estimate.  It reads no truth, is the
oracle where the ship does not change, and recovers a change it was not told of."""

from __future__ import annotations

import dataclasses
import math

import pytest

import shipgym  # noqa: F401  (registers the envs)
from shipgym.scenarios import load_scenario
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


def test_bad_settings_are_refused_at_construction() -> None:
    with pytest.raises(ValueError, match="parameter_walk"):
        NmpcEkf(parameter_walk=-1.0)
    with pytest.raises(ValueError, match="no setting"):
        NmpcEkf(process_noise=1.0)
    with pytest.raises(ValueError, match="servo"):
        NmpcEkf(servo="guess")
