"""The evaluation trials env: given trials as rows, each row the single env's episode of its
trial and seed, bit for bit: observations, rewards, ends and every ``info`` key."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from shipgym.envs import row_tracking
from shipgym.envs.eval_trials import (
    EvaluationTrialsVectorEnv,
    LockstepError,
    RowInfosError,
    lockstep_problem,
)
from shipgym.envs.path_follow import ShipPathFollowEnv
from shipgym.scenarios.loader import Scenario, load_scenario

SEEDS = [10_000, 10_001, 10_002]


def _variants(name: str, extra: dict | None = None) -> list[Scenario]:
    """Three trials of ``name``: the start moved, the time limits apart (rows end apart);
    ``extra``: overrides of every trial (e.g. noisy sensors)."""
    base = load_scenario(name)
    start, limit = base.config.initial_state, base.config.time_limit
    return [
        base.with_overrides(
            {
                "initial_state": {"y": start.y + 3.0 * i, "heading_deg": 4.0 * i},
                "time_limit": limit * (1.0 - 0.2 * i),
                **(extra or {}),
            }
        )
        for i in range(len(SEEDS))
    ]


#: noisy heading and yaw-rate sensors with outliers and dropouts
NOISY = {
    "sensors": {
        "heading_noise_deg": 0.5,
        "yaw_rate_noise_deg_s": 0.05,
        "outlier_probability": 0.01,
        "dropout_probability": 0.02,
    }
}


def _assert_same(a: Any, b: Any, where: str) -> None:
    """Equal bit for bit: dicts key by key, arrays entry by entry, NaN equal to NaN."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), (where, a.keys(), b)
        for key in a:
            _assert_same(a[key], b[key], f"{where}.{key}")
    elif isinstance(a, np.ndarray | tuple | list):
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b), err_msg=where)
    elif isinstance(a, float) and np.isnan(a):
        assert isinstance(b, float) and np.isnan(b), where
    else:
        assert type(a) is type(b) and a == b, (where, a, b)


# heldout:8: nomoto2 with a parameter jump, a constant current and noisy heading sensors;
# heldout:6: the 3-DOF Mariner with a parameter jump, a current shift and noisy sensors
@pytest.mark.parametrize("name", ["heldout:8", "heldout:6"])
@pytest.mark.parametrize("mode", ["rudder", "guidance"])
def test_each_row_is_the_single_env_episode_of_its_trial(name: str, mode: str) -> None:
    _assert_rows_are_single_episodes(_variants(name), mode)


