"""The evaluation loop: what a policy sees and what the loop measures."""

from __future__ import annotations

import math
import re
import threading
import time
from typing import Any

import numpy as np
import pytest

from shipgym.scenarios.loader import Scenario, load_scenario
from shipgym_baselines import evaluation
from shipgym_baselines.classical.pid import PIDLOS
from shipgym_baselines.classical.reference import ZeroRudder
from shipgym_baselines.errors import ControllerError, RunError
from shipgym_baselines.evaluation import (
    ERROR_CHARS,
    EVAL_SEED_OFFSET,
    ActGuard,
    compute_time_metrics,
    error_line,
    evaluate,
    evaluate_batch,
    run_episode,
)
from shipgym_baselines.records.episodes import EpisodeLabel, EpisodeResult
from shipgym_baselines.registry import make_controller, register_controller, training_seeds

SLEEP_S = 0.002


class SleepyZero(ZeroRudder):
    """Zero rudder that spends ``SLEEP_S`` in every ``act`` (not a registered controller)."""

    name = "sleepy_zero"

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        time.sleep(SLEEP_S)
        return super().act(obs, info)


def _same(a: Any, b: Any) -> bool:
    """Equal, with NaN equal to NaN (t_c of an episode without a change is NaN)."""
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


def test_compute_time_metrics_are_mean_and_max_in_ms() -> None:
    assert compute_time_metrics([0.001, 0.003]) == pytest.approx(
        {"compute_ms": 2.0, "compute_ms_max": 3.0}
    )


def test_compute_ms_is_the_time_spent_in_act() -> None:
    """A policy sleeping 2 ms per act() shows ≥ 2 ms per step; the same actions without the
    sleep show less (the loop times act(), nothing else)."""
    sleepy = run_episode(SleepyZero(), "nominal", seed=0)
    quick = run_episode(ZeroRudder(), "nominal", seed=0)
    m = sleepy.metrics
    assert m["compute_ms"] >= 1e3 * SLEEP_S
    assert m["compute_ms_max"] >= m["compute_ms"]
    assert quick.metrics["compute_ms"] < m["compute_ms"]
    # the sleep changes nothing else
    for key in m:
        if not key.startswith("compute_ms"):
            assert _same(m[key], quick.metrics[key]), key


def test_same_seed_gives_the_same_metrics_apart_from_compute_time() -> None:
    """Two runs of one seed (random rudder and sensor noise on a stochastic scenario)."""
    a, b = evaluate("random", "osaka_stochastic_current", seeds=[7, 7])
    assert a.metrics.keys() == b.metrics.keys()
    differ = [k for k in a.metrics if not _same(a.metrics[k], b.metrics[k])]
    assert all(k.startswith("compute_ms") for k in differ), differ
    for key, values in a.trajectory.items():
        np.testing.assert_array_equal(values, b.trajectory[key], err_msg=key)
    (c,) = evaluate("random", "osaka_stochastic_current", seeds=[8])
    assert c.metrics["ace"] != a.metrics["ace"]  # the seed does matter


def test_pid_los_sees_no_truth() -> None:
    """The controller context carries the nominal model only, not the post-event parameters."""
    policy = PIDLOS()
    result = run_episode(policy, "rudder_aging", seed=0)
    assert policy.ctx.nominal_params.Tc == pytest.approx(0.1)
    assert not hasattr(policy.ctx, "schedule")
    assert result.metrics["steps"] > 0


def test_a_policy_instance_runs_in_its_own_action_mode() -> None:
    """Without an ``action_mode`` the loop makes the env in the policy's (zero action in
    guidance mode is the env's PID LOS: it reaches the goal)."""
    policy = ZeroRudder()
    policy.action_mode = "guidance"
    (result,) = evaluate(policy, "nominal", seeds=[0])
    assert result.metrics["termination_reason"] == "goal"
    (rudder,) = evaluate(ZeroRudder(), "nominal", seeds=[0])
    assert rudder.metrics["termination_reason"] != "goal"


# --------------------------------------------------------------------- batched evaluation

SHIPPED = ("ppo", "sac", "td3", "recurrent_ppo", "ppo_guidance")


