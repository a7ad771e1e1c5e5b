"""Thinning a trajectory to what a figure can show, without aliasing (issue 20).

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

#: the arrays a scenario figure draws (:func:`shipgym_baselines.figures.plot_scenario`), the
#: only ones a run folder keeps of a trajectory: time [s], position [m], cross-track error
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


__all__ = ["DRAWN_KEYS", "TRACE_BUCKETS", "m4_indices", "thin_trajectory"]
