"""Run records: every ``leaderboard`` / ``evaluate`` run keeps its results in its ``--out``.

::

    run.json         command (argv), suite (resolved: seeds, randomize, controllers with
                     their training seeds, each scenario's settings by table name, the
                     files of the suite's own scenarios), versions, git commit,
                     start/end time (ISO 8601 UTC), status ("running" → "complete" |
                     "interrupted" | "failed"), jobs (the episodes the run holds when
                     complete), episodes, wall_s and cpu_s (wall-clock and CPU seconds
                     of the run, tables and figures included, its process and its
                     workers; a resumed run adds each invocation's)
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

A run holds an exclusive lock on its folder (:mod:`shipgym_baselines.records.locking`) and
lists every path it writes in ``manifest.txt`` (:mod:`shipgym_baselines.records.manifest`),
each written through no link (:mod:`shipgym_baselines.records.outfiles`; a folder holding a
link is refused).  A folder that is not empty is refused before any work unless ``resume``
(run the episodes missing from ``episodes.jsonl``; the resolved suite must equal
``run.json``'s) or ``force`` (delete what the manifest lists first; a folder holding anything
else is refused).  ``episodes.jsonl`` is read as a set keyed by the episode key
(:func:`read_episodes`).  Tables are always aggregated from ``episodes.jsonl`` (so a resumed
run's tables equal a clean run's, and ``shipgym report`` rebuilds them from the folder).

Strict JSON has no infinity or NaN: in ``episodes.jsonl`` a metric of ±inf (t_c = inf, "never
converged") is the string ``"inf"`` / ``"-inf"`` and NaN is ``null`` (metrics ignore NaN), so
a record reads back to the same numbers (:func:`read_episodes`).  Read back, each value is
checked by type: a metric is a finite number, null, ``"inf"`` or ``"-inf"``; only
:data:`BOOL_METRICS` are booleans and :data:`TEXT_METRICS` text.
"""

from __future__ import annotations

import contextlib
import datetime
import errno
import fnmatch
import hashlib
import io
import json
import math
import os
import platform
import shutil
import signal
import subprocess
import time
from collections.abc import Iterable, Iterator, Mapping, Sequence
from concurrent.futures.process import BrokenProcessPool
from importlib import metadata
from pathlib import Path
from typing import IO, Any, NamedTuple

import numpy as np

from shipgym_baselines.errors import RunError, RunFailed
from shipgym_baselines.jsonout import COMPACT
from shipgym_baselines.leaderboard.ranking import controller_failed
from shipgym_baselines.records.episodes import EpisodeResult
from shipgym_baselines.records.locking import LOCK_FILE, in_use, lock_holder, out_lock
from shipgym_baselines.records.manifest import Manifest, clear_listed
from shipgym_baselines.records.outfiles import check_no_links, make_dir, open_regular, write_bytes
from shipgym_baselines.records.trajectories import (
    DRAWN_KEYS,
    pack_trajectory,
    thin_trajectory,
    unpack_trajectory,
)
from shipgym_baselines.signals import signal_number

RUN_FILE = "run.json"
EPISODES_FILE = "episodes.jsonl"
TRAJECTORY_DIR = "trajectories"
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


# --- the output folder -----------------------------------------------------------------------


def check_out_usable(out: str | os.PathLike, *, resume: bool = False, force: bool = False) -> Path:
    """``out`` as a Path if it can be a run's folder at all; a :class:`RunError` when it
    cannot: a file, below a file, not writable (checked before the suite is read)."""
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
    return path


def check_out_dir(
    out: str | os.PathLike, *, resume: bool = False, force: bool = False, note: str = ""
) -> Path:
    """``out`` as a Path once it can hold this run; a :class:`RunError` before any work when
    it cannot: unusable (:func:`check_out_usable`), in use by another run (its lock:
    :mod:`shipgym_baselines.records.locking`), holding a link or a special file
    (:func:`~shipgym_baselines.records.outfiles.check_no_links`: a run writes through none), or
    not empty without ``resume`` / ``force`` (``note`` is added to that message, e.g.
    where a default folder came from; a lock file left by a killed run does not count)."""
    path = check_out_usable(out, resume=resume, force=force)
    holder = lock_holder(path)
    if holder is not None:
        raise in_use(path, holder)
    check_no_links(path)
    entries = sorted(p.name for p in path.iterdir() if not _is_lock(p)) if path.is_dir() else []
    if resume and RUN_FILE not in entries:
        raise RunError(f"--resume: {path} holds no run to resume (no {RUN_FILE})")
    if entries and not (resume or force):
        raise RunError(
            f"--out {path} is not empty ({_describe(path, entries)}){note}; pass --resume to "
            "finish that run, --force to replace it, or another --out"
        )
    return path


