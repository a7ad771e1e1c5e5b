"""Thinning a trajectory to what a figure can show, without aliasing, so that a run folder
stays small.

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

from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

#: the arrays a scenario figure draws (:func:`shipgym_baselines.leaderboard.figures.plot_scenario`),
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


__all__ = [
    "DRAWN_KEYS",
    "TRACE_BUCKETS",
    "m4_indices",
    "pack_trajectory",
    "thin_trajectory",
    "unpack_trajectory",
]