def _trials(scenario: str, n: int) -> list[Scenario]:
    """``n`` trial variants of ``scenario``, one per seed: the start moved across the path,
    and time limits that differ (the episodes end at different steps: the goal, the limits)."""
    base = load_scenario(scenario)
    start, limit = base.config.initial_state, base.config.time_limit
    return [
        base.with_overrides(
            {
                "initial_state": {"y": start.y + 0.4 * i, "heading_deg": 5.0 * i},
                "time_limit": limit / (1 + i),
            }
        )
        for i in range(n)
    ]


#: metrics that are times measured on the machine (the controller's act, its solver)
TIMINGS = ("compute_ms", "solve_ms")


def _untimed(metrics: dict[str, Any]) -> dict[str, Any]:
    """The metrics and the controller's figures (as ``controller_stats.<name>``) but the
    measured times."""
    figures = metrics.get("controller_stats", {})
    flat = {k: v for k, v in metrics.items() if k != "controller_stats"}
    flat |= {f"controller_stats.{k}": v for k, v in figures.items()}
    return {k: v for k, v in flat.items() if not k.rpartition(".")[2].startswith(TIMINGS)}


def _assert_same_episodes(batched: list[EpisodeResult], one_by_one: list[EpisodeResult]) -> None:
    """Equal metrics (measured times aside) and trajectories, bit for bit."""
    assert len(batched) == len(one_by_one)
    for a, b in zip(batched, one_by_one, strict=True):
        assert (a.controller, a.kind, a.scenario, a.seed, a.training_seed) == (
            b.controller,
            b.kind,
            b.scenario,
            b.seed,
            b.training_seed,
        )
        ma, mb = _untimed(a.metrics), _untimed(b.metrics)
        assert ma.keys() == mb.keys()
        differ = [k for k in ma if not _same(ma[k], mb[k])]
        assert not differ, (a.controller, a.seed, differ)
        assert a.trajectory.keys() == b.trajectory.keys()
        for key, values in a.trajectory.items():
            np.testing.assert_array_equal(values, b.trajectory[key], err_msg=key)


def _one_by_one(name: str, scenarios: list, seeds: list[int], training_seed=None) -> list:
    results = []
    for scenario, seed in zip(scenarios, seeds, strict=True):
        policy, mode = make_controller(name, training_seed=training_seed)
        results.append(run_episode(policy, scenario, seed, mode))
    return results


@pytest.mark.parametrize("name", SHIPPED)
def test_batched_learned_evaluation_equals_one_episode_at_a_time(name: str) -> None:
    """Three seeds on each of two scenarios, each seed its own trial variant (the episodes
    end at different steps, so rows move up in the batch): the lockstep run with one network
    forward per step equals ``run_episode`` one by one, bit for bit."""
    pytest.importorskip("stable_baselines3")
    seeds = [EVAL_SEED_OFFSET + i for i in range(3)]
    trained = training_seeds(name)[-1]
    for scenario in ("rudder_aging", "current_shift"):
        trials = _trials(scenario, len(seeds))
        batched = evaluate_batch(name, trials, seeds, training_seed=trained)
        _assert_same_episodes(batched, _one_by_one(name, trials, seeds, trained))
        assert {r.training_seed for r in batched} == {trained}
        assert len({r.metrics["ace"] for r in batched}) == len(seeds)  # the trials differ
        assert len({r.metrics["steps"] for r in batched}) == len(seeds)  # and end apart


def test_batched_recurrent_evaluation_spans_several_forward_chunks() -> None:
    """More episodes than one forward's rows (BATCH_ROWS): LSTM states stay with their
    episodes across chunks, as episodes end and the rows shift."""
    pytest.importorskip("sb3_contrib")
    from shipgym_baselines.learned.policy import BATCH_ROWS

    n = BATCH_ROWS + 2
    seeds = [EVAL_SEED_OFFSET + i for i in range(n)]
    base = load_scenario("nominal")
    trials = [
        base.with_overrides({"initial_state": {"y": 0.2 * i}, "time_limit": 40.0 + 2.0 * i})
        for i in range(n)
    ]
    batched = evaluate_batch("recurrent_ppo", trials, seeds)
    _assert_same_episodes(batched, _one_by_one("recurrent_ppo", trials, seeds))
    assert len({r.metrics["steps"] for r in batched}) > 1


