"""An open run: its folder locked, its ``run.json`` written as it starts (status
"running") and as it ends ("complete" | "interrupted" | "failed"), each finished episode
appended to ``episodes.jsonl`` as it arrives, and the wall-clock and CPU seconds it took.

``episodes.jsonl`` is appended and flushed by the parent process as each episode ends:
Ctrl-C or a kill keeps them; it is fsync'd at most :data:`FSYNC_INTERVAL_S` apart and at
the end (a power cut loses at most that last second).  A drawn episode's trajectory is
written as it ends (:func:`~shipgym_baselines.records.trajectories.trajectory_file`), and
once a row (scenario, controller) is complete only the episode its figure draws is kept
(:meth:`RunLog.drop_trajectories`).
"""

from __future__ import annotations

import contextlib
import errno
import io
import json
import os
import signal
import time
from collections.abc import Iterable, Iterator, Mapping, Sequence
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import IO, Any

import numpy as np

from shipgym_baselines.errors import RunError, RunFailed
from shipgym_baselines.jsonout import COMPACT, dumps
from shipgym_baselines.records.episodes import (
    EPISODES_FILE,
    EpisodeResult,
    Key,
    cut_partial_line,
    episode_key,
    episode_record,
    read_episodes,
)
from shipgym_baselines.records.folders import check_out_dir, check_out_usable
from shipgym_baselines.records.jsonfiles import as_json, differences, write_json
from shipgym_baselines.records.locking import out_lock
from shipgym_baselines.records.manifest import Manifest, clear_listed
from shipgym_baselines.records.outfiles import make_dir, open_regular, write_bytes
from shipgym_baselines.records.runrecord import RUN_FILE, git_commit, now, read_run, versions
from shipgym_baselines.records.trajectories import (
    TRAJECTORY_DIR,
    light_trajectory,
    trajectory_file,
)
from shipgym_baselines.signals import signal_number

#: most seconds between two fsyncs of ``episodes.jsonl`` (one per episode cost ≈ 5 ms each,
#: 30 s of a default leaderboard's 6000 episodes)
FSYNC_INTERVAL_S = 1.0

#: errors of a write that found no room: disk full, quota, file size limit
NO_ROOM = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)


class RunInterrupted(KeyboardInterrupt):
    """Ctrl-C (or SIGTERM: ``signum``) during a run; the message says what was kept and how
    to resume."""

    def __init__(self, message: str, signum: int = signal.SIGINT):
        super().__init__(message)
        self.signum = int(signum)

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


