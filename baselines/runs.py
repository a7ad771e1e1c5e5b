"""Run records: every ``leaderboard`` / ``evaluate`` run keeps its results in its ``--out``.

::

    run.json         command (argv), suite (resolved: seeds, randomize, controllers with
                     their training seeds, each scenario's settings), versions, git commit,
                     start/end time (ISO 8601 UTC), status ("running" → "complete" |
                     "interrupted" | "failed"), jobs (the episodes the run holds when
                     complete), episodes
    episodes.jsonl   one JSON object per finished episode (scenario, controller, kind, seed,
                     training_seed and every metric), appended and flushed by the parent
                     process as each episode ends: Ctrl-C or a kill keeps them; fsync'd at
                     most :data:`FSYNC_INTERVAL_S` apart and at the end (a power cut loses
                     at most that last second); an episode's key is (scenario, controller,
                     seed, training_seed)
    trajectories/    the drawn episodes' trajectories: each episode's is written as it
                     ends (``<hash of its key>.npz``, :func:`trajectory_file`), and once a
                     row (scenario, controller) is complete only the episode its figure
                     draws is kept (:meth:`RunLog.drop_trajectories`)

A folder that is not empty is refused before any work unless ``resume`` (run the episodes
missing from ``episodes.jsonl``; the resolved suite must equal ``run.json``'s) or ``force``
(clear the earlier outputs first).  Tables are always aggregated from ``episodes.jsonl`` (so
a resumed run's tables equal a clean run's, and ``shipgym report`` rebuilds them from the
folder).

Strict JSON has no infinity or NaN: in ``episodes.jsonl`` a metric of ±inf (t_c = inf, "never
converged") is the string ``"inf"`` / ``"-inf"`` and NaN is ``null`` (metrics ignore NaN), so
a record reads back to the same numbers (:func:`read_episodes`).
"""

from __future__ import annotations

import contextlib
import datetime
import fnmatch
import hashlib
import json
import math
import os
import platform
import shutil
import subprocess
import time
from collections.abc import Iterable, Iterator, Mapping, Sequence
from importlib import metadata
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import numpy as np

from baselines.errors import RunError

if TYPE_CHECKING:
    from baselines.evaluation import EpisodeResult

RUN_FILE = "run.json"
EPISODES_FILE = "episodes.jsonl"
TRAJECTORY_DIR = "trajectories"
#: what a run (or ``shipgym report``) writes into its folder; ``force`` removes these and
#: refuses to touch anything else.  A new output file of a run belongs here.
RUN_OUTPUTS = (
    RUN_FILE,
    EPISODES_FILE,
    TRAJECTORY_DIR,
    "report.json",
    "leaderboard.md",
    "leaderboard.csv",
    "leaderboard.json",
    "leaderboard.html",
    "generalisation.json",
    "aggregate.json",
    "scenario_scores.json",
    "*.png",
    "*.pdf",
    "*.svg",
)
#: most seconds between two fsyncs of ``episodes.jsonl`` (one per episode cost ≈ 5 ms each,
#: 30 s of a default leaderboard's 6000 episodes)
FSYNC_INTERVAL_S = 1.0
#: the keys of an ``episodes.jsonl`` object that are not metrics
EPISODE_KEYS = ("scenario", "controller", "kind", "seed", "training_seed", "trajectory")
#: distributions whose versions ``run.json`` records (those installed)
PACKAGES = (
    "numpy",
    "scipy",
    "gymnasium",
    "casadi",
    "pydantic",
    "stable-baselines3",
    "sb3-contrib",
    "torch",
)

#: where a run's jobs execute (``--backend``): a local process pool or a Ray cluster
BACKENDS = ("local", "ray")

#: an episode's key: (scenario, controller, seed, training_seed)
Key = tuple[str, str, int, int | None]


