"""Reference data: the privileged references' episodes, computed once and shipped (as D4RL's
scores).

The ``oracle`` (:mod:`shipgym_baselines.classical.oracle`) is the denominator of the
leaderboard's cost ratio on every scenario trial, and ``oracle_frozen`` (the same NMPC with its
truth frozen at the episode's start) says what a controller that never adapts can reach.  Their
episodes are deterministic given the trial (the resolved scenario a suite's seed draws) and the
env seed, so they are computed once per trial, frozen per env revision
(:data:`shipgym.envs.core.ENV_REVISION`), oracle revision and settings, and shipped, one table
per reference, in ``baselines/reference_data/<reference>.json.gz``:

    {"format": 2, "env_revision": R, "reference": "oracle", "oracle": {settings},
     "entries": {
        "<scenario content hash>:<seed>": {"scenario": name, "metrics": {...},
                                           "trace": {"t": [...], "x": [...], ...}}}}

The content hash is the SHA-256 of the resolved scenario's settings as canonical JSON
(:func:`scenario_key`), so an edited scenario never meets a stale entry.  ``trace`` holds
the figure's columns (:data:`TRACE_KEYS`) thinned to at most :data:`TRACE_POINTS` points.
The leaderboard reads an entry for each reference episode and runs the reference only for a
trial missing from its table (``--recompute-references``: for every trial); a table of another
env revision, oracle revision or other oracle settings is ignored as a whole (every trial is
then computed).  ``shipgym references`` fills a table (resumable: it writes after every
episode); :func:`fill_tables` refuses to fill a file of another header (:func:`foreign`)
unless asked to replace it, and then keeps the old file beside it (:func:`backup_path`).

A trial the shipped table lacks (an own scenario, a suite's extra seeds) is computed once per
user: :class:`ReferenceCache` keeps its entry in a table of the same format at
:func:`user_cache_path`, ``references/<reference>.json.gz`` in the per-user cache folder
(:func:`shipgym.codegen.user_cache_dir`: ``$SHIPGYM_CACHE_DIR``, else
``$XDG_CACHE_HOME/shipgym``, else ``~/.cache/shipgym``).  Lookups go shipped table → user
cache → compute and store.  Several processes may store at once: each store re-reads the
file, merges and replaces it atomically under an exclusive lock (``fcntl.lockf`` on a
``.lock`` file beside it).  A cache file that cannot be read (cut short, not gzip, no table)
is set aside as ``<file>.bad`` (:func:`set_aside_path`) with one line naming it, and the cache
starts afresh.  Before computing, :func:`announce` says how many and an estimate
of their CPU time (:data:`ORACLE_CPU_S_PER_STEP`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import fcntl
import functools
import gzip
import hashlib
import io
import json
import math
import os
from collections.abc import Iterable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.codegen import user_cache_dir
from shipgym.envs.core import ENV_REVISION
from shipgym.notices import duration, notice
from shipgym.scenarios.loader import Scenario
from shipgym_baselines.errors import RunError
from shipgym_baselines.privileged import ORACLE, ORACLE_FROZEN
from shipgym_baselines.records.episodes import EpisodeResult
from shipgym_baselines.records.jsonfiles import from_plain, plain
from shipgym_baselines.records.outfiles import open_regular, refuse_special, write_bytes

#: the references with a table, in the order they are computed
REFERENCES = (ORACLE, ORACLE_FROZEN)
#: the oracle's table file (each reference's: :func:`table_file`)
TABLE_FILE = f"{ORACLE}.json.gz"
FORMAT = 2
#: the columns of a reference episode's trajectory kept in the table (the figures' traces)
TRACE_KEYS = ("t", "x", "y", "cross_track_error", "rudder_angle")
#: at most this many points per trace (evenly thinned, the last kept)
TRACE_POINTS = 200
#: significant digits of the stored trace values
TRACE_DIGITS = 6


def table_file(reference: str = ORACLE) -> str:
    """The file name of ``reference``'s table: ``<reference>.json.gz``."""
    if reference not in REFERENCES:
        raise ValueError(f"no reference table for {reference!r}: one of {REFERENCES}")
    return f"{reference}.json.gz"


def table_path(reference: str = ORACLE) -> Path:
    """The shipped table's path of ``reference`` (inside the installed package)."""
    return Path(__file__).parent / "reference_data" / table_file(reference)