def _is_lock(entry: Path) -> bool:
    """Whether ``entry`` is a lock file (:data:`LOCK_FILE`, a regular file, not a link)."""
    return entry.name == LOCK_FILE and entry.is_file() and not entry.is_symlink()


def _describe(path: Path, entries: list[str]) -> str:
    """What an occupied folder holds, for the refusal message."""
    if RUN_FILE in entries:
        try:
            record = _read_json(path / RUN_FILE)
            status = record.get("status", "?") if isinstance(record, dict) else "unreadable"
            count = f"{len(read_episodes(path))} episodes"
        except RunError:
            return "an earlier run, unreadable"
        return f"an earlier run, {status}, {count}"
    shown = ", ".join(entries[:3]) + (", …" if len(entries) > 3 else "")
    return f"{len(entries)} entries: {shown}"


def clear_outputs(
    folder: str | os.PathLike, outputs: Sequence[str], option: str = "--force"
) -> None:
    """Remove the earlier outputs (names or glob patterns of ``outputs``) from ``folder``;
    a :class:`RunError`, before removing anything, when it holds anything else (a run's
    lock file, :data:`LOCK_FILE`, is neither)."""
    path = Path(folder)
    if not path.is_dir():
        return
    entries = sorted(p for p in path.iterdir() if not _is_lock(p))  # not an output
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
    root = Path(__file__).resolve().parents[2]  # baselines/records/runs.py -> the checkout
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
    """A run folder's ``run.json``; a :class:`RunError` naming the folder if it has none,
    or naming the file and the line or key where it is not a run record."""
    file = Path(folder) / RUN_FILE
    if not file.is_file():
        raise RunError(f"{folder}: not a run folder (no {RUN_FILE})")
    record = _read_json(file)
    problem = _run_record_problem(record)
    if problem:
        raise RunError(f"{file}: not a run record ({problem})")
    return record


def _run_record_problem(record: Any) -> str | None:
    """What makes ``record`` no run record (the key and the problem), or None."""
    if not isinstance(record, dict) or not isinstance(record.get("suite"), dict):
        return "no 'suite'"
    suite = record["suite"]
    checks = (
        ("seeds", list, lambda v: all(type(x) is int for x in v), "a list of integers"),
        ("scenarios", dict, lambda v: all(isinstance(x, dict) for x in v.values()), "settings"),
        ("controllers", list, _controller_entries, "entries of name, kind, training_seeds"),
        ("does_not_apply", list, _pairs, "[scenario, controller] pairs"),
    )
    for key, kind, valid, what in checks:
        value = suite.get(key)
        if not isinstance(value, kind) or not valid(value):
            return f"key 'suite.{key}' is {_short(value)}, not {what}"
    if not isinstance(suite.get("randomize"), dict | None):
        return f"key 'suite.randomize' is {_short(suite.get('randomize'))}, not ranges or null"
    return None


def _controller_entries(value: list) -> bool:
    return all(
        isinstance(c, dict)
        and isinstance(c.get("name"), str)
        and isinstance(c.get("kind"), str)
        and isinstance(c.get("training_seeds"), list)
        and all(s is None or type(s) is int for s in c["training_seeds"])
        for c in value
    )


def _pairs(value: list) -> bool:
    return all(
        isinstance(p, list) and len(p) == 2 and all(isinstance(x, str) for x in p) for p in value
    )


def _read_json(file: Path) -> Any:
    try:
        return json.loads(file.read_bytes().decode("utf-8"))
    except UnicodeDecodeError as exc:
        line = file.read_bytes()[: exc.start].count(b"\n") + 1
        raise RunError(f"{file}: line {line}: not UTF-8 text") from None
    except json.JSONDecodeError as exc:
        raise RunError(f"{file}: line {exc.lineno}: not JSON ({exc.msg})") from None
    except OSError as exc:
        raise RunError(f"{file}: unreadable ({exc.strerror})") from None