class RunLog:
    """An open run folder: its ``run.json`` record, the ``episodes.jsonl`` it appends to,
    its manifest (:mod:`shipgym_baselines.records.manifest`) and its lock
    (:mod:`shipgym_baselines.records.locking`).

    :meth:`open` locks the folder and starts (or resumes) the run, :meth:`append` records
    each finished episode, :meth:`recording` sets the final status and releases the lock.
    """

    def __init__(
        self,
        folder: Path,
        record: dict[str, Any],
        episodes: list[dict[str, Any]],
        manifest: Manifest | None = None,
    ):
        self.folder = folder
        self.record = record
        #: the recorded episodes by key
        self.episodes: dict[Key, dict[str, Any]] = {episode_key(e): e for e in episodes}
        self.done: set[Key] = set(self.episodes)
        self.manifest = manifest or Manifest(folder)
        self._count = len(self.episodes)
        self._file: IO[bytes] | None = None
        self._synced = time.monotonic()
        self._lock = contextlib.ExitStack()
        #: this invocation's start: wall clock [s] and CPU time [s] (:func:`cpu_seconds`)
        self._started = (time.perf_counter(), cpu_seconds())
        #: ``wall_s`` / ``cpu_s`` of earlier invocations (a resumed run adds to them)
        self._earlier = (float(record.get("wall_s") or 0.0), float(record.get("cpu_s") or 0.0))

    @property
    def episodes_file(self) -> Path:
        return self.folder / EPISODES_FILE

    @classmethod
    def open(
        cls,
        out: str | os.PathLike,
        *,
        command: Sequence[str],
        suite: Mapping[str, Any],
        jobs: int,
        resume: bool = False,
        force: bool = False,
        act_timeout: float | None = None,
    ) -> RunLog:
        """Lock ``out`` and start a run there (``force``: the paths its manifest lists
        removed first) or resume the one there (its suite must equal ``suite``, and its
        ``act_timeout`` this one: else a :class:`RunError` naming what differs).  Writes
        ``run.json`` with status "running" and ``act_timeout`` [s], the limit its
        controllers' calls are judged by (None: none recorded).  The lock is held until
        :meth:`recording` ends (or this fails)."""
        check_out_usable(out, resume=resume, force=force)
        lock = contextlib.ExitStack()
        start = now()
        folder = lock.enter_context(out_lock(out, start))
        try:
            log = cls._start(folder, command, suite, jobs, resume, force, start, act_timeout)
        except BaseException:
            lock.close()
            raise
        log._lock = lock
        return log

    @classmethod
    def _start(
        cls,
        folder: Path,
        command: Sequence[str],
        suite: Mapping[str, Any],
        jobs: int,
        resume: bool,
        force: bool,
        start: str,
        act_timeout: float | None = None,
    ) -> RunLog:
        """:meth:`open` once the folder is locked."""
        check_out_dir(folder, resume=resume, force=force)
        suite = as_json(suite)
        command = [str(c) for c in command]
        if resume:
            record = read_run(folder)
            changed = differences(record["suite"], suite)
            if changed:
                shown = "; ".join(changed[:5]) + ("; …" if len(changed) > 5 else "")
                raise RunError(
                    f"--resume: the suite differs from {folder / RUN_FILE}'s: {shown}; run it "
                    "as it was, or use --force to start afresh"
                )
            check_act_timeout(record, act_timeout, folder / RUN_FILE)
            episodes = read_episodes(folder, suite=record["suite"])
            cut_partial_line(folder / EPISODES_FILE)
            resumed = {"time": now(), "command": command, "git_commit": git_commit()}
            record.setdefault("resumed", []).append({**resumed, "versions": versions()})
            record.update(status="running", end_time=None, jobs=jobs)
            if act_timeout is not None:  # a record of an earlier version: this run's
                record.setdefault(ACT_TIMEOUT_KEY, act_timeout)
        else:
            if force:
                clear_listed(folder)
            episodes = []
            record = {
                "command": command,
                "suite": suite,
                "versions": versions(),
                "git_commit": git_commit(),
                "start_time": start,
                "end_time": None,
                "status": "running",
                "jobs": jobs,
                "episodes": 0,
            }
        if act_timeout is not None:
            record[ACT_TIMEOUT_KEY] = act_timeout
        manifest = Manifest(folder)
        manifest.claim(RUN_FILE, EPISODES_FILE)
        log = cls(folder, record, episodes, manifest)
        log._write_record()
        appending = open_regular(log.episodes_file, os.O_WRONLY | os.O_APPEND | os.O_CREAT)
        log._file = open(appending, "ab", buffering=0)  # closed by finish
        return log

    def append(self, result: EpisodeResult, keep_trajectory: bool = False) -> None:
        """Record one finished episode: its trajectory file first (if kept: at
        :func:`trajectory_file`), then its line, flushed (and fsync'd if the last fsync is
        :data:`FSYNC_INTERVAL_S` ago)."""
        record = episode_record(result)
        key = episode_key(record)
        if keep_trajectory and result.trajectory:
            data = io.BytesIO()
            np.savez_compressed(data, **light_trajectory(result.trajectory))
            with self.manifest.recording():  # listed before it is written
                make_dir(self.folder / TRAJECTORY_DIR)
                write_bytes(self.folder / trajectory_file(key), data.getvalue())
        assert self._file is not None, "append after finish"
        line = json.dumps(record, allow_nan=False, separators=COMPACT)  # no spaces
        self._write_line((line + "\n").encode())
        if time.monotonic() - self._synced >= FSYNC_INTERVAL_S:
            os.fsync(self._file.fileno())
            self._synced = time.monotonic()
        self.episodes[key] = record
        self.done.add(key)
        self._count += 1

    def retry(self, keys: Iterable[Key]) -> None:
        """Run these recorded episodes again (those their controller ended): they leave
        :attr:`done`, and the line appended for each replaces the earlier one
        (:func:`read_episodes`)."""
        self.done -= set(keys)

    def _write_line(self, data: bytes) -> None:
        """Append one line to ``episodes.jsonl`` (unbuffered: on disk when this returns);
        a line that cannot be written whole is cut off again, so no partial line stays
        between whole ones (a full disk)."""
        assert self._file is not None
        start = self._file.seek(0, os.SEEK_END)
        try:
            done = 0
            while done < len(data):
                written = self._file.write(data[done:])
                if not written:
                    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
                done += written
        except OSError as exc:
            with contextlib.suppress(OSError):
                os.ftruncate(self._file.fileno(), start)
            if exc.filename is None:
                exc.filename = str(self.episodes_file)
            raise

    def drop_trajectories(self, keys: Iterable[Key]) -> None:
        """Remove the trajectory files of these episodes (those not drawn), if there."""
        for key in keys:
            (self.folder / trajectory_file(key)).unlink(missing_ok=True)

    def finish(self, status: str) -> None:
        """Close ``episodes.jsonl`` and write the final status and end time (on a full
        disk ``run.json`` is overwritten in place if it can be: :meth:`_write_record`)."""
        if self._file is not None:
            file, self._file = self._file, None
            with contextlib.suppress(OSError):
                os.fsync(file.fileno())
            file.close()
        with contextlib.suppress(RunError):  # the file's count: Ctrl-C may cut in
            self._count = len(read_episodes(self.folder))
        wall, cpu = self.elapsed()
        self.record.update(
            status=status,
            end_time=now(),
            episodes=self._count,
            wall_s=self._earlier[0] + wall,
            cpu_s=self._earlier[1] + cpu,
        )
        self._write_record(in_place=status != "complete")
        self.manifest.compact(keep=(RUN_FILE, EPISODES_FILE))

    def elapsed(self) -> tuple[float, float]:
        """Wall-clock and CPU seconds of this invocation so far (:func:`cpu_seconds`)."""
        wall0, cpu0 = self._started
        return time.perf_counter() - wall0, cpu_seconds() - cpu0

    def kept(self) -> str:
        """What the run kept, and how to finish it."""
        return (
            f"{self._count} of {self.record['jobs']} episodes kept in {self.episodes_file}; "
            "resume with --resume"
        )

    @contextlib.contextmanager
    def recording(self) -> Iterator[RunLog]:
        """The run's body: status "complete" when it ends, "failed" (with ``error``) on an
        error, and on Ctrl-C or SIGTERM "interrupted" and a :class:`RunInterrupted` saying
        what was kept.  A worker that died or a full disk: "failed" and a
        :class:`~shipgym_baselines.errors.RunFailed` saying what was kept.  (A killed run keeps
        "running" and every episode it finished.)  Releases the folder's lock."""
        with self._lock:
            try:
                yield self
            except KeyboardInterrupt as exc:
                self.finish("interrupted")
                raise RunInterrupted(self.kept(), signal_number(exc)) from None
            except (OSError, RunFailed, BrokenProcessPool) as exc:
                problem = outside_problem(exc)
                if problem is None:
                    self._fail(exc)
                    raise
                self.record["error"] = problem
                self.finish("failed")
                raise RunFailed(f"{problem}: {self.kept()}") from None
            except BaseException as exc:
                self._fail(exc)
                raise
            self.record.pop("error", None)  # a resumed run that failed before
            self.finish("complete")

    def _fail(self, exc: BaseException) -> None:
        self.record["error"] = f"{type(exc).__name__}: {exc}"
        self.finish("failed")

    def _write_record(self, in_place: bool = False) -> None:
        """``run.json``, atomically; ``in_place``: when that finds no room, overwritten in
        place as compact JSON if that does not make the file longer (the final status on
        a full disk), else left as it was."""
        file = self.folder / RUN_FILE
        try:
            with self.manifest.recording():  # listed before it is written
                write_json(file, self.record)
        except OSError as exc:
            if not (in_place and exc.errno in NO_ROOM and file.is_file()):
                raise
            data = (dumps(self.record) + "\n").encode()
            if len(data) <= file.stat().st_size:
                with contextlib.suppress(OSError), open(open_regular(file, os.O_RDWR), "r+b") as fh:
                    fh.write(data)
                    fh.truncate()


