"""Strict JSON for every file and ``--json`` document the project writes.

JSON has no infinity or NaN: non-finite numbers (t_c = inf, "never converged"; a std over
one seed that is undefined) are written as ``null``.
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np


def finite_or_none(obj: Any) -> Any:
    """``obj`` with every non-finite float (also inside dicts/lists) replaced by None."""
    if isinstance(obj, float | np.floating):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, dict):
        return {k: finite_or_none(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [finite_or_none(v) for v in obj]
    return obj


def dumps(obj: Any, **kwargs: Any) -> str:
    """``json.dumps`` of :func:`finite_or_none` (``allow_nan=False``: strict JSON)."""
    return json.dumps(finite_or_none(obj), allow_nan=False, **kwargs)
