"""Tests of shipgym.metrics on hand-made episode logs."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from shipgym.metrics import EpisodeLog, MetricSettings, aggregate, compute_metrics

DT = 0.5  # s, control period of nomoto2 (Liu et al. 2019)
L = 0.95  # m


def make_log(
    e: np.ndarray,
    *,
    dt: float = DT,
    change_time: float | None = None,
    heading_error: np.ndarray | None = None,
    rudder_angle: np.ndarray | None = None,
    rudder_command: np.ndarray | None = None,
    reward: np.ndarray | None = None,
    ship_length: float = L,
    reached_goal: bool = False,
    goal_bonus: float = 0.0,
) -> EpisodeLog:
    e = np.asarray(e, dtype=float)
    n = e.size
    zeros = np.zeros(n)
    return EpisodeLog(
        t=dt * np.arange(1, n + 1),
        cross_track_error=e,
        heading_error=zeros if heading_error is None else heading_error,
        rudder_angle=zeros if rudder_angle is None else rudder_angle,
        rudder_command=zeros if rudder_command is None else rudder_command,
        reward=zeros if reward is None else reward,
        change_time=change_time,
        ship_length=ship_length,
        reached_goal=reached_goal,
        goal_bonus=goal_bonus,
        dt=dt,
    )


def test_ace_counts_only_steps_after_change() -> None:
    # t = 0.5, 1.0, ..., 10.0; change at 5.0 s. Steps with t <= 5 (10 steps) have |e| = 1,
    # the 10 steps after alternate +2, -4 → mean |e| after = 3 m; whole episode would be 2 m.
    t = DT * np.arange(1, 21)
    e = np.where(t <= 5.0, 1.0, np.where(np.arange(20) % 2 == 0, 2.0, -4.0))
    m = compute_metrics(make_log(e, change_time=5.0))
    assert m["ace"] == pytest.approx(3.0)
    assert m["ace_L"] == pytest.approx(3.0 / L)
    assert m["mean_abs_cross_track"] == pytest.approx(2.0)


def test_ace_step_exactly_at_change_is_excluded() -> None:
    # Sample at t = 1.0 == change_time is not "after" the change (strictly t > change_time).
    m = compute_metrics(make_log([9.0, 9.0, 1.0, 3.0], change_time=1.0))
    assert m["ace"] == pytest.approx(2.0)


def test_ace_whole_episode_without_change() -> None:
    m = compute_metrics(make_log([1.0, -2.0, 3.0, -6.0]))
    assert m["ace"] == pytest.approx(3.0)
    assert m["t_c_after_change"] == m["t_c"]


def test_ace_nan_when_no_step_after_change() -> None:
    m = compute_metrics(make_log([0.1, 0.2], change_time=5.0))
    assert math.isnan(m["ace"])
    assert math.isnan(m["t_c"])


def test_t_c_exponential_decay_matches_analytic_crossing() -> None:
    # e = 0.5 m until the change at 12 s, then e = 0.5·exp(-(t-12)/τ): crosses 0.05 m at
    # t* = 12 + τ·ln(10). The first sample below lies in (t*, t* + dt].
    tau, tch = 4.0, 12.0
    t = DT * np.arange(1, 121)
    e = np.where(t <= tch, 0.5, 0.5 * np.exp(-(t - tch) / tau))
    m = compute_metrics(make_log(e, change_time=tch))
    t_star = tch + tau * math.log(10.0)
    assert m["convergence_threshold"] == pytest.approx(0.05)
    assert t_star < m["t_c"] <= t_star + DT
    assert m["t_c_after_change"] == pytest.approx(m["t_c"] - tch)


def test_t_c_inf_when_error_ends_above_threshold() -> None:
    e = np.r_[np.full(10, 0.01), np.full(5, 0.2)]
    m = compute_metrics(make_log(e, change_time=1.0))
    assert m["t_c"] == math.inf
    assert m["t_c_after_change"] == math.inf
    json.dumps(m)  # inf/NaN serialise (as Infinity/NaN) with the default encoder


def test_t_c_ignores_early_dip() -> None:
    # Above, dip below (t = 2.0, 2.5), rise above again (t = 3.0 .. 4.0), then below to the end.
    e = [0.3, 0.3, 0.3, 0.01, 0.01, 0.2, 0.2, 0.2, 0.01, 0.02, 0.03]
    m = compute_metrics(make_log(e, change_time=0.5))
    assert m["t_c"] == pytest.approx(4.5)
    assert m["t_c_after_change"] == pytest.approx(4.0)


def test_t_c_searches_from_change_and_is_absolute_time() -> None:
    # Already below at the change (t = 6 s) and stays below: t_c is the change-time sample.
    e = np.r_[np.full(11, 1.0), np.full(10, 0.0)]
    m = compute_metrics(make_log(e, change_time=6.0))
    assert m["t_c"] == pytest.approx(6.0)
    assert m["t_c_after_change"] == pytest.approx(0.0)


def test_j_of_constant_error() -> None:
    e0, n = 3.0, 40
    s = MetricSettings()
    m = compute_metrics(make_log(np.full(n, e0)), s)
    T = n * DT
    assert m["duration"] == pytest.approx(T)
    assert m["J"] == pytest.approx(s.lambda_y * e0**2 * T)


def test_j_weights_heading_and_rudder() -> None:
    n = 10
    log = make_log(np.zeros(n), heading_error=np.full(n, 0.1), rudder_angle=np.full(n, -0.2))
    m = compute_metrics(log, MetricSettings(lambda_psi=2.0, lambda_delta=3.0))
    assert m["J"] == pytest.approx((2.0 * 0.01 + 3.0 * 0.04) * n * DT)


def test_rudder_travel_of_square_wave() -> None:
    # ±0.1 rad square wave with half-period 3 steps over 12 steps: 3 flips of 0.2 rad.
    delta = 0.1 * np.r_[np.ones(3), -np.ones(3), np.ones(3), -np.ones(3)]
    cmd = 0.3 * np.r_[np.ones(6), -np.ones(6)]
    m = compute_metrics(make_log(np.zeros(12), rudder_angle=delta, rudder_command=cmd))
    assert m["rudder_travel"] == pytest.approx(0.6)
    assert m["rudder_command_travel"] == pytest.approx(0.6)
    assert m["mean_abs_rudder"] == pytest.approx(0.1)
    assert m["std_abs_rudder"] == pytest.approx(0.0)


def test_statistics_return_success_and_no_wall_clock() -> None:
    e = np.array([1.0, -3.0])
    log = make_log(
        e,
        heading_error=np.array([0.2, -0.4]),
        reward=np.array([-1.0, -2.5]),
        reached_goal=True,
    )
    m = compute_metrics(log)
    assert m["std_abs_cross_track"] == pytest.approx(1.0)  # population std of {1, 3}
    assert m["max_abs_cross_track"] == pytest.approx(3.0)
    assert m["mean_abs_heading_error"] == pytest.approx(0.3)
    assert m["std_abs_heading_error"] == pytest.approx(0.1)
    assert m["return"] == pytest.approx(-3.5)
    assert m["success"] is True
    assert m["steps"] == 2
    assert not any(key.startswith("compute") for key in m)  # the evaluation loop times
    assert all(isinstance(v, float | bool | int) for v in m.values())


def test_cost_is_the_return_without_the_goal_bonus() -> None:
    """C = −(Σ reward − bonus): the bonus in the last step's reward is left out, only when
    the goal was reached."""
    reward = np.array([-1.0, -2.5, 10.0 - 0.5])  # the last step: its cost 0.5 and the bonus
    reached = compute_metrics(
        make_log(np.zeros(3), reward=reward, reached_goal=True, goal_bonus=10.0)
    )
    assert reached["cost"] == pytest.approx(4.0) and reached["return"] == pytest.approx(6.0)
    missed = compute_metrics(
        make_log(np.zeros(3), reward=reward - 10.0 * (reward > 5), goal_bonus=10.0)
    )
    assert missed["cost"] == pytest.approx(4.0) and missed["return"] == pytest.approx(-4.0)
    assert compute_metrics(make_log(np.zeros(2)))["cost"] == 0.0  # not −0.0
    with pytest.raises(ValueError, match="goal_bonus"):
        make_log(np.zeros(2), goal_bonus=math.inf)


def test_default_threshold_liu_scaling() -> None:
    s = MetricSettings()
    assert s.convergence_threshold is None
    assert s.threshold(0.95) == pytest.approx(0.05)
    assert s.threshold(1.9) == pytest.approx(0.10)
    assert MetricSettings(convergence_threshold=0.3).threshold(0.95) == 0.3
    assert (s.lambda_y, s.lambda_psi, s.lambda_delta) == (1 / 2000, 1.0, 5.0)


def test_from_records_builds_arrays_and_ignores_extra_keys() -> None:
    records = [
        {
            "t": 0.5 * (k + 1),
            "cross_track_error": 0.1 * k,
            "heading_error": 0.0,
            "rudder_angle": 0.0,
            "rudder_command": 0.0,
            "reward": -1.0,
            "position": (k, 0.0),
        }
        for k in range(4)
    ]
    log = EpisodeLog.from_records(records, ship_length=L, dt=DT, change_time=1.0)
    assert log.cross_track_error.dtype == np.float64
    assert np.allclose(log.cross_track_error, [0.0, 0.1, 0.2, 0.3])
    assert compute_metrics(log)["ace"] == pytest.approx(0.25)


def test_from_records_missing_key_names_field() -> None:
    records = [{"t": 0.5, "cross_track_error": 0.0, "heading_error": 0.0, "rudder_angle": 0.0}]
    with pytest.raises(ValueError, match="rudder_command"):
        EpisodeLog.from_records(records, ship_length=L, dt=DT)


def test_empty_log_raises() -> None:
    with pytest.raises(ValueError, match="empty"):
        make_log(np.zeros(0))
    with pytest.raises(ValueError, match="empty"):
        EpisodeLog.from_records([], ship_length=L, dt=DT)


def test_unequal_lengths_raise_naming_field() -> None:
    with pytest.raises(ValueError, match="heading_error"):
        make_log(np.zeros(5), heading_error=np.zeros(4))


@pytest.mark.parametrize("name", ["cross_track_error", "heading_error", "rudder_angle"])
def test_nan_in_error_arrays_raises_naming_field(name: str) -> None:
    bad = np.zeros(5)
    bad[2] = np.nan
    kwargs = {"heading_error": None, "rudder_angle": None}
    if name == "cross_track_error":
        with pytest.raises(ValueError, match=name):
            make_log(bad)
    else:
        kwargs[name] = bad
        with pytest.raises(ValueError, match=name):
            make_log(np.zeros(5), **kwargs)


def test_nan_inserted_after_construction_is_caught() -> None:
    log = make_log(np.zeros(3))
    log.cross_track_error[1] = np.nan
    with pytest.raises(ValueError, match="cross_track_error"):
        compute_metrics(log)


def test_aggregate_mean_std_nan_and_inf() -> None:
    rows = [
        {"ace": 1.0, "t_c": 30.0, "J": math.nan, "success": True},
        {"ace": 3.0, "t_c": math.inf, "J": 2.0, "success": False},
        {"ace": math.nan, "t_c": 34.0, "J": 4.0, "success": True},
        {"ace": 2.0, "t_c": 32.0, "J": None, "success": True},
    ]
    agg = aggregate(rows, ["ace", "t_c", "J", "success"])
    assert agg["n"] == 4
    assert agg["ace"] == pytest.approx(2.0)  # NaN ignored
    assert agg["ace_std"] == pytest.approx(math.sqrt(2.0 / 3.0))  # ddof = 0
    assert agg["t_c"] == math.inf  # one seed never converged
    assert math.isnan(agg["t_c_std"])
    assert agg["J"] == pytest.approx(3.0)
    assert agg["J_std"] == pytest.approx(1.0)
    assert agg["success"] == pytest.approx(0.75)
    assert agg["success_std"] == pytest.approx(math.sqrt(0.75 * 0.25))


def test_aggregate_all_nan_and_default_keys() -> None:
    rows = [compute_metrics(make_log([0.1, 0.2], change_time=5.0)) for _ in range(3)]
    agg = aggregate(rows)
    assert math.isnan(agg["ace"]) and math.isnan(agg["ace_std"])
    assert agg["steps"] == pytest.approx(2.0)
    assert agg["steps_std"] == pytest.approx(0.0)
    with pytest.raises(ValueError):
        aggregate([])
    with pytest.raises(ValueError, match="'ace'"):
        aggregate([{"J": 1.0}], ["ace"])
