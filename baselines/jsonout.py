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


#: JSON without spaces after separators (a run's record and its long tables: smaller files)
COMPACT = (",", ":")


def dumps_rows(rows: Any) -> str:
    """A JSON array of ``rows``, one compact row a line (strict JSON as :func:`dumps`): a
    long table that stays light and readable line by line."""
    lines = [dumps(row, separators=COMPACT) for row in rows]
    return "[\n" + ",\n".join(lines) + "\n]\n" if lines else "[]\n"


def dumps(obj: Any, **kwargs: Any) -> str:
    """``json.dumps`` of :func:`finite_or_none` (``allow_nan=False``: strict JSON)."""
    return json.dumps(finite_or_none(obj), allow_nan=False, **kwargs)