def test_batched_evaluation_runs_classical_controllers_one_by_one() -> None:
    """A classical controller (by name or as an instance) gives what ``evaluate`` gives, one
    scenario for all seeds or one per seed."""
    seeds = [EVAL_SEED_OFFSET, EVAL_SEED_OFFSET + 1]
    _assert_same_episodes(
        evaluate_batch("pid_los", "rudder_aging", seeds), evaluate("pid_los", "rudder_aging", seeds)
    )
    trials = _trials("nominal", 2)
    expected = [evaluate("pid_los", t, [s])[0] for t, s in zip(trials, seeds, strict=True)]
    _assert_same_episodes(evaluate_batch(PIDLOS(), trials, seeds), expected)
    assert all(r.training_seed is None for r in expected)
    with pytest.raises(ValueError, match="2 scenarios for 3 seeds"):
        evaluate_batch("pid_los", trials, [*seeds, 3])
    with pytest.raises(ControllerError, match="'pid_los' has no training seeds"):
        evaluate_batch("pid_los", "nominal", seeds, training_seed=0)


class _ClockedZero(ZeroRudder):
    """A zero-rudder BatchPolicy (one ``act_batch`` call for all live episodes)."""

    name = "clocked_zero"

    def reset_batch(self, contexts: list) -> None:
        pass

    def act_batch(self, obs: np.ndarray, episodes: list[int]) -> np.ndarray:
        return np.zeros((len(obs), 1), dtype=np.float32)


def test_batched_compute_time_divides_each_forward_among_the_live_envs() -> None:
    """The loop's clock reads 1 s more at every call, so each ``act_batch`` takes 1 s: while
    two episodes are live each step costs each 500 ms; once the short one has ended, the
    long one pays the whole second."""
    ticks = iter(range(10**6))
    long = load_scenario("nominal")
    short = long.with_overrides({"time_limit": 20.0})
    with evaluation.act_clock(lambda: float(next(ticks))):
        a, b = evaluate_batch(_ClockedZero(), [long, short], [0, 0])
    n_long, n_short = len(a.trajectory["t"]) - 1, len(b.trajectory["t"]) - 1
    assert n_short < n_long
    assert (b.metrics["compute_ms"], b.metrics["compute_ms_max"]) == (500.0, 500.0)
    assert a.metrics["compute_ms_max"] == 1000.0
    expected = (500.0 * n_short + 1000.0 * (n_long - n_short)) / n_long
    assert a.metrics["compute_ms"] == pytest.approx(expected, rel=1e-12)


# --- a failing controller ends its episode (ActGuard) ----------------------------------------

#: the act call at which a failing test controller goes wrong
FAIL_AT = 3


class GoesWrong(PIDLOS):
    """pid_los until its ``FAIL_AT``-th act of an episode, which ``wrong`` replaces; only on
    the seeds of ``on`` (None: every seed)."""

    name = "goes_wrong"

    def __init__(self, wrong: Any, on: set[int] | None = None) -> None:
        super().__init__()
        self.wrong, self.on = wrong, on

    def reset(self, context: Any, seed: int | None = None) -> None:
        super().reset(context, seed=seed)
        self.calls, self.failing = 0, self.on is None or seed in self.on

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> Any:
        self.calls += 1
        action = super().act(obs, info)
        return self.wrong() if self.failing and self.calls == FAIL_AT else action


def _raise() -> None:
    raise ValueError("the gain table\nhas no entry")


#: a bad act → the start of the episode's one-line ``error``
WRONG = {
    "raises": (_raise, "ValueError: the gain table has no entry"),
    "nan": (lambda: np.array([np.nan]), "ValueError: action contains NaN or inf"),
    "none": (lambda: None, "ValueError: action must be an array of shape (1,), got None"),
    "shape": (lambda: np.zeros(3), "ValueError: action must be an array of shape (1,), got"),
    "text": (lambda: "hard to port", "ValueError: action must be an array of shape (1,)"),
}


def test_without_a_guard_a_failing_act_raises() -> None:
    with pytest.raises(ValueError, match="the gain table"):
        run_episode(GoesWrong(_raise), "rudder_aging", seed=EVAL_SEED_OFFSET)