class RunInterrupted(KeyboardInterrupt):
    """Ctrl-C during a run; the message says what was kept and how to resume."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


# --- the output folder -----------------------------------------------------------------------


def check_out_dir(
    out: str | os.PathLike, *, resume: bool = False, force: bool = False, note: str = ""
) -> Path:
    """``out`` as a Path once it can hold this run; a :class:`RunError` before any work when
    it cannot: a file, below a file, not writable, or not empty without ``resume`` /
    ``force`` (``note`` is added to that message, e.g. where a default folder came from)."""
    path = Path(out)
    if resume and force:
        raise RunError("--resume and --force exclude each other")
    if path.exists() and not path.is_dir():
        raise RunError(f"--out {path} is a file, not a folder")
    existing = next(p for p in (path, *path.parents) if p.exists() or p == Path(p.anchor))
    if not existing.is_dir():
        raise RunError(f"--out {path}: {existing} is a file, not a folder")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise RunError(f"--out {path}: {existing} is not writable")
    entries = sorted(p.name for p in path.iterdir()) if path.is_dir() else []
    if resume and RUN_FILE not in entries:
        raise RunError(f"--resume: {path} holds no run to resume (no {RUN_FILE})")
    if entries and not (resume or force):
        raise RunError(
            f"--out {path} is not empty ({_describe(path, entries)}){note}; pass --resume to "
            "finish that run, --force to replace it, or another --out"
        )
    return path


def _describe(path: Path, entries: list[str]) -> str:
    """What an occupied folder holds, for the refusal message."""
    if RUN_FILE in entries:
        record = _read_json(path / RUN_FILE)
        status = record.get("status", "?") if isinstance(record, dict) else "unreadable"
        return f"an earlier run, {status}, {len(read_episodes(path))} episodes"
    shown = ", ".join(entries[:3]) + (", …" if len(entries) > 3 else "")
    return f"{len(entries)} entries: {shown}"


def clear_outputs(
    folder: str | os.PathLike, outputs: Sequence[str] = RUN_OUTPUTS, option: str = "--force"
) -> None:
    """Remove the earlier outputs (names or glob patterns of ``outputs``) from ``folder``;
    a :class:`RunError`, before removing anything, when it holds anything else."""
    path = Path(folder)
    if not path.is_dir():
        return
    entries = sorted(path.iterdir())
    foreign = [p.name for p in entries if not any(fnmatch.fnmatch(p.name, o) for o in outputs)]
    if foreign:
        raise RunError(
            f"{option}: {path} holds files no run wrote ({', '.join(foreign)}): move them "
            "away or choose another folder"
        )
    for entry in entries:
        if entry.is_dir() and not entry.is_symlink():
            shutil.rmtree(entry)
        else:
            entry.unlink()


# --- run.json --------------------------------------------------------------------------------


def now() -> str:
    """The current time, ISO 8601 UTC (seconds)."""
    return datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")


def versions() -> dict[str, str]:
    """Python's and the installed main packages' versions (shipgym's own included)."""
    import shipgym

    found = {"python": platform.python_version(), "shipgym": shipgym.__version__}
    for name in PACKAGES:
        with contextlib.suppress(metadata.PackageNotFoundError):
            found[name] = metadata.version(name)
    return found


def git_commit() -> str | None:
    """``git rev-parse HEAD`` of the checkout the package runs from; None when it is not a
    git checkout (an installed wheel) or git is missing."""
    root = Path(__file__).resolve().parents[1]
    if not (root / ".git").exists():
        return None
    try:
        done = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True, timeout=10
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return (done.stdout.strip() or None) if done.returncode == 0 else None


def read_run(folder: str | os.PathLike) -> dict[str, Any]:
    """A run folder's ``run.json``; a :class:`RunError` naming the folder if it has none."""
    file = Path(folder) / RUN_FILE
    if not file.is_file():
        raise RunError(f"{folder}: not a run folder (no {RUN_FILE})")
    record = _read_json(file)
    if not isinstance(record, dict) or not isinstance(record.get("suite"), dict):
        raise RunError(f"{file}: not a run record (no 'suite')")
    return record


def _read_json(file: Path) -> Any:
    try:
        return json.loads(file.read_text())
    except (OSError, ValueError) as exc:
        raise RunError(f"{file}: unreadable ({exc})") from None


def write_json(file: Path, document: Any) -> None:
    """Write atomically (a temporary file renamed over ``file``)."""
    from baselines.jsonout import dumps

    tmp = file.with_name(f".{file.name}.tmp")
    tmp.write_text(dumps(document, indent=2) + "\n")
    os.replace(tmp, file)


def as_json(document: Any) -> Any:
    """``document`` as it reads back from JSON (tuples → lists, numpy → Python)."""
    from baselines.jsonout import dumps

    return json.loads(dumps(document))


def differences(old: Any, new: Any, where: str = "") -> list[str]:
    """The dotted keys at which two JSON documents differ, with both values."""
    if isinstance(old, dict) and isinstance(new, dict):
        found = []
        for key in dict.fromkeys([*old, *new]):
            sub = f"{where}.{key}" if where else str(key)
            if key not in old or key not in new:
                side = "now" if key in new else "in the run"
                found.append(f"{sub} only {side}")
            else:
                found += differences(old[key], new[key], sub)
        return found
    if old == new:
        return []
    return [f"{where or 'value'}: {_short(old)} in the run, {_short(new)} now"]


def _short(value: Any, limit: int = 60) -> str:
    text = json.dumps(value)
    return text if len(text) <= limit else text[: limit - 1] + "…"


# --- episodes.jsonl --------------------------------------------------------------------------


def _plain(value: Any) -> Any:
    """A metric as strict JSON: numpy scalars as Python ones, ±inf as "inf"/"-inf", NaN null."""
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, int | np.integer):
        return int(value)
    if isinstance(value, float | np.floating):
        value = float(value)
        if math.isnan(value):
            return None
        return value if math.isfinite(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [_plain(v) for v in value]
    return value


def _number(value: Any) -> Any:
    """The inverse of :func:`_plain` for one value."""
    if value == "inf":
        return math.inf
    if value == "-inf":
        return -math.inf
    return value


def episode_record(result: EpisodeResult) -> dict[str, Any]:
    """One ``episodes.jsonl`` object (trajectory aside)."""
    head = {
        "scenario": result.scenario,
        "controller": result.controller,
        "kind": result.kind,
        "seed": int(result.seed),
        "training_seed": result.training_seed,
    }
    return _plain({**head, **result.metrics})


def episode_key(record: Mapping[str, Any]) -> Key:
    """(scenario, controller, seed, training_seed) of an episode record (or result row;
    training_seed None for a controller that is not trained)."""
    training_seed = record.get("training_seed")
    return (
        record["scenario"],
        record["controller"],
        int(record["seed"]),
        None if training_seed is None else int(training_seed),
    )


def read_episodes(folder: str | os.PathLike) -> list[dict[str, Any]]:
    """The finished episodes of a run folder, numbers restored (±inf).  A last line cut
    short by a kill is left out."""
    file = Path(folder) / EPISODES_FILE
    if not file.is_file():
        return []
    records = []
    lines = file.read_text().splitlines(keepends=True)
    for number, line in enumerate(lines, start=1):
        try:
            record = json.loads(line)
        except ValueError:
            if number == len(lines) and not line.endswith("\n"):
                break  # written when the run was killed
            raise RunError(f"{file}: line {number} is not JSON") from None
        records.append({k: _number(v) for k, v in record.items()})
    return records


def _repair(file: Path) -> None:
    """Cut a partial last line (a run killed while writing it) off ``file``."""
    if not file.is_file():
        return
    data = file.read_bytes()
    if data and not data.endswith(b"\n"):
        file.write_bytes(data[: data.rfind(b"\n") + 1])


def trajectory_file(key: Key) -> str:
    """Where an episode's trajectory is kept in its run folder: ``trajectories/`` and a
    hash of its key (scenario names may be paths, controller names anything)."""
    digest = hashlib.sha256(json.dumps(list(key)).encode()).hexdigest()[:20]
    return f"{TRAJECTORY_DIR}/{digest}.npz"


def _inside(folder: Path, name: Any) -> Path:
    """``folder / name`` if that is a file path inside ``folder`` (a record's
    ``trajectory`` may name nothing else), else a :class:`RunError`."""
    file = folder / str(name)
    if not isinstance(name, str) or not file.resolve().is_relative_to(folder.resolve()):
        raise RunError(
            f"{folder / EPISODES_FILE}: a record's trajectory {name!r} is not a file inside "
            "its run folder"
        )
    return file


def episode_result(record: Mapping[str, Any], folder: str | os.PathLike) -> EpisodeResult:
    """An :class:`~baselines.evaluation.EpisodeResult` from a record of ``folder``'s
    ``episodes.jsonl`` (its trajectory read if it was kept, else empty; a record of an
    earlier version names its file as ``trajectory``)."""
    from baselines.evaluation import EpisodeResult

    trajectory: dict[str, np.ndarray] = {}
    name = record.get("trajectory") or trajectory_file(episode_key(record))
    if name:
        file = _inside(Path(folder), name)
        if file.is_file():
            with np.load(file) as data:
                trajectory = {k: data[k] for k in data.files}
    return EpisodeResult(
        controller=record["controller"],
        kind=record["kind"],
        scenario=record["scenario"],
        seed=int(record["seed"]),
        metrics={k: v for k, v in record.items() if k not in EPISODE_KEYS},
        trajectory=trajectory,
        training_seed=record.get("training_seed"),
    )


# --- one run ---------------------------------------------------------------------------------


class RunLog:
    """An open run folder: its ``run.json`` record and the ``episodes.jsonl`` it appends to.

    :meth:`open` starts (or resumes) the run, :meth:`append` records each finished episode,
    :meth:`recording` sets the final status.
    """

    def __init__(self, folder: Path, record: dict[str, Any], episodes: list[dict[str, Any]]):
        self.folder = folder
        self.record = record
        #: the recorded episodes by key
        self.episodes: dict[Key, dict[str, Any]] = {episode_key(e): e for e in episodes}
        self.done: set[Key] = set(self.episodes)
        self._count = len(episodes)
        self._file: IO[str] | None = None
        self._synced = time.monotonic()

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
    ) -> RunLog:
        """Start a run in ``out`` (``force``: its earlier outputs removed first) or resume
        the one there (its suite must equal ``suite``: else a :class:`RunError` naming what
        differs).  Writes ``run.json`` with status "running"."""
        folder = check_out_dir(out, resume=resume, force=force)
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
            _repair(folder / EPISODES_FILE)
            episodes = read_episodes(folder)
            resumed = {"time": now(), "command": command, "git_commit": git_commit()}
            record.setdefault("resumed", []).append({**resumed, "versions": versions()})
            record.update(status="running", end_time=None, jobs=jobs)
        else:
            if force:
                clear_outputs(folder)
            try:
                folder.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise RunError(f"--out {folder}: cannot create it ({exc.strerror})") from None
            episodes = []
            record = {
                "command": command,
                "suite": suite,
                "versions": versions(),
                "git_commit": git_commit(),
                "start_time": now(),
                "end_time": None,
                "status": "running",
                "jobs": jobs,
                "episodes": 0,
            }
        log = cls(folder, record, episodes)
        log._file = open(log.episodes_file, "a")  # closed by finish
        log._write_record()
        return log

    def append(self, result: EpisodeResult, keep_trajectory: bool = False) -> None:
        """Record one finished episode: its trajectory file first (if kept: at
        :func:`trajectory_file`), then its line, flushed (and fsync'd if the last fsync is
        :data:`FSYNC_INTERVAL_S` ago)."""
        record = episode_record(result)
        key = episode_key(record)
        if keep_trajectory and result.trajectory:
            (self.folder / TRAJECTORY_DIR).mkdir(exist_ok=True)
            name = trajectory_file(key)
            tmp = self.folder / f"{name}.tmp.npz"
            np.savez(tmp, **result.trajectory)  # uncompressed: 6x faster, 20 % larger
            os.replace(tmp, self.folder / name)
        assert self._file is not None, "append after finish"
        self._file.write(json.dumps(record, allow_nan=False) + "\n")
        self._file.flush()
        if time.monotonic() - self._synced >= FSYNC_INTERVAL_S:
            os.fsync(self._file.fileno())
            self._synced = time.monotonic()
        self.episodes[key] = record
        self.done.add(key)
        self._count += 1

    def drop_trajectories(self, keys: Iterable[Key]) -> None:
        """Remove the trajectory files of these episodes (those not drawn), if there."""
        for key in keys:
            (self.folder / trajectory_file(key)).unlink(missing_ok=True)

    def finish(self, status: str) -> None:
        """Close ``episodes.jsonl`` and write the final status and end time."""
        if self._file is not None:
            self._file.flush()
            os.fsync(self._file.fileno())
            self._file.close()
            self._file = None
        self._count = len(read_episodes(self.folder))  # the file's count: Ctrl-C may cut in
        self.record.update(status=status, end_time=now(), episodes=self._count)
        self._write_record()

    @contextlib.contextmanager
    def recording(self) -> Iterator[RunLog]:
        """The run's body: status "complete" when it ends, "failed" (with ``error``) on an
        error, and on Ctrl-C "interrupted" and a :class:`RunInterrupted` saying what was
        kept.  (A killed run keeps "running" and every episode it finished.)"""
        try:
            yield self
        except KeyboardInterrupt:
            self.finish("interrupted")
            raise RunInterrupted(
                f"{self._count} of {self.record['jobs']} episodes kept in "
                f"{self.episodes_file}; resume with --resume"
            ) from None
        except BaseException as exc:
            self.record["error"] = f"{type(exc).__name__}: {exc}"
            self.finish("failed")
            raise
        self.record.pop("error", None)  # a resumed run that failed before
        self.finish("complete")

    def _write_record(self) -> None:
        write_json(self.folder / RUN_FILE, self.record)


__all__ = [
    "BACKENDS",
    "EPISODES_FILE",
    "RUN_FILE",
    "RUN_OUTPUTS",
    "RunInterrupted",
    "RunLog",
    "check_out_dir",
    "clear_outputs",
    "differences",
    "episode_result",
    "read_episodes",
    "read_run",
    "versions",
    "write_json",
]
