"""The row every reproduction reports (its --json): ``{case, controller, metric, ours, paper}``."""

from __future__ import annotations

from typing import Any

import numpy as np


def reproduction_row(
    case: str,
    controller: str,
    metric: str,
    ours: Any,
    paper: Any,
    seeds: int,
    std: float | None = None,
    **extra: Any,
) -> dict[str, Any]:
    """One comparison: ``paper`` is None where the paper gives no number; ``extra`` keys
    (e.g. a plant setting) come before ``seeds``; ``ours_std`` is added when given."""
    row = {
        "case": case,
        "controller": controller,
        "metric": metric,
        "ours": float(ours) if isinstance(ours, np.floating) else ours,
        "paper": paper,
        **extra,
        "seeds": seeds,
    }
    if std is not None:
        row["ours_std"] = float(std)
    return row