@pytest.mark.parametrize("kind", list(WRONG))
def test_a_guarded_failing_act_ends_its_episode_as_controller_error(kind: str) -> None:
    wrong, message = WRONG[kind]
    result = run_episode(GoesWrong(wrong), "rudder_aging", EVAL_SEED_OFFSET, guard=ActGuard())
    m = result.metrics
    assert m["termination_reason"] == "controller_error"
    assert m["error"].startswith(message) and "\n" not in m["error"]
    assert m["steps"] == FAIL_AT  # two steps acted, then the abandoned one
    assert result.trajectory["t"].size == FAIL_AT + 1  # and the reset
    assert math.isfinite(m["cost"]) and not m["success"]


def _spin(seconds: float = math.inf) -> np.ndarray:
    """Compute (CPU time) for ``seconds`` [s] of CPU time (inf: forever), then act."""
    end = time.process_time() + seconds
    while time.process_time() < end:
        pass
    return np.zeros(1)


def _block(seconds: float = 1e9) -> np.ndarray:
    """Wait for ``seconds`` [s] (no CPU time), then act."""
    time.sleep(seconds)
    return np.zeros(1)


@pytest.mark.parametrize(
    ("wrong", "message"),
    [
        (_spin, r"the call ran 0\.\d+ s of CPU time, over the limit of 0\.05 s"),
        (_block, r"the call had not returned after 0\.\d+ s, 10 times the limit of 0\.05 s"),
    ],
)
def test_a_call_that_never_returns_ends_its_episode_as_controller_timeout(
    wrong: Any, message: str
) -> None:
    """A call that computes or waits forever is ended while it runs: past the limit of CPU
    time, or past ten times the limit of wall time; the episode ends, the loop goes on."""
    start = time.perf_counter()
    result = run_episode(
        GoesWrong(wrong), "rudder_aging", EVAL_SEED_OFFSET, guard=ActGuard(timeout=0.05)
    )
    assert time.perf_counter() - start < 5.0
    m = result.metrics
    assert m["termination_reason"] == "controller_timeout" and m["steps"] == FAIL_AT
    assert re.fullmatch(message, m["error"]), m["error"]


def test_a_call_that_swallows_the_timeout_still_ends_its_episode() -> None:
    def swallow() -> np.ndarray:
        try:
            return _spin()
        except BaseException:
            return np.zeros(1)

    result = run_episode(
        GoesWrong(swallow), "rudder_aging", EVAL_SEED_OFFSET, guard=ActGuard(timeout=0.05)
    )
    assert result.metrics["termination_reason"] == "controller_timeout"


def test_a_call_slow_in_wall_time_but_not_in_cpu_time_is_no_timeout() -> None:
    """A first call that imports a library waits on the disk and the machine's other
    processes: wall time below ten times the limit, little CPU time, no timeout."""
    result = run_episode(
        GoesWrong(lambda: _block(0.2)), "rudder_aging", EVAL_SEED_OFFSET, guard=ActGuard(0.05)
    )
    assert result.metrics["termination_reason"] == "goal" and "error" not in result.metrics
    assert result.metrics["compute_ms_max"] >= 200.0  # the slow call is timed


def test_off_the_main_thread_a_call_over_the_limit_is_judged_when_it_returns() -> None:
    """No signal reaches another thread: the call runs to its end, then counts as a
    timeout."""
    results: list[EpisodeResult] = []
    slow = GoesWrong(lambda: _spin(0.3))
    worker = threading.Thread(
        target=lambda: results.append(
            run_episode(slow, "rudder_aging", EVAL_SEED_OFFSET, guard=ActGuard(timeout=0.05))
        )
    )
    worker.start()
    worker.join()
    m = results[0].metrics
    assert m["termination_reason"] == "controller_timeout" and m["steps"] == FAIL_AT
    assert m["compute_ms_max"] >= 300.0


def test_in_lockstep_a_hanging_call_ends_only_its_episode(scratch_registry: None) -> None:
    register_controller("test_hangs", lambda: GoesWrong(_spin, on={EVAL_SEED_OFFSET + 1}))
    seeds = [EVAL_SEED_OFFSET + i for i in range(3)]
    results = evaluate_batch("test_hangs", "rudder_aging", seeds, guard=ActGuard(0.05))
    reasons = [r.metrics["termination_reason"] for r in results]
    assert reasons == ["goal", "controller_timeout", "goal"]