def scenario_key(scenario: Scenario) -> str:
    """SHA-256 (16 hex digits) of the resolved scenario's settings as canonical JSON."""
    config = scenario.config.model_dump(mode="json")
    text = json.dumps(config, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def entry_key(scenario: Scenario, seed: int) -> str:
    return f"{scenario_key(scenario)}:{int(seed)}"


def oracle_header(reference: str = ORACLE) -> dict[str, Any]:
    """The header ``reference``'s table must carry to be valid now (format, env revision,
    the reference, oracle revision and settings)."""
    from shipgym_baselines.classical.oracle import ORACLE_REVISION, OracleSettings

    return {
        "format": FORMAT,
        "env_revision": ENV_REVISION,
        "reference": reference,
        "oracle": {"revision": ORACLE_REVISION, **dataclasses.asdict(OracleSettings())},
    }


def thin_trace(trajectory: Mapping[str, np.ndarray]) -> dict[str, list[float]]:
    """The :data:`TRACE_KEYS` of a trajectory, at most :data:`TRACE_POINTS` points each."""
    n = len(trajectory["t"])
    index = np.unique(np.r_[np.linspace(0, n - 1, min(n, TRACE_POINTS)).round().astype(int)])
    return {
        k: [float(f"{v:.{TRACE_DIGITS}g}") for v in np.asarray(trajectory[k])[index]]
        for k in TRACE_KEYS
        if k in trajectory
    }


@dataclasses.dataclass
class ReferenceTable:
    """A reference's episodes (module doc), by :func:`entry_key`."""

    entries: dict[str, dict[str, Any]]
    path: Path | None = None
    reference: str = ORACLE

    @classmethod
    def load(cls, path: str | os.PathLike | None = None, reference: str = ORACLE) -> ReferenceTable:
        """``reference``'s table at ``path`` (default: the shipped one); empty if there is
        none, or if it was computed for another reference, env revision, oracle revision
        or other oracle settings."""
        file = Path(path) if path is not None else table_path(reference)
        if not file.is_file():
            return cls({}, file, reference)
        with gzip.open(file, "rt", encoding="utf-8") as f:
            data = json.load(f)
        if not isinstance(data, dict) or not isinstance(data.get("entries", {}), dict):
            raise ValueError("no reference table: no JSON object of entries")
        wanted = oracle_header(reference)
        if {k: data.get(k) for k in wanted} != wanted:
            return cls({}, file, reference)
        return cls(dict(data.get("entries", {})), file, reference)

    def lookup(self, scenario: Scenario, seed: int) -> dict[str, Any] | None:
        return self.entries.get(entry_key(scenario, seed))

    def add(self, scenario: Scenario, result: EpisodeResult) -> None:
        """Record the reference's episode ``result`` of ``scenario`` (a trial)."""
        self.entries[entry_key(scenario, result.seed)] = table_entry(result)

    def store(self, scenario: Scenario, result: EpisodeResult) -> None:
        """:meth:`add` the episode, then :meth:`save` the table to its file."""
        self.add(scenario, result)
        self.save()

    def save(self, path: str | os.PathLike | None = None) -> Path:
        """Write the table atomically (sorted keys: the same entries give the same bytes)."""
        file = Path(path) if path is not None else (self.path or table_path(self.reference))
        file.parent.mkdir(parents=True, exist_ok=True)
        data = {**oracle_header(self.reference), "entries": dict(sorted(self.entries.items()))}
        raw = io.BytesIO()
        # no file name or time in the gzip header: the same entries give the same bytes
        with gzip.GzipFile(filename="", fileobj=raw, mode="wb", mtime=0) as f:
            f.write(json.dumps(data, allow_nan=False).encode())
        write_bytes(file, raw.getvalue())  # atomic, through no link
        return file


def table_entry(result: EpisodeResult) -> dict[str, Any]:
    """The table's entry of a reference's episode ``result``."""
    return {
        "scenario": result.scenario,
        "metrics": plain(result.metrics),  # ±inf as "inf" (episodes.jsonl's rule)
        "trace": thin_trace(result.trajectory),
    }


def foreign(path: str | os.PathLike, reference: str = ORACLE) -> str | None:
    """What keeps the file at ``path`` from being filled as ``reference``'s table, in words
    (``a table of another revision or settings (env_revision 3, not 4)``); None when there
    is no file or it holds such a table under the current header (:func:`oracle_header`)."""
    file = Path(path)
    if not file.exists():
        return None
    try:
        with gzip.open(file, "rt", encoding="utf-8") as f:
            data = json.load(f)
    except (OSError, EOFError, ValueError) as exc:
        return f"no reference table ({exc})"
    if not isinstance(data, dict):
        return "no reference table (no JSON object)"
    wanted, differences = oracle_header(reference), []
    for key, want in wanted.items():
        have = data.get(key, "missing")
        if key == "oracle" and isinstance(have, dict):
            differences += [
                f"oracle {k} {have.get(k, 'missing')}, not {want.get(k, 'none')}"
                for k in sorted(set(have) | set(want))
                if have.get(k) != want.get(k)
            ]
        elif have != want:
            differences.append(f"{key} {have}, not {want}")
    return (
        f"a table of another revision or settings ({'; '.join(differences)})"
        if differences
        else None
    )


def backup_path(path: str | os.PathLike) -> Path:
    """Where :func:`fill_tables` keeps a replaced table: ``<file>.bak`` beside it."""
    file = Path(path)
    return file.with_name(f"{file.name}.bak")


def fill_tables(
    files: Mapping[str, str | os.PathLike], replace: bool = False
) -> dict[str, ReferenceTable]:
    """The :class:`ReferenceTable` of each reference in ``files`` (reference -> file) to fill:
    its entries when the file holds its table under the current header (none: empty).  A
    file of another format, env revision, reference, oracle revision or oracle settings, or
    no table at all (:func:`foreign`), is refused (:class:`RunError` naming the file and what
    differs) unless ``replace``: then its bytes are kept as :func:`backup_path` (refused when
    that file exists with other bytes: it is never overwritten) and the file starts afresh.
    A link or anything but a regular file in a file's place is refused too (a table is
    written through no link).  Every refusal comes before any file is written."""
    tables: dict[str, ReferenceTable] = {}
    replaced = []
    for path in files.values():  # written through no link: refused before any work
        refuse_special(path, "--table")
    for ref, path in files.items():
        why = foreign(path, ref)
        if why is None:
            tables[ref] = ReferenceTable.load(path, ref)
            continue
        file, bak = Path(path), backup_path(path)
        if not file.is_file():
            raise RunError(f"{file} is no file: a table is a file (*.json.gz)")
        if not replace:
            raise RunError(
                f"{file} holds {why}: --replace replaces it (keeping the old file as {bak})"
            )
        if bak.exists() and (not bak.is_file() or bak.read_bytes() != file.read_bytes()):
            raise RunError(
                f"--replace keeps {file} as {bak}, which exists: move that file away first"
            )
        replaced.append(ref)
    for ref in replaced:
        file, bak = Path(files[ref]), backup_path(files[ref])
        if not bak.exists():  # else it holds these bytes already (an interrupted --replace)
            with open(bak, "xb") as kept:
                kept.write(file.read_bytes())
        tables[ref] = ReferenceTable({}, file, ref)
        tables[ref].save()  # the current header: a resumed fill needs no --replace
    return {ref: tables[ref] for ref in files}


@functools.cache
def shipped_table(reference: str = ORACLE) -> ReferenceTable:
    """``reference``'s shipped table, loaded once per process."""
    return ReferenceTable.load(reference=reference)


def result_from_entry(
    entry: Mapping[str, Any], scenario: str, seed: int, reference: str = ORACLE
) -> EpisodeResult:
    """``reference``'s :class:`EpisodeResult` of a table entry (its trajectory: the trace)."""
    metrics = {k: from_plain(v) for k, v in entry["metrics"].items()}
    return EpisodeResult(
        controller=reference,
        kind="reference",
        scenario=scenario,
        seed=int(seed),
        metrics=metrics,
        trajectory={k: np.asarray(v, dtype=float) for k, v in entry.get("trace", {}).items()},
        training_seed=None,
    )


def missing_trials(
    table: ReferenceTable, trials: Iterable[tuple[Scenario, int]]
) -> list[tuple[Scenario, int]]:
    """The (trial, seed) pairs the table does not hold."""
    return [(sc, seed) for sc, seed in trials if table.lookup(sc, seed) is None]


# --- the per-user cache ----------------------------------------------------------------------


def user_cache_path(reference: str = ORACLE) -> Path:
    """The per-user cache of ``reference``'s computed episodes (module doc)."""
    return user_cache_dir() / "references" / table_file(reference)


@contextlib.contextmanager
def _locked(file: Path) -> Iterator[None]:
    """Hold the exclusive lock of ``file`` (on ``<file>.lock``; waits for another holder)."""
    file.parent.mkdir(parents=True, exist_ok=True)
    fd = open_regular(file.with_name(file.name + ".lock"), os.O_RDWR | os.O_CREAT)  # no link
    try:
        fcntl.lockf(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # closing releases the lock


def set_aside_path(path: str | os.PathLike) -> Path:
    """Where an unreadable cache file is moved: ``<file>.bad`` beside it (an earlier one
    replaced)."""
    file = Path(path)
    return file.with_name(f"{file.name}.bad")


class ReferenceCache:
    """The per-user cache (module doc) of ``reference``'s episodes: a
    :class:`ReferenceTable` file, re-read when another process replaced it, stored to under
    a lock.  ``path``: its file (default: :func:`user_cache_path`)."""

    def __init__(self, path: str | os.PathLike | None = None, reference: str = ORACLE) -> None:
        self.reference = reference
        self.path = Path(path) if path is not None else user_cache_path(reference)
        self._table = ReferenceTable({}, self.path, reference)
        self._stamp: tuple[int, int, int] | None = None

    def _load(self) -> ReferenceTable:
        """The table as on disk now (read again only when the file changed)."""
        try:
            stat = self.path.stat()
        except FileNotFoundError:
            self._table, self._stamp = ReferenceTable({}, self.path, self.reference), None
            return self._table
        stamp = (stat.st_ino, stat.st_mtime_ns, stat.st_size)
        if stamp != self._stamp:
            try:
                self._table = ReferenceTable.load(self.path, self.reference)
            except (OSError, EOFError, ValueError) as exc:
                self._set_aside(stamp, exc)
                return self._load()
            self._stamp = stamp
        return self._table

    def _set_aside(self, stamp: tuple[int, int, int], exc: Exception) -> None:
        """Move the unreadable file (``stamp``: as it was read) to :func:`set_aside_path`,
        under the lock and only if no other process replaced it meanwhile, saying so in one
        line: the cache starts afresh (it holds only computed references)."""
        with _locked(self.path):
            try:
                stat = self.path.stat()
            except FileNotFoundError:
                return  # another process set it aside
            if (stat.st_ino, stat.st_mtime_ns, stat.st_size) != stamp:
                return  # another process replaced it: read that one
            bad = set_aside_path(self.path)
            os.replace(self.path, bad)
        notice(
            f"shipgym: the reference cache {self.path} is unreadable ({exc}): set aside as "
            f"{bad}; its references are computed again when needed"
        )

    def lookup(self, scenario: Scenario, seed: int) -> dict[str, Any] | None:
        return self._load().lookup(scenario, seed)

    def store(self, scenario: Scenario, result: EpisodeResult) -> dict[str, Any]:
        """Add the reference's episode ``result`` of ``scenario``: re-read, merge and replace
        the file under its lock (entries stored meanwhile by other processes are kept; a
        file of another revision is replaced).  Returns the entry."""
        entry = table_entry(result)
        with _locked(self.path):
            self._stamp = None  # read what is on disk now
            table = self._load()
            table.entries[entry_key(scenario, result.seed)] = entry
            table.save(self.path)
            stat = self.path.stat()
            self._stamp = (stat.st_ino, stat.st_mtime_ns, stat.st_size)
        return entry


def lookup(
    scenario: Scenario, seed: int, cache: ReferenceCache | None = None, reference: str = ORACLE
) -> dict[str, Any] | None:
    """``reference``'s entry of the trial: the shipped table's, else the user cache's (None:
    neither); ``cache`` holds the same reference's episodes."""
    if cache is not None and cache.reference != reference:
        raise ValueError(f"a cache of {cache.reference} looked up for {reference}")
    entry = shipped_table(reference).lookup(scenario, seed)
    if entry is None and cache is not None:
        entry = cache.lookup(scenario, seed)
    return entry


# --- announcing a computation ----------------------------------------------------------------

#: the oracle's CPU seconds per control step of a trial at its full length (time limit over
#: control period), by ship: the validation split's 8 episodes per ship (``shipgym references
#: --packaged --validation --workers 1``, a cold compilation cache), the oracle's CPU and its C
#: compilations' (each trial's solver is compiled anew) over the full-length steps; episodes
#: that reach the goal early cost less
ORACLE_CPU_S_PER_STEP: dict[str, float] = {
    "nomoto2": 0.0026,  # 3.9 CPU s (2.6 of it gcc) for 1512 steps
    "esso_osaka": 0.0133,  # 135.0 CPU s (84.3 gcc) for 10136 steps
    "mariner": 0.0023,  # 48.3 CPU s (10.2 gcc) for 20683 steps
    "blanke": 0.0039,  # 87.1 CPU s (12.8 gcc) for 22595 steps
}


def estimate_cpu_s(trials: Iterable[Scenario]) -> float:
    """The oracle's estimated CPU seconds on ``trials`` (each at its full length; a ship
    not measured at the slowest ship's rate)."""
    slowest = max(ORACLE_CPU_S_PER_STEP.values())
    total = 0.0
    for trial in trials:
        steps = math.ceil(trial.config.time_limit / trial.control_period)
        total += steps * ORACLE_CPU_S_PER_STEP.get(trial.model.name, slowest)
    return total


def announce(trials: Sequence[Scenario], where: str, reference: str = ORACLE) -> None:
    """One line on stderr before ``reference`` runs on ``trials``: how many, the estimated
    CPU time, ``where`` the results go."""
    if not trials:
        return
    n = len(trials)
    notice(
        f"shipgym: computing {n} {reference} reference{'s' if n != 1 else ''} "
        f"(≈ {duration(estimate_cpu_s(trials))} CPU; {where})"
    )