def write_json(file: Path, document: Any) -> None:
    """Write atomically, through no link
    (:func:`~shipgym_baselines.records.outfiles.write_bytes`)."""
    from shipgym_baselines.jsonout import dumps

    write_bytes(file, (dumps(document, indent=2) + "\n").encode())


def as_json(document: Any) -> Any:
    """``document`` as it reads back from JSON (tuples → lists, numpy → Python)."""
    from shipgym_baselines.jsonout import dumps

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
    if isinstance(old, list) and isinstance(new, list):
        return _list_differences(old, new, where or "value")
    return [f"{where or 'value'}: {_short(old)} in the run, {_short(new)} now"]


def _item(value: Any) -> str:
    """A list item as a person names it: a mapping by its ``name``, else its JSON."""
    if isinstance(value, dict) and isinstance(value.get("name"), str):
        return value["name"]
    return _short(value, 30)


def _list_differences(old: list, new: list, where: str) -> list[str]:
    """How two lists differ: the items only in one (by name), else item by item."""
    a, b = [_item(v) for v in old], [_item(v) for v in new]
    if a != b:
        gone, added = [x for x in a if x not in b], [x for x in b if x not in a]
        parts = [f"{', '.join(gone)} only in the run"] if gone else []
        parts += [f"{', '.join(added)} only now"] if added else []
        return [f"{where}: {'; '.join(parts) or 'the same items in another order'}"]
    found = []
    for name, x, y in zip(a, old, new, strict=True):
        found += differences(x, y, f"{where}[{name}]")
    return found


def _short(value: Any, limit: int = 60) -> str:
    text = json.dumps(value)
    return text if len(text) <= limit else text[: limit - 1] + "…"


# --- episodes.jsonl --------------------------------------------------------------------------


def plain(value: Any) -> Any:
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
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [plain(v) for v in value]
    return value


def from_plain(value: Any) -> Any:
    """One value as :func:`plain` wrote it, read back: "inf" / "-inf" as ±inf, the rest as
    it is."""
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
    return plain({**head, **result.metrics})


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


#: metrics whose value is text or null (every other metric is a number, null, "inf" or
#: "-inf"): ``error`` is the one-line message of an episode its controller ended
TEXT_METRICS = ("termination_reason", "error")
#: metrics whose value is a boolean (true / false, or null)
BOOL_METRICS = ("success",)


class _Constant(ValueError):
    """A ``NaN`` / ``Infinity`` token: JSON's extension that strict JSON has not."""


def _no_constant(token: str) -> Any:
    raise _Constant(token)


def _metric_problem(key: str, value: Any) -> str | None:
    """Why ``value`` cannot be the metric ``key`` of an episode record, or None."""
    if key in TEXT_METRICS:
        return None if value is None or isinstance(value, str) else "not text"
    if key in BOOL_METRICS:
        return None if value is None or isinstance(value, bool) else "not true or false"
    if value is None or value in ("inf", "-inf"):
        return None
    if isinstance(value, bool):
        return f"not a number (only {', '.join(BOOL_METRICS)} is true or false)"
    if isinstance(value, int | float):
        try:
            finite = math.isfinite(value)
        except OverflowError:  # an integer beyond any float
            finite = False
        return None if finite else "not a finite number"
    return "not a number"


def _bad_line(file: Path, number: int, problem: str) -> RunError:
    return RunError(f"{file}: line {number}: {problem}")


def _check_episode(record: Any, file: Path, number: int) -> dict[str, Any]:
    """``record`` (one parsed line) if it is an episode record; else a :class:`RunError`
    naming the file, the line and the problem."""
    if not isinstance(record, dict):
        raise _bad_line(file, number, f"not an episode record (a JSON {type(record).__name__})")
    absent = [k for k in EPISODE_KEYS[:5] if k not in record]
    if absent:
        raise _bad_line(file, number, f"not an episode record (no {', '.join(absent)})")
    for key in ("scenario", "controller", "kind"):
        if not isinstance(record[key], str):
            raise _bad_line(file, number, f"{key} {_short(record[key])} is not text")
    for key in ("seed", "training_seed"):
        value = record[key]
        if not (isinstance(value, int) and not isinstance(value, bool)) and not (
            key == "training_seed" and value is None
        ):
            raise _bad_line(file, number, f"{key} {_short(value)} is not an integer")
    for key, value in record.items():
        if key in EPISODE_KEYS:
            continue
        problem = _metric_problem(key, value)
        if problem is not None:
            raise _bad_line(file, number, f"metric {key} is {_short(value)}, {problem}")
    return record