def test_a_slow_reset_is_no_timeout() -> None:
    """``reset`` may build (and compile) a solver: it has a longer limit than ``act``
    (:attr:`ActGuard.setup_timeout`, 60 s here)."""

    class SlowReset(GoesWrong):
        def reset(self, context: Any, seed: int | None = None) -> None:
            time.sleep(0.1)
            super().reset(context, seed=seed)

    slow = SlowReset(_raise, on=set())
    result = run_episode(slow, "rudder_aging", EVAL_SEED_OFFSET, guard=ActGuard(timeout=0.05))
    assert result.metrics["termination_reason"] == "goal" and "error" not in result.metrics


def test_a_failing_reset_ends_the_episode_before_any_act() -> None:
    class BadReset(PIDLOS):
        def reset(self, context: Any, seed: int | None = None) -> None:
            raise RuntimeError("no model file")

    result = run_episode(BadReset(), "rudder_aging", EVAL_SEED_OFFSET, guard=ActGuard())
    m = result.metrics
    assert (m["termination_reason"], m["error"]) == (
        "controller_error",
        "RuntimeError: no model file",
    )
    assert m["steps"] == 1 and math.isnan(m["compute_ms"])  # no act was timed


class Claims(PIDLOS):
    """pid_los whose ``episode_stats`` gives ``figures()``."""

    name = "claims"

    def __init__(self, figures: Any) -> None:
        super().__init__()
        self.figures = figures

    def episode_stats(self) -> Any:
        return self.figures()


def test_a_controllers_figures_never_replace_a_metric() -> None:
    """Figures named as the benchmark's metrics stay in their own mapping: the episode's
    cost, termination and time are the env's and the loop's."""
    claims = {"cost": 0.001, "termination_reason": "goal", "compute_ms": 0.0, "error": None}
    (mine,) = evaluate(Claims(lambda: claims), "rudder_aging", [EVAL_SEED_OFFSET], guard=ActGuard())
    (twin,) = evaluate(Claims(dict), "rudder_aging", [EVAL_SEED_OFFSET], guard=ActGuard())
    assert mine.metrics["controller_stats"] == claims
    assert mine.metrics["cost"] == twin.metrics["cost"] > 1.0
    assert "error" not in mine.metrics and mine.metrics["compute_ms"] > 0.0


def _exit() -> None:
    raise SystemExit(3)


@pytest.mark.parametrize(
    ("figures", "why"),
    [
        (lambda: _raise(), "episode_stats() raised ValueError: the gain table has no entry"),
        (lambda: _exit(), "episode_stats() raised SystemExit: 3"),
        (lambda: [("cost", 1.0)], "episode_stats() is a list, not a mapping of names to numbers"),
        (lambda: {"gains": [1, 2]}, "episode_stats() gives 'gains' a list, not a number"),
        (lambda: {f"k{i}": i for i in range(101)}, "episode_stats() has 101 entries, beyond"),
    ],
)
def test_figures_that_fail_are_left_out_and_the_episode_kept(figures: Any, why: str) -> None:
    result = run_episode(Claims(figures), "rudder_aging", EVAL_SEED_OFFSET, guard=ActGuard())
    m = result.metrics
    assert m["termination_reason"] == "goal" and "controller_stats" not in m
    assert m["stats_error"].startswith(why)
    with pytest.raises((ValueError, SystemExit, ControllerError)):  # no guard: raised
        run_episode(Claims(figures), "rudder_aging", EVAL_SEED_OFFSET)


def test_a_failed_controllers_figures_that_fail_are_left_out() -> None:
    class NoStats(GoesWrong):
        def episode_stats(self) -> dict[str, Any]:
            raise RuntimeError("the stats need the last step")

    result = run_episode(NoStats(_raise), "rudder_aging", EVAL_SEED_OFFSET, guard=ActGuard())
    assert result.metrics["termination_reason"] == "controller_error"
    assert result.metrics["stats_error"].startswith("episode_stats() raised RuntimeError")


def test_the_setup_limit_is_thirty_acts_and_at_least_a_minute() -> None:
    assert ActGuard(10.0).setup_timeout == 300.0
    assert ActGuard(0.05).setup_timeout == 60.0
    assert ActGuard(math.inf).setup_timeout == math.inf


@pytest.fixture
def quick_setup(monkeypatch: pytest.MonkeyPatch) -> None:
    """No one-minute floor under the setup limit: 30 × the act limit."""
    monkeypatch.setattr(evaluation, "SETUP_MIN_S", 0.0)