@pytest.fixture(params=["batched", "per_row", "to_scalar"])
def batching(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    """Every route group on one batched tracker, or on one scalar tracker per row, or on a
    batched tracker until fewer than 2 of its rows advance (then scalar trackers)."""
    least = {"batched": 1, "per_row": 10**6, "to_scalar": 2}[request.param]
    monkeypatch.setattr(row_tracking, "MIN_BATCHED_ROWS", {"polyline": least, "curve": least})
    return request.param


# a PCHIP curve with a parameter jump (Mariner), a polyline with a parameter jump (nomoto2)
# and a curve with a current shift (Blanke), with noisy sensors; the route groups batched
# and per row
@pytest.mark.parametrize(
    ("name", "mode"),
    [
        ("mariner_maneuverability_change_curved", "rudder"),
        ("mariner_maneuverability_change_curved", "guidance"),
        ("rudder_aging", "rudder"),
        ("blanke_current_shift_curved", "rudder"),  # a current shift: settled blocks kept
    ],
)
def test_rows_of_a_route_tracked_together_are_the_single_env_episodes(
    name: str, mode: str, batching: str
) -> None:
    trials = _variants(name, NOISY)
    env = _assert_rows_are_single_episodes(trials, mode, batched=batching != "per_row")
    if batching == "to_scalar":  # the last row went on alone, on a scalar tracker
        assert env._tracks.batched_rows == 0


@pytest.mark.parametrize("mode", ["rudder", "guidance"])
def test_rows_of_two_routes_are_the_single_env_episodes(mode: str, batching: str) -> None:
    """Two route groups in one env: the curve's trials and a polyline through the same
    waypoints (rows interleaved)."""
    curve = _variants("rudder_aging_smooth", NOISY)
    polyline = [t.with_overrides({"path": {"type": "waypoints"}}) for t in curve]
    trials = [curve[0], polyline[1], curve[2]]
    env = _assert_rows_are_single_episodes(trials, mode, batched=None, ends_apart=False)
    assert len(env._tracks.groups) == 2


def _assert_rows_are_single_episodes(
    trials: list[Scenario], mode: str, batched: bool | None = None, ends_apart: bool = True
) -> EvaluationTrialsVectorEnv:
    """Step the trials as rows and as single envs with the same small random actions:
    observations, rewards, ends and every info key equal, bit for bit (and the infos'
    values of the same Python types); ``ends_apart``: the rows end at different steps."""
    env = EvaluationTrialsVectorEnv(trials, SEEDS, action_mode=mode)
    singles = [ShipPathFollowEnv(t, action_mode=mode) for t in trials]
    obs, info = env.reset()
    if batched is not None:
        assert env._tracks.batched_rows == (len(SEEDS) if batched else 0)
    for i, single in enumerate(singles):
        o, inf = single.reset(seed=SEEDS[i])
        np.testing.assert_array_equal(obs[i], o)
        _assert_same(info["rows"][i], inf, f"reset row {i}")
    rng = np.random.default_rng(1)
    width = env.single_action_space.shape[0]
    ends = [0] * len(SEEDS)
    step = 0
    while not env.finished.all():
        step += 1
        # small actions around a steady course so that rows reach their goal or time limit
        action = (0.15 * rng.standard_normal((len(SEEDS), width))).astype(np.float32)
        live = ~env.finished
        obs, rew, term, trunc, info = env.step(action)
        for i, single in enumerate(singles):
            if not live[i]:
                assert info["rows"][i] is None and rew[i] == 0.0 and not (term[i] or trunc[i])
                continue
            o, r, te, tr, inf = single.step(action[i])
            np.testing.assert_array_equal(obs[i], o)
            assert (rew[i], term[i], trunc[i]) == (r, te, tr)
            _assert_same(info["rows"][i], inf, f"step {step} row {i}")
            if te or tr:
                assert "episode_metrics" in info["rows"][i]
                ends[i] = step
    assert len(set(ends)) == len(SEEDS) or not ends_apart  # the rows ended apart
    return env


def test_rows_of_different_ships_or_step_constants_are_refused() -> None:
    nomoto, mariner = load_scenario("rudder_aging"), load_scenario("mariner_rudder_aging")
    assert lockstep_problem([nomoto, nomoto]) is None
    assert "ship model" in lockstep_problem([nomoto, mariner])
    slower = nomoto.with_overrides({"control_period": 2 * nomoto.control_period})
    assert "control_period" in lockstep_problem([nomoto, slower])
    with pytest.raises(LockstepError, match="trial 1"):
        EvaluationTrialsVectorEnv([nomoto, mariner], [0, 1])
    with pytest.raises(ValueError, match="2 scenarios for 1 seeds"):
        EvaluationTrialsVectorEnv([nomoto, nomoto], [0])


def test_rows_without_samples_step_the_same() -> None:
    """``samples=False`` (a policy that reads observations only): the same observations,
    rewards, ends and infos bit for bit, without the ``samples`` key."""
    trials = _variants("rudder_aging")
    with_s = EvaluationTrialsVectorEnv(trials, SEEDS)
    without = EvaluationTrialsVectorEnv(trials, SEEDS, samples=False)
    obs_a, info_a = with_s.reset()
    obs_b, info_b = without.reset()
    np.testing.assert_array_equal(obs_a, obs_b)
    rng = np.random.default_rng(0)
    for _ in range(40):
        action = rng.uniform(-1.0, 1.0, size=with_s.action_space.shape)
        *out_a, info_a = with_s.step(action)
        *out_b, info_b = without.step(action)
        for a, b in zip(out_a, out_b, strict=True):
            np.testing.assert_array_equal(a, b)
        for row_a, row_b in zip(info_a["rows"], info_b["rows"], strict=True):
            if row_a is None:
                assert row_b is None
                continue
            assert "samples" in row_a and "samples" not in row_b
            _assert_same({k: v for k, v in row_a.items() if k != "samples"}, row_b, "info")


def test_row_infos_end_gives_the_last_info_and_the_trajectory() -> None:
    """``row_infos="end"``: the same observations, rewards and ends; a row's info only at
    its last step (the full env's, bit for bit); its trajectory (the infos' values at the
    reset and every step) from the env's columns."""
    trials = _variants("mariner_maneuverability_change_curved", NOISY)
    full = EvaluationTrialsVectorEnv(trials, SEEDS, samples=False)
    lean = EvaluationTrialsVectorEnv(trials, SEEDS, samples=False, row_infos="end")
    obs_a, info_a = full.reset()
    obs_b, info_b = lean.reset()
    np.testing.assert_array_equal(obs_a, obs_b)
    assert info_b["rows"] == [None] * len(SEEDS)
    rows = [[info] for info in info_a["rows"]]
    rng = np.random.default_rng(5)
    while not full.finished.all():
        action = 0.15 * rng.standard_normal(full.action_space.shape)
        *out_a, info_a = full.step(action)
        *out_b, info_b = lean.step(action)
        for a, b in zip(out_a, out_b, strict=True):
            np.testing.assert_array_equal(a, b)
        for i, (row_a, row_b) in enumerate(zip(info_a["rows"], info_b["rows"], strict=True)):
            if row_a is None:
                continue
            rows[i].append(row_a)
            if "termination_reason" in row_a:
                _assert_same(row_b, row_a, f"last info of row {i}")
            else:
                assert row_b is None
    assert lean.finished.all()
    for i, infos in enumerate(rows):
        trajectory = lean.trajectory(i)
        expected = {
            "t": [r["t"] for r in infos],
            "x": [r["position"][0] for r in infos],
            "y": [r["position"][1] for r in infos],
            "cross_track_error": [r["cross_track_error"] for r in infos],
            "heading": [r["heading"] for r in infos],
            "rudder_angle": [r["rudder_angle"] for r in infos],
            "rudder_command": [r["rudder_command"] for r in infos],
        }
        assert list(trajectory) == list(expected)
        for key, values in expected.items():
            assert trajectory[key].dtype == np.float64
            assert trajectory[key].tobytes() == np.array(values).tobytes(), (i, key)


def test_bad_row_infos_are_refused() -> None:
    trials = _variants("rudder_aging")
    with pytest.raises(RowInfosError, match="row_infos must be one of"):
        EvaluationTrialsVectorEnv(trials, SEEDS, samples=False, row_infos="last")
    with pytest.raises(RowInfosError, match="no samples"):
        EvaluationTrialsVectorEnv(trials, SEEDS, row_infos="end")


@pytest.mark.parametrize("mode", ["rudder", "guidance"])
def test_an_abandoned_row_is_the_single_env_episode_abandoned(mode: str) -> None:
    """Row 1 abandoned after 5 steps: its info, metrics and trajectory are the single env's
    abandoned at that step, bit for bit; the other rows step on as without it."""
    trials = _variants("heldout:8", NOISY)
    rng = np.random.default_rng(5)
    n_act = 1 if mode == "rudder" else 2
    actions = rng.uniform(-1.0, 1.0, size=(8, len(SEEDS), n_act))
    env = EvaluationTrialsVectorEnv(trials, SEEDS, mode)
    plain = EvaluationTrialsVectorEnv(trials, SEEDS, mode)
    env.reset()
    plain.reset()
    single = ShipPathFollowEnv(trials[1], action_mode=mode)
    single.reset(seed=SEEDS[1])
    for a in actions[:5]:
        env.step(a)
        plain.step(a)
        single.step(a[1])
    row = env.abandon(1, "controller_timeout")
    alone = single.abandon("controller_timeout")
    _assert_same(row, alone, "abandoned")
    assert row["termination_reason"] == "controller_timeout" and env.finished.tolist() == [
        False,
        True,
        False,
    ]
    trajectory = env.trajectory(1)
    assert trajectory["t"][-1] == alone["t"] and trajectory["t"].size == 7  # reset + 6
    with pytest.raises(ValueError, match="row 1 has finished"):
        env.abandon(1, "controller_error")
    for a in actions[5:]:
        obs, *_ = env.step(a)
        obs_plain, *_ = plain.step(a)
        np.testing.assert_array_equal(obs[[0, 2]], obs_plain[[0, 2]])
    for i in (0, 2):
        _assert_same(env.episode_metrics(i), plain.episode_metrics(i), f"row {i}")