def _lines(file: Path) -> list[tuple[int, str]]:
    """The complete lines of ``file`` (numbered from 1), a last line cut short by a kill
    left out; a :class:`RunError` naming the line that is not UTF-8."""
    data = file.read_bytes()
    raw = data.split(b"\n")
    complete = raw[:-1]  # the part after the last newline: empty, or cut short by a kill
    lines = []
    for number, line in enumerate(complete, start=1):
        try:
            lines.append((number, line.decode("utf-8")))
        except UnicodeDecodeError:
            raise _bad_line(file, number, "not UTF-8 text") from None
    return lines


class _SuiteKeys(NamedTuple):
    """What a resolved suite (``run.json``'s) runs: scenarios, the (scenario, controller)
    pairs that apply, each scenario's evaluation seeds, each controller's training seeds."""

    scenarios: set[str]
    pairs: set[tuple[str, str]]
    seeds: dict[str, set[int]]  # scenario → its evaluation seeds
    trained: dict[str, set[int | None]]


def _suite_keys(suite: Mapping[str, Any]) -> _SuiteKeys:
    skip = {tuple(pair) for pair in suite["does_not_apply"]}
    trained = {c["name"]: set(c["training_seeds"]) for c in suite["controllers"]}
    pairs = {(s, c) for s in suite["scenarios"] for c in trained if (s, c) not in skip}
    fewer = suite.get("scenario_seeds", {})
    seeds = {s: set(fewer.get(s, suite["seeds"])) for s in suite["scenarios"]}
    return _SuiteKeys(set(suite["scenarios"]), pairs, seeds, trained)


def _foreign(key: Key, keys: _SuiteKeys) -> str | None:
    """Why the episode ``key`` is not one of a suite's (``keys``), or None when it is."""
    scenarios, pairs, seeds, trained = keys
    scenario, controller, seed, training_seed = key
    if controller not in trained:
        return f"controller {controller!r} is not in the run's suite"
    if scenario not in scenarios:
        return f"scenario {scenario!r} is not in the run's suite"
    if (scenario, controller) not in pairs:
        return f"{controller!r} does not apply to {scenario!r} in the run's suite"
    if seed not in seeds[scenario]:
        return f"seed {seed} is not one of the run's seeds of {scenario!r}"
    if training_seed not in trained[controller]:
        return f"training seed {training_seed} is not one of {controller!r}'s in the run"
    return None


def read_episodes(
    folder: str | os.PathLike, suite: Mapping[str, Any] | None = None
) -> list[dict[str, Any]]:
    """The finished episodes of a run folder, numbers restored (±inf), as a set keyed by
    the episode key: a line repeating an earlier one is dropped; a last line cut short by
    a kill is left out.  A :class:`RunError` naming the file and line for a line that is
    not an episode record (not UTF-8, not JSON, a ``NaN`` / ``Infinity`` token, not an
    object, a key missing, a value of the wrong type: :func:`_metric_problem`), repeats a
    key with other content, or (given ``suite``, as ``run.json`` records it) holds an
    episode that is not the suite's.  An episode its controller ended
    (``controller_error`` / ``controller_timeout``) may be recorded again: the later line
    is the episode (``--retry-failed`` runs it again, :meth:`RunLog.retry`)."""
    file = Path(folder) / EPISODES_FILE
    if not file.is_file():
        return []
    keys = None if suite is None else _suite_keys(suite)
    records: dict[Key, dict[str, Any]] = {}
    first: dict[Key, int] = {}
    for number, line in _lines(file):
        try:
            parsed = json.loads(line, parse_constant=_no_constant)
        except _Constant as exc:
            strict = f'{exc} is not strict JSON (write null or "inf")'
            raise _bad_line(file, number, strict) from None
        except ValueError:
            raise _bad_line(file, number, "not JSON") from None
        record = _check_episode(parsed, file, number)
        key = episode_key(record)
        if keys is not None and (why := _foreign(key, keys)) is not None:
            raise _bad_line(file, number, why)
        record = {k: from_plain(v) for k, v in record.items()}
        if key in records and not controller_failed(records[key]):
            if _same(records[key], record):
                continue  # the same episode written twice: one episode
            raise _bad_line(
                file,
                number,
                f"episode {json.dumps(list(key))} again, with other values than on line "
                f"{first[key]}",
            )
        records[key], first[key] = record, number
    return list(records.values())


