"""A controller whose code is not the benchmark's own plays in a process of its own: its
value comes back, the benchmark's errors are raised as without a child, and a child that
ends or will not end stands for the controller's failure."""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path
from typing import Any

import pytest

from shipgym_baselines import evaluation, isolation
from shipgym_baselines.errors import RunError
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET, ActGuard, run_episode
from shipgym_baselines.isolation import call, isolated, run_isolated
from shipgym_baselines.plugins import ControllerEntry
from shipgym_baselines.registry import register_controller

from .test_evaluation import GoesWrong

PLUGIN = """
from shipgym_baselines.classical.pid import PIDLOS


class Mine(PIDLOS):
    name = "mine"
"""


def test_a_plugin_is_isolated_the_built_ins_are_not(tmp_path: Path, scratch_registry: None) -> None:
    (tmp_path / "mine.py").write_text(PLUGIN)
    assert isolated(f"{tmp_path / 'mine.py'}:Mine")
    register_controller("test_outside", lambda: GoesWrong(lambda: None))  # a test's factory
    assert isolated("test_outside")
    for own in ("pid_los", "ppo", ControllerEntry(controller="pid_los", settings={})):
        assert not isolated(own)


def _failed(reason: str, error: str) -> tuple[str, str]:
    return ("failed", reason, error)


def _raises() -> None:
    raise RunError("the benchmark's own refusal")


def _exits() -> None:
    os._exit(3)


def _crashes() -> None:
    import faulthandler

    faulthandler.disable()  # pytest's: no traceback printed for the crash
    os.kill(os.getpid(), signal.SIGSEGV)


def test_the_value_comes_back_and_the_benchmarks_errors_are_raised() -> None:
    assert run_isolated(call, lambda: ("played", os.getpid()), _failed, 60.0)[0] == "played"
    assert run_isolated(call, lambda: os.getpid(), _failed, 60.0) != os.getpid()
    with pytest.raises(RunError, match="the benchmark's own refusal"):
        run_isolated(call, _raises, _failed, 60.0)


def test_a_child_that_ends_stands_for_the_controllers_failure() -> None:
    assert run_isolated(call, _exits, _failed, 60.0) == (
        "failed",
        "controller_error",
        "the controller's process ended with exit code 3",
    )
    assert run_isolated(call, _crashes, _failed, 60.0) == (
        "failed",
        "controller_error",
        "the controller's process was killed by SIGSEGV",
    )


def _stubborn() -> Any:
    """An episode whose third act ignores the watchdog's signal and computes for ever."""

    def wrong() -> None:
        signal.signal(signal.SIGUSR2, signal.SIG_IGN)
        while True:
            pass

    return run_episode(
        GoesWrong(wrong), "rudder_aging", EVAL_SEED_OFFSET, guard=ActGuard(timeout=0.02)
    )


def test_a_call_that_will_not_end_has_its_process_killed(monkeypatch: pytest.MonkeyPatch) -> None:
    """The guard cannot end it (its signal ignored): the supervisor kills the child 0.3 s
    after ten times the limit, and says so."""
    monkeypatch.setattr(isolation, "GRACE_S", 0.3)
    start = time.perf_counter()
    outcome = run_isolated(call, _stubborn, _failed, 60.0)
    assert time.perf_counter() - start < 10.0
    assert outcome == (
        "failed",
        "controller_timeout",
        "the call had not returned after 0.5 s, 10 times the limit of 0.02 s and 0.3 s more, "
        "nor ended when asked: its process was killed",
    )


def _sleeps(pid_file: Path) -> None:
    pid_file.write_text(str(os.getpid()))
    time.sleep(600)


def _interrupt(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt


def test_ctrl_c_in_the_supervisor_kills_the_child(tmp_path: Path) -> None:
    pid_file = tmp_path / "child.pid"
    previous = signal.signal(signal.SIGALRM, _interrupt)
    signal.setitimer(signal.ITIMER_REAL, 1.0)
    try:
        with pytest.raises(KeyboardInterrupt):
            run_isolated(_sleeps, pid_file, _failed, 60.0)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, previous)
    pid = int(pid_file.read_text())
    with pytest.raises(ProcessLookupError):
        os.kill(pid, 0)  # gone, and reaped


def test_the_childs_start_is_held_to_the_setup_limit(monkeypatch: pytest.MonkeyPatch) -> None:
    """Until the child runs its work (a spawned child imports first), the beacon holds its
    start with the setup limit: a child that never gets there is killed."""
    monkeypatch.setattr(isolation, "GRACE_S", 0.2)
    monkeypatch.setattr(isolation, "_child", _never_starts)
    outcome = run_isolated(call, lambda: None, _failed, 0.01)
    assert outcome[:2] == ("failed", "controller_timeout")


def _never_starts(*args: Any) -> None:
    time.sleep(600)


def test_failed_episodes_end_at_reset_as_a_controller_that_cannot_be_made() -> None:
    from shipgym_baselines.records.episodes import EpisodeLabel

    label = EpisodeLabel("rudder_aging", "mine", None)
    result = evaluation.failed_episode(
        "pid_los", "rudder_aging", EVAL_SEED_OFFSET, "controller_timeout", "why", ActGuard(), label
    )
    m = result.metrics
    assert (result.controller, m["termination_reason"], m["error"], m["steps"]) == (
        "mine",
        "controller_timeout",
        "why",
        1,
    )