#: the key of ``run.json`` that holds the limit [s] on one controller call (``--act-timeout``)
ACT_TIMEOUT_KEY = "act_timeout"


def check_act_timeout(record: Mapping[str, Any], act_timeout: float | None, file: Path) -> None:
    """A :class:`RunError` when a resumed run's record (``file``) judged its controllers'
    calls by another limit than ``act_timeout`` [s]: its episodes would mix two limits.  A
    record without one (an earlier version) resumes under any."""
    recorded = record.get(ACT_TIMEOUT_KEY)
    if recorded is None or act_timeout is None:
        return
    if isinstance(recorded, bool) or not isinstance(recorded, int | float):
        raise RunError(f"{file}: key '{ACT_TIMEOUT_KEY}' is {recorded!r:.40}, not a time in s")
    if float(recorded) == float(act_timeout):
        return
    raise RunError(
        f"--resume: {file} judged its controllers with --act-timeout {recorded:g} s, not "
        f"{act_timeout:g} s: resume with --act-timeout {recorded:g}, or use --force to "
        "start afresh"
    )


def cpu_seconds() -> float:
    """CPU seconds [s] of this process and of its finished child processes (a process
    pool's workers count once the pool has shut down), user and system."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def outside_problem(exc: BaseException) -> str | None:
    """The one-line account of a run stopped from outside (a full disk, a worker that
    died), or None for any other error."""
    if isinstance(exc, BrokenProcessPool):
        return "a worker process died (killed, or out of memory)"
    if isinstance(exc, RunFailed):
        return str(exc)
    if isinstance(exc, OSError) and exc.errno in NO_ROOM:
        where = exc.filename or "a file"
        return f"no room to write {where} ({exc.strerror}: disk full?)"
    return None


__all__ = [
    "ACT_TIMEOUT_KEY",
    "FSYNC_INTERVAL_S",
    "NO_ROOM",
    "RunInterrupted",
    "RunLog",
    "check_act_timeout",
    "cpu_seconds",
    "outside_problem",
]