def _same(a: Mapping[str, Any], b: Mapping[str, Any]) -> bool:
    """Two records of one episode say the same, field by field (NaN equal to NaN)."""
    return _canonical(a) == _canonical(b)


def _canonical(record: Mapping[str, Any]) -> str:
    return json.dumps(plain(dict(record)), sort_keys=True)


def _repair(file: Path) -> None:
    """Cut a partial last line (a run killed while writing it) off ``file``."""
    if not file.is_file():
        return
    data = file.read_bytes()
    if data and not data.endswith(b"\n"):
        fd = open_regular(file, os.O_WRONLY)
        try:
            os.ftruncate(fd, data.rfind(b"\n") + 1)
        finally:
            os.close(fd)


def light_trajectory(trajectory: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """A trajectory as its file keeps it, compact so that a run folder stays small: only the
    arrays a figure draws (:data:`~shipgym_baselines.records.trajectories.DRAWN_KEYS`), thinned to
    what a figure can show without aliasing (M4,
    :func:`~shipgym_baselines.records.trajectories.thin_trajectory`), packed as 16-bit codes over
    each array's range (:func:`~shipgym_baselines.records.trajectories.pack_trajectory`: within
    range / 131068, far below a figure's pixel; the episode's metrics are computed
    before, at full precision); the file is deflated (``np.savez_compressed``).
    :func:`read_trajectory` reads it back."""
    return pack_trajectory(thin_trajectory(trajectory, DRAWN_KEYS))


def read_trajectory(file: Path) -> dict[str, np.ndarray]:
    """A kept trajectory's arrays (:func:`light_trajectory`'s file, or an earlier
    version's file of plain arrays)."""
    with np.load(file, allow_pickle=False) as data:
        fields = {k: data[k] for k in data.files}
    if set(fields) == {"keys", "ranges", "codes"}:
        return unpack_trajectory(fields)
    return fields


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
    """An :class:`~shipgym_baselines.records.episodes.EpisodeResult` from a record of ``folder``'s
    ``episodes.jsonl`` (its trajectory read if it was kept, else empty; a record of an
    earlier version names its file as ``trajectory``)."""
    trajectory: dict[str, np.ndarray] = {}
    name = record.get("trajectory") or trajectory_file(episode_key(record))
    if name:
        file = _inside(Path(folder), name)
        if file.is_file():
            trajectory = read_trajectory(file)
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
    ) -> RunLog:
        """Lock ``out`` and start a run there (``force``: the paths its manifest lists
        removed first) or resume the one there (its suite must equal ``suite``: else a
        :class:`RunError` naming what differs).  Writes ``run.json`` with status
        "running".  The lock is held until :meth:`recording` ends (or this fails)."""
        check_out_usable(out, resume=resume, force=force)
        lock = contextlib.ExitStack()
        start = now()
        folder = lock.enter_context(out_lock(out, start))
        try:
            log = cls._start(folder, command, suite, jobs, resume, force, start)
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
            episodes = read_episodes(folder, suite=record["suite"])
            _repair(folder / EPISODES_FILE)
            resumed = {"time": now(), "command": command, "git_commit": git_commit()}
            record.setdefault("resumed", []).append({**resumed, "versions": versions()})
            record.update(status="running", end_time=None, jobs=jobs)
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
        self._count = len(read_episodes(self.folder))  # the file's count: Ctrl-C may cut in
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
            from shipgym_baselines.jsonout import dumps

            data = (dumps(self.record) + "\n").encode()
            if len(data) <= file.stat().st_size:
                with contextlib.suppress(OSError), open(open_regular(file, os.O_RDWR), "r+b") as fh:
                    fh.write(data)
                    fh.truncate()


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
    "BACKENDS",
    "EPISODES_FILE",
    "NO_ROOM",
    "RUN_FILE",
    "RunInterrupted",
    "RunLog",
    "check_out_dir",
    "check_out_usable",
    "clear_outputs",
    "differences",
    "episode_result",
    "from_plain",
    "outside_problem",
    "plain",
    "read_episodes",
    "read_run",
    "versions",
    "write_json",
]