class SpinningReset(PIDLOS):
    name = "spinning_reset"

    def reset(self, context: Any, seed: int | None = None) -> None:
        _spin()


class BlockingReset(PIDLOS):
    name = "blocking_reset"

    def reset(self, context: Any, seed: int | None = None) -> None:
        _block()


@pytest.mark.parametrize(
    ("policy", "message"),
    [
        (SpinningReset, r"the call ran 0\.3\d* s of CPU time, over the limit of 0\.3 s"),
        (
            BlockingReset,
            r"the call had not returned after 3(\.\d+)? s, 10 times the limit of 0\.3 s",
        ),
    ],
)
def test_a_reset_that_never_returns_ends_its_episode_as_controller_timeout(
    quick_setup: None, policy: type, message: str
) -> None:
    """``reset`` is held to the setup limit (30 × 0.01 s here): past it in CPU time, or
    past ten times it in wall time, the episode ends before any act, and the loop goes on."""
    start = time.perf_counter()
    result = run_episode(policy(), "rudder_aging", EVAL_SEED_OFFSET, guard=ActGuard(0.01))
    assert time.perf_counter() - start < 10.0
    m = result.metrics
    assert m["termination_reason"] == "controller_timeout" and m["steps"] == 1
    assert re.fullmatch(message, m["error"]), m["error"]


class SpinningConstructor(PIDLOS):
    def __init__(self) -> None:
        _spin()


def _metrics_in_every_path(name: str, *limit: float) -> list[dict[str, Any]]:
    """The metrics of the registered controller ``name`` on rudder_aging in every path of
    the loop (two seeds batched, one alone), each under a fresh ``ActGuard(*limit)``."""
    seeds = [EVAL_SEED_OFFSET, EVAL_SEED_OFFSET + 1]
    results = [
        *evaluate_batch(name, "rudder_aging", seeds, guard=ActGuard(*limit)),
        *evaluate(name, "rudder_aging", seeds[:1], guard=ActGuard(*limit)),
    ]
    assert [result.controller for result in results] == [name] * 3
    return [result.metrics for result in results]


def test_a_constructor_that_never_returns_fails_every_episode(
    scratch_registry: None, quick_setup: None
) -> None:
    """Construction is held to the setup limit too: a constructor that computes forever
    fails each of its episodes at its reset as controller_timeout, in every path of the
    loop."""
    register_controller("test_spins_when_made", lambda: SpinningConstructor())
    for m in _metrics_in_every_path("test_spins_when_made", 0.01):
        assert m["termination_reason"] == "controller_timeout"
        assert re.fullmatch(
            r"the controller could not be made: the call ran 0\.3\d* s of CPU time, over the "
            r"limit of 0\.3 s",
            m["error"],
        ), m["error"]
        assert m["steps"] == 1


class Unbuildable(PIDLOS):
    def __init__(self) -> None:
        raise SystemExit("no licence for the solver")


def test_a_controller_that_cannot_be_made_fails_every_episode(scratch_registry: None) -> None:
    """With a guard, a constructor that raises (even SystemExit) fails each episode at its
    reset, in every path of the loop; without one it raises."""
    register_controller("test_unbuildable", lambda: Unbuildable())
    for m in _metrics_in_every_path("test_unbuildable"):
        assert m["termination_reason"] == "controller_error"
        assert (
            m["error"] == "the controller could not be made: SystemExit: no licence for the solver"
        )
        assert m["steps"] == 1
    with pytest.raises(SystemExit):
        evaluate("test_unbuildable", "rudder_aging", [EVAL_SEED_OFFSET])


def test_in_lockstep_only_the_failing_seeds_episode_ends(scratch_registry: None) -> None:
    """A controller made by name fails on one of three seeds: that episode ends as
    controller_error, the others are the episodes one by one (lockstep rows)."""
    register_controller("test_goes_wrong", lambda: GoesWrong(_raise, on={EVAL_SEED_OFFSET + 1}))
    seeds = [EVAL_SEED_OFFSET + i for i in range(3)]
    results = evaluate_batch("test_goes_wrong", "rudder_aging", seeds, guard=ActGuard())
    reasons = [r.metrics["termination_reason"] for r in results]
    assert reasons[1] == "controller_error" and results[1].metrics["steps"] == FAIL_AT
    for i in (0, 2):
        alone = run_episode(GoesWrong(_raise, on=set()), "rudder_aging", seeds[i])
        assert "error" not in results[i].metrics
        for key, value in alone.metrics.items():
            if not key.startswith("compute_ms"):
                assert _same(results[i].metrics[key], value), (i, key)


