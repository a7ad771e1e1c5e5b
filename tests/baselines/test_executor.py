"""The executor: a function over items in turn, in a local process pool, or on Ray (faked)."""

from __future__ import annotations

import functools
import importlib.machinery
import importlib.util
import os
import sys
import time
import types
from pathlib import Path
from typing import Any

import pytest

from shipgym_baselines.errors import RunError
from shipgym_baselines.executor import BACKENDS, RaySetup, check_backend, map_jobs
from shipgym_baselines.extras import MissingExtra

ITEMS = list(range(7))


def _square(x: int) -> int:
    return x * x


def _fail_on_one(folder: str, x: int) -> int:
    """Item 1 raises at once; every other item marks that it started, then sleeps 60 s."""
    if x == 1:
        time.sleep(0.2)  # the others have started
        raise ValueError("job 1 failed")
    Path(folder, f"started_{x}").touch()
    time.sleep(60)
    return x


def _fail_or_finish(folder: str, x: int) -> int:
    """Item 1 raises after 0.1 s; every other item ends after 0.5 s, leaving a mark."""
    if x == 1:
        time.sleep(0.1)
        raise ValueError("job 1 failed")
    time.sleep(0.5)
    Path(folder, f"done_{x}").touch()
    return x


def _first_fast(x: int) -> int:
    """Item 0 at once, any other after 60 s."""
    if x:
        time.sleep(60)
    return x


def _note_pid(folder: str) -> None:
    """An initializer: writes this process's id into ``folder``."""
    Path(folder, f"init_{os.getpid()}").touch()


def _pid(_: int) -> int:
    time.sleep(0.05)  # both workers take jobs
    return os.getpid()


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie does not)."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except FileNotFoundError:
        return False
    return fields[0] != "Z"


def _gone_soon(pids: set[int], seconds: float = 5.0) -> bool:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if not any(_alive(p) for p in pids):
            return True
        time.sleep(0.05)
    return False


@pytest.mark.parametrize("workers", [1, 2])
def test_local_results_equal_the_serial_ones(workers: int) -> None:
    serial = [_square(x) for x in ITEMS]
    completed = list(map_jobs(_square, ITEMS, "local", workers))
    assert sorted(completed) == sorted(serial) and len(completed) == len(serial)
    assert list(map_jobs(_square, ITEMS, "local", workers, ordered=True)) == serial
    assert list(map_jobs(_square, [], "local", workers, ordered=True)) == []


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc")
@pytest.mark.parametrize("ordered", [False, True])
def test_a_failed_job_propagates_and_ends_the_rest(tmp_path: Path, ordered: bool) -> None:
    """The error comes back at once: the workers are killed (the job sleeping beside the
    failed one too), and the jobs not started never start."""
    init = tmp_path / "init"
    init.mkdir()
    fn = functools.partial(_fail_on_one, str(tmp_path))
    start = time.monotonic()
    items = list(range(12))
    initializer = functools.partial(_note_pid, str(init))
    with pytest.raises(ValueError, match="job 1 failed"):
        list(map_jobs(fn, items, "local", 2, initializer, ordered=ordered))
    assert time.monotonic() - start < 10
    workers = {int(p.name.removeprefix("init_")) for p in init.iterdir()}
    assert workers and _gone_soon(workers)
    started = {p.name for p in tmp_path.glob("started_*")}
    assert "started_0" in started and len(started) <= 2  # two workers, each busy 60 s
    time.sleep(0.3)
    assert {p.name for p in tmp_path.glob("started_*")} == started


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc")
def test_a_consumer_that_stops_reading_stops_the_workers(tmp_path: Path) -> None:
    """Closing the iterator after the first result kills the workers busy with the others."""
    init = tmp_path / "init"
    init.mkdir()
    initializer = functools.partial(_note_pid, str(init))
    results = map_jobs(_first_fast, [0, 1, 2, 3], "local", 2, initializer)
    assert next(results) == 0
    results.close()  # the others sleep 60 s
    workers = {int(p.name.removeprefix("init_")) for p in init.iterdir()}
    assert workers and _gone_soon(workers)


def test_finish_running_lets_the_running_jobs_end(tmp_path: Path) -> None:
    """``finish_running``: after a failed job, the job running beside it finishes (the
    training sweep's choice); the jobs not started are cancelled."""
    fn = functools.partial(_fail_or_finish, str(tmp_path))
    with pytest.raises(ValueError, match="job 1 failed"):
        list(map_jobs(fn, range(12), "local", 2, ordered=True, finish_running=True))
    done = {p.name for p in tmp_path.iterdir()}
    assert "done_0" in done and len(done) < 11


