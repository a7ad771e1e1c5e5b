"""Reference data: the ``oracle``'s episodes, computed once and shipped (as D4RL's scores).

The oracle (:mod:`shipgym_baselines.classical.oracle`) is the denominator of the leaderboard's cost
ratio on every scenario trial.  Its episodes are deterministic given the trial (the resolved
scenario a suite's seed draws) and the env seed, so they are computed once per trial, frozen
per env revision (:data:`shipgym.envs.core.ENV_REVISION`), oracle revision and settings, and
shipped
in ``baselines/reference_data/oracle.json.gz``:

    {"format": 1, "env_revision": R, "oracle": {settings}, "entries": {
        "<scenario content hash>:<seed>": {"scenario": name, "metrics": {...},
                                           "trace": {"t": [...], "x": [...], ...}}}}

The content hash is the SHA-256 of the resolved scenario's settings as canonical JSON
(:func:`scenario_key`), so an edited scenario never meets a stale entry.  ``trace`` holds
the figure's columns (:data:`TRACE_KEYS`) thinned to at most :data:`TRACE_POINTS` points.
The leaderboard reads an entry for each oracle episode and runs the oracle only for a trial
missing from the table (``--recompute-references``: for every trial); ``shipgym references``
fills the table (resumable: it writes after every episode).  A table of another env revision
or other oracle settings is ignored as a whole (every trial is then computed).
"""

from __future__ import annotations

import dataclasses
import functools
import gzip
import hashlib
import json
import os
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from shipgym.envs.core import ENV_REVISION
from shipgym.scenarios import Scenario
from shipgym_baselines.runs import _number, _plain

if TYPE_CHECKING:
    from shipgym_baselines.evaluation import EpisodeResult

TABLE_FILE = "oracle.json.gz"
FORMAT = 1
#: the columns of a reference episode's trajectory kept in the table (the figures' traces)
TRACE_KEYS = ("t", "x", "y", "cross_track_error", "rudder_angle")
#: at most this many points per trace (evenly thinned, the last kept)
TRACE_POINTS = 200
#: significant digits of the stored trace values
TRACE_DIGITS = 6


def table_path() -> Path:
    """The shipped table's path (inside the installed package)."""
    return Path(__file__).parent / "reference_data" / TABLE_FILE


def scenario_key(scenario: Scenario) -> str:
    """SHA-256 (16 hex digits) of the resolved scenario's settings as canonical JSON."""
    config = scenario.config.model_dump(mode="json")
    text = json.dumps(config, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def entry_key(scenario: Scenario, seed: int) -> str:
    return f"{scenario_key(scenario)}:{int(seed)}"


def oracle_header() -> dict[str, Any]:
    """The header a table must carry to be valid now (env revision, oracle settings)."""
    from shipgym_baselines.classical.oracle import ORACLE_REVISION, OracleSettings

    return {
        "format": FORMAT,
        "env_revision": ENV_REVISION,
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
    """The oracle's reference episodes (module doc), by :func:`entry_key`."""

    entries: dict[str, dict[str, Any]]
    path: Path | None = None

    @classmethod
    def load(cls, path: str | os.PathLike | None = None) -> ReferenceTable:
        """The table at ``path`` (default: the shipped one); empty if there is none, or if
        it was computed for another env revision or other oracle settings."""
        file = Path(path) if path is not None else table_path()
        if not file.is_file():
            return cls({}, file)
        with gzip.open(file, "rt", encoding="utf-8") as f:
            data = json.load(f)
        header = {k: data.get(k) for k in ("format", "env_revision", "oracle")}
        if header != oracle_header():
            return cls({}, file)
        return cls(dict(data.get("entries", {})), file)

    def lookup(self, scenario: Scenario, seed: int) -> dict[str, Any] | None:
        return self.entries.get(entry_key(scenario, seed))

    def add(self, scenario: Scenario, result: EpisodeResult) -> None:
        """Record the oracle's episode ``result`` of ``scenario`` (a trial)."""
        self.entries[entry_key(scenario, result.seed)] = {
            "scenario": result.scenario,
            "metrics": _plain(result.metrics),  # ±inf as "inf" (episodes.jsonl's rule)
            "trace": thin_trace(result.trajectory),
        }

    def save(self, path: str | os.PathLike | None = None) -> Path:
        """Write the table atomically (sorted keys: the same entries give the same bytes)."""
        file = Path(path) if path is not None else (self.path or table_path())
        file.parent.mkdir(parents=True, exist_ok=True)
        data = {**oracle_header(), "entries": dict(sorted(self.entries.items()))}
        staged = file.with_name(f"{file.name}.{os.getpid()}.tmp")
        with open(staged, "wb") as raw, gzip.GzipFile(fileobj=raw, mode="wb", mtime=0) as f:
            f.write(json.dumps(data, allow_nan=False).encode())
        os.replace(staged, file)
        return file


@functools.lru_cache(maxsize=1)
def shipped_table() -> ReferenceTable:
    """The shipped table, loaded once per process."""
    return ReferenceTable.load()


def result_from_entry(entry: Mapping[str, Any], scenario: str, seed: int) -> EpisodeResult:
    """The oracle's :class:`EpisodeResult` of a table entry (its trajectory: the trace)."""
    from shipgym_baselines.evaluation import EpisodeResult

    metrics = {k: _number(v) for k, v in entry["metrics"].items()}
    return EpisodeResult(
        controller="oracle",
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
