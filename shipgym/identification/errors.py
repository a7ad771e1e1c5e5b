"""The identification toolkit's error type and its checks of bad input (before any work)."""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from shipgym.errors import ShipgymError


class IdentificationError(ShipgymError, ValueError):
    """The data cannot identify the model (degenerate, too short, non-physical result), or
    an identifier was given a bad setting or bad samples."""


def check_sampling_step(h: Any) -> float:
    """The sampling step h [s] as a float; IdentificationError naming h unless finite > 0."""
    if isinstance(h, bool) or not isinstance(h, numbers.Real):
        raise IdentificationError(f"the sampling step h must be a number [s], got {h!r}")
    value = float(h)
    if not (math.isfinite(value) and value > 0.0):
        raise IdentificationError(f"the sampling step h must be finite and > 0 s, got {h!r}")
    return value


def check_sample_keys(samples: Mapping[str, Any], needed: Iterable[str]) -> None:
    """IdentificationError naming the missing keys of ``samples`` and the keys needed."""
    needed = tuple(needed)
    if not isinstance(samples, Mapping):
        raise IdentificationError(
            f"samples must be a mapping with keys {', '.join(needed)}, got {type(samples).__name__}"
        )
    missing = [k for k in needed if k not in samples]
    if missing:
        raise IdentificationError(
            f"samples lack {', '.join(repr(k) for k in missing)}: the identifier needs "
            f"{', '.join(repr(k) for k in needed)} (as in info['samples'])"
        )


#: the sampled signals of a nomoto2 log, in the order the identifiers take them
LOG_NAMES = ("psi", "delta", "delta_c")
#: a log must span this many of the model's slowest time constant (T1) to identify it: at
#: h = 0.01 s, 2.4·T1 of data leave K 1–3 % off, 5·T1 under 1 % (Liu et al.'s ship)
MIN_TIME_CONSTANTS = 5.0


def check_log_arrays(arrays: Sequence[Any], finite: bool = True) -> list[np.ndarray]:
    """ψ, δ, δc (:data:`LOG_NAMES`) as 1-D float arrays.  IdentificationError naming the
    array that is not 1-D, the arrays of different lengths (with their lengths) and, with
    ``finite``, the first non-finite entry of each array (``psi[12] = nan``)."""
    out = []
    for name, array in zip(LOG_NAMES, arrays, strict=True):
        try:
            values = np.asarray(array, dtype=float)
        except (TypeError, ValueError) as exc:
            raise IdentificationError(f"{name} is not an array of numbers: {exc}") from None
        if values.ndim != 1:
            raise IdentificationError(f"{name} must be a 1-D array, got shape {values.shape}")
        out.append(values)
    lengths = {name: values.shape[0] for name, values in zip(LOG_NAMES, out, strict=True)}
    if len(set(lengths.values())) > 1:
        said = ", ".join(f"{name} {n}" for name, n in lengths.items())
        raise IdentificationError(f"psi, delta and delta_c must have equal lengths; got {said}")
    if finite and (found := describe_nonfinite(np.column_stack(out))) is not None:
        raise IdentificationError(f"the log holds non-finite samples: {found}")
    return out


def describe_nonfinite(columns: np.ndarray) -> str | None:
    """The first non-finite entry of each column of a (n, 3) log of :data:`LOG_NAMES`
    (``psi[12] = nan, delta_c[3] = inf``), None if every entry is finite."""
    found = []
    for j, name in enumerate(LOG_NAMES):
        bad = np.flatnonzero(~np.isfinite(columns[:, j]))
        if bad.size:
            more = f" (and {bad.size - 1} more)" if bad.size > 1 else ""
            found.append(f"{name}[{bad[0]}] = {columns[bad[0], j]}{more}")
    return ", ".join(found) or None


def minimum_samples(time_constant: float, h: float) -> int:
    """Samples at spacing h [s] spanning :data:`MIN_TIME_CONSTANTS` × ``time_constant`` [s]."""
    return math.ceil(MIN_TIME_CONSTANTS * time_constant / h - 1e-9) + 1


def check_log_span(n: int, h: float, time_constant: float, whose: str) -> None:
    """IdentificationError unless ``n`` samples at spacing h [s] span
    :data:`MIN_TIME_CONSTANTS` × ``time_constant`` [s] (T1 of ``whose`` model), naming the
    minimum length."""
    need = minimum_samples(time_constant, h)
    if n < need:
        raise IdentificationError(
            f"{n} samples ({(n - 1) * h:.3g} s at h = {h} s) are too short to identify "
            f"{whose} (T1 = {time_constant:.4g} s): the log must span "
            f"{MIN_TIME_CONSTANTS:g}·T1 = {MIN_TIME_CONSTANTS * time_constant:.3g} s, at least "
            f"{need} samples"
        )