def test_the_initializer_runs_in_each_worker_only(tmp_path: Path) -> None:
    init = functools.partial(_note_pid, str(tmp_path))
    pids = set(map_jobs(_pid, range(8), "local", 2, init))
    noted = {int(p.name.removeprefix("init_")) for p in tmp_path.iterdir()}
    assert pids <= noted and os.getpid() not in pids | noted
    # in turn: the jobs run here, without the initializer
    assert set(map_jobs(_pid, range(2), "local", 1, init)) == {os.getpid()}
    assert os.getpid() not in {int(p.name.removeprefix("init_")) for p in tmp_path.iterdir()}


def test_a_bad_backend_is_named() -> None:
    assert BACKENDS == ("local", "ray")
    with pytest.raises(RunError, match="unknown backend 'slurm'; valid: local, ray"):
        map_jobs(_square, ITEMS, "slurm")  # at the call, before any next()
    with pytest.raises(RunError, match="'slurm'"):
        map_jobs(_square, ITEMS, "slurm", ordered=True)
    with pytest.raises(RunError, match="'slurm'"):
        check_backend("slurm")


def test_ray_missing_names_the_install(monkeypatch: pytest.MonkeyPatch) -> None:
    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name, *a: None if name == "ray" else real(name, *a)
    )
    with pytest.raises(MissingExtra, match=r"--backend ray needs Ray .*shipgym\[ray\]"):
        map_jobs(_square, ITEMS, "ray")


class _Ref:
    def __init__(self, fn: Any, args: tuple) -> None:
        self.fn, self.args = fn, args


class _FakeRay:
    """A stand-in for the ``ray`` module: a task runs at ``get``; the calls are recorded."""

    __spec__ = importlib.machinery.ModuleSpec("ray", None)

    def __init__(self, initialized: bool) -> None:
        self.up, self.calls = initialized, []

    def is_initialized(self) -> bool:
        return self.up

    def init(self, **kwargs: Any) -> None:
        self.calls.append(("init", kwargs))
        self.up = True

    def shutdown(self) -> None:
        self.calls.append(("shutdown",))
        self.up = False

    def remote(self, *args: Any, **options: Any) -> Any:
        if args:
            return types.SimpleNamespace(remote=lambda *a: _Ref(args[0], a))
        self.calls.append(("remote", options))
        return self.remote

    def wait(self, pending: list[_Ref]) -> tuple[list[_Ref], list[_Ref]]:
        return pending[-1:], pending[:-1]  # the last task finishes first

    def get(self, ref: _Ref) -> Any:
        return ref.fn(*ref.args)

    def cancel(self, ref: _Ref, force: bool) -> None:
        self.calls.append(("cancel", ref.args[1]))


def test_ray_defaults_connect_to_ray_address_and_leave_ray_running(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    ray = _FakeRay(initialized=False)
    monkeypatch.setitem(sys.modules, "ray", ray)
    monkeypatch.setenv("RAY_ADDRESS", "ray://head:10001")
    assert list(map_jobs(_square, ITEMS, "ray", ordered=True)) == [_square(x) for x in ITEMS]
    assert ray.calls == [("init", {"address": "ray://head:10001", "ignore_reinit_error": True})]
    assert list(map_jobs(_square, ITEMS, "ray")) == [_square(x) for x in reversed(ITEMS)]
    assert len(ray.calls) == 1  # running: not started again


def test_ray_setup_starts_and_shuts_down_only_its_own_ray(monkeypatch: pytest.MonkeyPatch) -> None:
    setup = RaySetup(init={"num_cpus": 2}, task={"num_cpus": 1}, shutdown=True)
    ray = _FakeRay(initialized=False)
    monkeypatch.setitem(sys.modules, "ray", ray)
    assert list(map_jobs(_square, [3, 4], "ray", ordered=True, ray_setup=setup)) == [9, 16]
    assert ray.calls == [("init", {"num_cpus": 2}), ("remote", {"num_cpus": 1}), ("shutdown",)]
    running = _FakeRay(initialized=True)
    monkeypatch.setitem(sys.modules, "ray", running)
    assert list(map_jobs(_square, [3], "ray", ray_setup=setup)) == [9]
    assert running.calls == [("remote", {"num_cpus": 1})]


def test_a_failed_ray_task_cancels_the_pending_ones(monkeypatch: pytest.MonkeyPatch) -> None:
    ray = _FakeRay(initialized=True)
    monkeypatch.setitem(sys.modules, "ray", ray)
    fn = functools.partial(_raise_at, 4)
    with pytest.raises(ValueError, match="item 4"):
        list(map_jobs(fn, range(6), "ray"))  # the fake finishes the last item first
    assert ray.calls == [("cancel", 0), ("cancel", 1), ("cancel", 2), ("cancel", 3)]


def _raise_at(bad: int, x: int) -> int:
    if x == bad:
        raise ValueError(f"item {x}")
    return x
