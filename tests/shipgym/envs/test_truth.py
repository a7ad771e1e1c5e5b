"""The env's privileged truth (``plant_truth``): what only the oracle reference reads."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import shipgym  # noqa: F401  (registers the envs)
from shipgym.scenarios.loader import load_scenario


def _run_to(env: gym.Env, t: float) -> None:
    while env.unwrapped.time < t - 1e-9:
        env.step(np.zeros(1, dtype=np.float32))


def test_the_truth_carries_the_parameters_acting_now_never_the_schedule() -> None:
    """Before a jump the truth is the nominal record; after it, the jumped one."""
    sc = load_scenario("maneuverability_change")
    (event,) = sc.config.events
    env = gym.make("ShipPathFollow-v0", scenario=sc)
    env.reset(seed=0)
    before = env.unwrapped.plant_truth()
    assert before.params == sc.nominal_params
    assert before.t == 0.0
    _run_to(env, event.time + 1.0)
    after = env.unwrapped.plant_truth()
    assert after.params == sc.schedule.record_at(after.t)
    assert after.params != sc.nominal_params
    assert np.array_equal(after.state, env.unwrapped._state.x)
    after.state[0] += 1.0  # a copy: the oracle cannot move the plant
    assert not np.array_equal(after.state, env.unwrapped._state.x)


def test_the_truth_is_causal_it_holds_the_current_now_never_the_switch_ahead() -> None:
    """A two-phase current (calm, then 0.5 m/s from 150 s, no fluctuation): before the
    switch the truth's disturbance is the calm row and it carries nothing of the switch
    ahead (its fields are the plant now); after it, the 0.5 m/s current."""
    import dataclasses

    env = gym.make("ShipPathFollow-v0", scenario="blanke_current_shift", randomize=False)
    env.reset(seed=0)
    dist = env.unwrapped._disturbances
    truth = env.unwrapped.plant_truth()
    assert [f.name for f in dataclasses.fields(truth)] == [
        "t",
        "state",
        "params",
        "disturbance_now",
        "wave_now",
    ]
    assert np.allclose(truth.disturbance_now, dist.constant_row())
    _run_to(env, 149.0)
    assert np.hypot(*env.unwrapped.plant_truth().disturbance_now[:2]) == pytest.approx(0.0)
    _run_to(env, 200.0)
    late = env.unwrapped.plant_truth()
    assert np.hypot(*late.disturbance_now[:2]) == pytest.approx(0.5)


def test_the_truth_separates_the_wave_load_now() -> None:
    """On a sea with waves (mariner_track, no current) the yaw disturbance acting now is
    the wave load: ``wave_now`` is all of it, and nothing is left without the waves; on a
    calm sea ``wave_now`` is zero."""
    env = gym.make("ShipPathFollow-v0", scenario="mariner_track")
    env.reset(seed=0)
    _run_to(env, 20.0)
    truth = env.unwrapped.plant_truth()
    yaw = env.unwrapped.model.disturbance_names.index("yaw_disturbance")
    assert truth.disturbance_now[yaw] != 0.0
    assert np.array_equal(truth.wave_now, truth.disturbance_now)
    assert not np.any(truth.without_waves)
    calm = gym.make("ShipPathFollow-v0", scenario="blanke_current_shift")
    calm.reset(seed=0)
    _run_to(calm, 20.0)
    assert not np.any(calm.unwrapped.plant_truth().wave_now)
