"""The step core: reward, termination and observation as closed forms (docs/environment.md)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from shipgym.envs import core
from shipgym.envs.path_follow import ShipPathFollowEnv
from shipgym.envs.vector import ShipPathFollowVectorEnv
from shipgym.numerics import ARRAY, SCALAR
from shipgym.scenarios.loader import load_scenario
from shipgym.tracking import TrackFrame

K = core.StepConstants.of(load_scenario("nominal"))


def frame(e: float = 0.0, at_goal: bool = False, angle: float = 0.0) -> TrackFrame:
    return TrackFrame(e, angle, 0.0, 0, 0.5 * math.pi, 10.0 * K.ship_length, at_goal)


def test_constants_read_the_scenario() -> None:
    sc = load_scenario("nominal")
    assert K.max_steps == math.ceil(sc.config.time_limit / sc.control_period)
    assert K.substeps * K.fine_step == pytest.approx(K.control_period)
    assert K.max_cross_track == pytest.approx(10 * K.ship_length)


def test_reward_is_the_weighted_sum_of_spec_5() -> None:
    e, psi, dc, prev = 0.3, -0.2, 0.1, -0.05
    want = -(
        abs(e) / K.ship_length
        + K.heading_weight * abs(psi)
        + K.rudder_weight * (dc / K.rudder_limit) ** 2
        + K.rudder_rate_weight * ((dc - prev) / K.rudder_limit) ** 2
    )
    assert core.step_reward(e, psi, dc, prev, K, SCALAR) == pytest.approx(want, rel=1e-15)
    batched = core.step_reward(np.array([e, 0.0]), np.array([psi, 0.0]), dc, prev, K, ARRAY)
    assert batched[0] == core.step_reward(e, psi, dc, prev, K, SCALAR)


def test_leaving_the_corridor_costs_staying_at_its_edge_for_the_rest() -> None:
    steps = 10
    reward, goal, corridor, truncated = core.terminate(
        -1.0, frame(e=K.max_cross_track * 1.01), steps, K, SCALAR
    )
    assert corridor and not goal and not truncated
    left = K.max_steps - steps
    assert reward == pytest.approx(-1.0 - (K.max_cross_track / K.ship_length) * left)
    # the penalty is never smaller than what staying at the edge would have cost
    assert -reward >= (K.max_cross_track / K.ship_length) * left
    assert core.diverged_reward(steps, K) == pytest.approx(
        -(K.max_cross_track / K.ship_length) * (left + 1)
    )


def test_goal_bonus_and_time_limit() -> None:
    reward, goal, corridor, truncated = core.terminate(-1.0, frame(at_goal=True), 5, K, SCALAR)
    assert goal and not corridor and not truncated and reward == -1.0 + K.goal_bonus
    *_, truncated = core.terminate(-1.0, frame(), K.max_steps, K, SCALAR)
    assert truncated
    *_, truncated = core.terminate(-1.0, frame(), K.max_steps - 1, K, SCALAR)
    assert not truncated


def test_observation_columns_are_the_documented_scalings() -> None:
    obs = core.observation_columns(frame(e=0.5), 0.25, 0.01, 0.1, -0.2, 1.1, K, SCALAR)
    assert len(obs) == len(core.OBS_NAMES)
    assert obs[0] == 0.5 / K.max_cross_track
    assert (obs[1], obs[2]) == (math.sin(0.25), math.cos(0.25))
    assert obs[3] == 0.01 / (2 * K.nominal_speed / K.ship_length)
    assert (obs[4], obs[5]) == (0.1 / K.rudder_limit, -0.2 / K.rudder_limit)
    assert obs[6] == 1.1 / K.nominal_speed
    assert obs[7] == 0.5 and obs[8] == pytest.approx(0.5)


def test_transition_returns_a_new_state_and_never_writes_the_one_it_is_given() -> None:
    """One control period is a function of the state: the envs' old states stay as they
    were (noisy sensors, whose measurements are written per row, included)."""
    single = ShipPathFollowEnv("maneuverability_change")
    batched = ShipPathFollowVectorEnv(3, "maneuverability_change")
    single.reset(seed=0)
    batched.reset(seed=0)
    for env, action in ((single, np.full(1, 0.5)), (batched, np.full((3, 1), 0.5))):
        before = env._state
        kept = {f.name: np.copy(getattr(before, f.name)) for f in dataclasses.fields(before)}
        for _ in range(5):
            env.step(action.astype(np.float32))
        assert env._state is not before
        for name, value in kept.items():
            np.testing.assert_array_equal(getattr(before, name), value, err_msg=name)


def test_period_reasons_of_one_ship_and_of_rows_agree() -> None:
    ends = [(True, False, False, False), (False, True, False, False), (False, False, True, False)]
    ends += [(False, False, False, True), (False, False, False, False)]
    flags = np.array(ends).T
    rows = core.Period(frame(), np.zeros(5), np.zeros(5), *flags)
    singles = [core.Period(frame(), 0.0, 0.0, *end).reasons() for end in ends]
    want = ["goal", "corridor", "non_finite_state", "time_limit", None]
    assert rows.reasons().tolist() == singles == want
