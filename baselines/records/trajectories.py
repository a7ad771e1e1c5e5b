"""The trajectories a run folder keeps (``trajectories/``, one file per drawn episode:
:func:`trajectory_file`), thinned to what a figure can show, without aliasing, and packed,
so that a run folder stays small; an episode record read back with its trajectory
(:func:`episode_result`).

:func:`m4_indices` is M4 (Jugel et al. 2014, "M4: a visualization-oriented time series data
aggregation", PVLDB 7(10)): the time axis is cut into ``buckets`` equal spans (one per pixel
column of the panel that draws it) and in each span the first, last, smallest and largest
sample of each series is kept.  A line through the kept samples covers, in every pixel
column, the same vertical extent as the line through all samples, so a rudder in a ±35°
limit cycle still fills its band; a plain stride would alias it into a slow wave.
:func:`thin_trajectory` applies it to every drawn series at once (one set of kept indices,
so the arrays stay aligned).
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from shipgym_baselines.errors import RunError
from shipgym_baselines.records.episodes import (
    EPISODE_KEYS,
    EPISODES_FILE,
    EpisodeResult,
    Key,
    episode_key,
)

#: the folder of a run's kept trajectories
TRAJECTORY_DIR = "trajectories"

#: the arrays a scenario figure draws (:func:`shipgym_baselines.plots.scenarios.plot_scenario`),
#: the only ones a run folder keeps of a trajectory: time [s], position [m], cross-track error
#: [m], rudder angle [rad]
DRAWN_KEYS = ("t", "x", "y", "cross_track_error", "rudder_angle")
#: time buckets of a kept trajectory: the width [px] of a scenario figure's panel drawn at
#: 200 dpi (2.4 in), so every pixel column of the drawn line keeps its extent
TRACE_BUCKETS = 480


def m4_indices(t: Any, series: Iterable[Any], buckets: int = TRACE_BUCKETS) -> np.ndarray:
    """Sorted indices of the samples M4 keeps: of each of ``buckets`` equal spans of ``t``
    (increasing, e.g. [s]), the first and last sample and, per array of ``series`` (each as
    long as ``t``), its smallest and largest finite value; NaNs kept where a span holds
    them.  All indices when ``t`` has at most ``4 * buckets`` samples."""
    t = np.asarray(t, dtype=np.float64)
    n = t.size
    if n <= 4 * buckets:
        return np.arange(n)
    span = t[-1] - t[0]
    where = np.zeros(n, dtype=np.int64)
    if span > 0:
        where = np.minimum(((t - t[0]) / span * buckets).astype(np.int64), buckets - 1)
    starts = np.flatnonzero(np.r_[True, where[1:] != where[:-1]])
    ends = np.r_[starts[1:], n] - 1
    keep = [starts, ends]
    for values in series:
        v = np.asarray(values, dtype=np.float64)
        finite = np.isfinite(v)
        low = np.where(finite, v, np.inf)
        high = np.where(finite, v, -np.inf)
        for lo, hi in zip(starts, ends + 1, strict=True):
            keep.append(np.array([lo + np.argmin(low[lo:hi]), lo + np.argmax(high[lo:hi])]))
        keep.append(np.flatnonzero(~finite))
    return np.unique(np.concatenate(keep))


def thin_trajectory(
    trajectory: Mapping[str, Any], keys: Iterable[str], buckets: int = TRACE_BUCKETS
) -> dict[str, np.ndarray]:
    """The arrays ``keys`` of ``trajectory`` (``t`` [s] and series as long as it) at the
    samples :func:`m4_indices` keeps of all of them (``t`` aside)."""
    keys = [k for k in keys if k in trajectory]
    t = np.asarray(trajectory["t"])
    index = m4_indices(t, [trajectory[k] for k in keys if k != "t"], buckets)
    return {k: np.asarray(trajectory[k])[index] for k in keys}


#: levels of a packed array: 16-bit codes over its finite range, the top code for a
#: non-finite value (a finite value is within range / 131068 of what was drawn: 0.05 m on a
#: 6 km track, 10⁻⁵ rad of rudder, far below a figure's pixel)
_LEVELS = 65534
_NON_FINITE = 65535


def pack_trajectory(arrays: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """Equal-length float arrays (a thinned trajectory) as a kept file holds them, compact
    so that a run folder stays small: ``keys`` (their names), ``ranges`` (per array its finite
    [min, max], float64) and ``codes`` (per array 16-bit codes over that range, each the
    difference from the previous one, mod 2¹⁶: a smooth series has small steps, which
    deflate well).  :func:`unpack_trajectory` inverts it to within range / 131068."""
    keys = list(arrays)
    codes = np.zeros((len(keys), len(arrays[keys[0]]) if keys else 0), dtype=np.uint16)
    ranges = np.zeros((len(keys), 2))
    for row, key in enumerate(keys):
        a = np.asarray(arrays[key], dtype=np.float64)
        finite = np.isfinite(a)
        if finite.any():
            ranges[row] = a[finite].min(), a[finite].max()
        low, high = ranges[row]
        scale = (high - low) / _LEVELS if high > low else 1.0
        level = np.round((np.where(finite, a, low) - low) / scale)
        q = np.where(finite, level, _NON_FINITE).astype(np.uint16)
        codes[row] = np.diff(q, prepend=np.uint16(0))  # uint16 arithmetic wraps
    return {"keys": np.array(keys, dtype=str), "ranges": ranges, "codes": codes}


def unpack_trajectory(packed: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """The arrays of :func:`pack_trajectory`'s fields (float64; NaN where a value was not
    finite)."""
    out = {}
    for key, (low, high), steps in zip(
        packed["keys"].tolist(), packed["ranges"], packed["codes"], strict=True
    ):
        q = np.cumsum(steps, dtype=np.uint16)  # wraps as the differences did
        scale = (high - low) / _LEVELS if high > low else 1.0
        out[str(key)] = np.where(q == _NON_FINITE, np.nan, low + q * scale)
    return out


def light_trajectory(trajectory: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """A trajectory as its file keeps it, compact so that a run folder stays small: only the
    arrays a figure draws (:data:`DRAWN_KEYS`), thinned to what a figure can show without
    aliasing (M4, :func:`thin_trajectory`), packed as 16-bit codes over each array's range
    (:func:`pack_trajectory`: within range / 131068, far below a figure's pixel; the
    episode's metrics are computed before, at full precision); the file is deflated
    (``np.savez_compressed``).  :func:`read_trajectory` reads it back."""
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


__all__ = [
    "DRAWN_KEYS",
    "TRACE_BUCKETS",
    "TRAJECTORY_DIR",
    "episode_result",
    "light_trajectory",
    "m4_indices",
    "pack_trajectory",
    "read_trajectory",
    "thin_trajectory",
    "trajectory_file",
    "unpack_trajectory",
]