class Batch(ZeroRudder):
    """A batch policy whose ``act_batch`` gives ``rows(n)`` for n live episodes."""

    name = "batch"

    def __init__(self, rows: Any) -> None:
        self.rows = rows

    def reset_batch(self, contexts: Any) -> None:
        self.steps = 0

    def act_batch(self, obs: np.ndarray, episodes: Any) -> Any:
        self.steps += 1
        return self.rows(len(episodes)) if self.steps == FAIL_AT else np.zeros((len(obs), 1))


def _nan_in_row_1(n: int) -> np.ndarray:
    actions = np.zeros((n, 1))
    actions[1] = np.nan
    return actions


@pytest.mark.parametrize(
    ("rows", "failed", "message"),
    [
        (_nan_in_row_1, [False, True, False], "ValueError: action contains NaN or inf"),
        (lambda n: np.zeros((n, 2)), [True] * 3, "ValueError: action must be an array of"),
        (lambda n: _raise(), [True] * 3, "ValueError: the gain table has no entry"),
    ],
)
def test_a_batch_policy_fails_the_rows_its_call_failed(
    rows: Any, failed: list[bool], message: str
) -> None:
    seeds = [EVAL_SEED_OFFSET + i for i in range(3)]
    results = evaluate_batch(Batch(rows), "rudder_aging", seeds, guard=ActGuard())
    assert [r.metrics["termination_reason"] == "controller_error" for r in results] == failed
    for result, fails in zip(results, failed, strict=True):
        if fails:
            assert result.metrics["error"].startswith(message)
            assert result.metrics["steps"] == FAIL_AT
        else:
            assert result.metrics["steps"] > FAIL_AT


# --- what the loop labels each episode with (EpisodeLabel) ------------------------------------


class TrainedZero(ZeroRudder):
    """Zero rudder that says it was trained with seed 5."""

    name = "trained_zero"
    training_seed = 5


def test_the_loop_labels_each_episode_as_told() -> None:
    """Given a label, every path of the loop makes each result under it: in lockstep (a
    policy made per seed, or one batch policy) and one by one; the label's training seed
    None leaves the policy's own.  Without a label: the trial's and the policy's names."""
    seeds = [EVAL_SEED_OFFSET, EVAL_SEED_OFFSET + 1]
    label = EpisodeLabel("table name", "shown name", 3)
    zeros = Batch(lambda n: np.zeros((n, 1)))
    labelled = [
        *evaluate_batch("zero_rudder", "nominal", seeds, label=label),
        *evaluate_batch(zeros, "nominal", seeds, label=label),
        *evaluate(ZeroRudder(), "nominal", seeds[:1], label=label),
    ]
    assert [(r.scenario, r.controller, r.training_seed, r.seed) for r in labelled] == [
        ("table name", "shown name", 3, seed) for seed in (*seeds, *seeds, seeds[0])
    ]
    untrained = EpisodeLabel("table name", "shown name")
    (own,) = evaluate(TrainedZero(), "nominal", seeds[:1], label=untrained)
    assert (own.scenario, own.controller, own.training_seed) == ("table name", "shown name", 5)
    (plain,) = evaluate(TrainedZero(), "nominal", seeds[:1])
    assert (plain.scenario, plain.controller, plain.training_seed) == ("nominal", "trained_zero", 5)
    assert own.kind == plain.kind == "reference"


def test_the_error_line_is_one_printable_bounded_line() -> None:
    line = error_line(ValueError("a\nb\x1b[31m\t" + "x" * 1000))
    assert line.startswith("ValueError: a b [31m xxx") and line.isprintable()
    assert len(line) == ERROR_CHARS and line.endswith("…")


@pytest.mark.parametrize("timeout", [0.0, -1.0, math.nan])
def test_a_limit_that_is_no_positive_time_is_refused(timeout: float) -> None:
    with pytest.raises(RunError, match="--act-timeout must be a positive time in s"):
        ActGuard(timeout)
