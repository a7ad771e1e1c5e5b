"""The identification toolkit's error type and its checks of bad input (before any work)."""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Mapping
from typing import Any

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
