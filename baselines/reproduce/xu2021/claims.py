"""Xu et al. (2021) §5.2: the paper's qualitative statements, evaluated on our means."""

from __future__ import annotations

import math
from typing import Any

from shipgym_baselines.reproduce.rows import reproduction_row as _row
from shipgym_baselines.reproduce.xu2021.controllers import AB, L1_VARIANTS, PID

#: a comparative claim holds when ours is at least this much lower (a difference that a
#: figure shows; smaller ones are within the seed-to-seed spread of these runs)
CLAIM_MARGIN = 0.1
PIDS = (PID,)
#: claim metric -> (figure of the paper, what it says)
CLAIMS = {
    "reaches_goal": ("Fig. 9, 15", "the ship follows the path in both cases"),
    "command_hf_lower_than_adaptive_backstepping": ("Fig. 12", "filter removes HF from δc"),
    "rudder_hf_lower_than_adaptive_backstepping": ("Fig. 12", "filter removes HF from δ"),
    "command_hf1_lower_than_adaptive_backstepping": ("Fig. 12", "… above 1 rad/s, δc"),
    "rudder_hf1_lower_than_adaptive_backstepping": ("Fig. 12", "… above 1 rad/s, δ"),
    "rudder_rate_lower_than_adaptive_backstepping": ("Fig. 12", "rudder more stable"),
    "ace_ratio_to_adaptive_backstepping": ("Fig. 12", "cross-track errors nearly same"),
    "drift_fluctuation_lower_than_adaptive_backstepping": (
        "Fig. 10–11",
        "sway / drift fluctuate more without the filter",
    ),
    "b_hat_hf_lower_than_adaptive_backstepping": ("Fig. 14", "b̂ has HF without the filter"),
    **{f"ace_lower_than_{pid}": ("Fig. 15", "L1 better than PID") for pid in PIDS},
    **{
        f"settles_faster_than_{pid}": ("Fig. 15", "PID takes more time to converge") for pid in PIDS
    },
}
#: filter on vs off: claim -> the episode metric compared
FILTER_CLAIMS = {
    "command_hf_lower_than_adaptive_backstepping": "command_hf_rms_deg",
    "rudder_hf_lower_than_adaptive_backstepping": "rudder_hf_rms_deg",
    "command_hf1_lower_than_adaptive_backstepping": "command_hf1_rms_deg",
    "rudder_hf1_lower_than_adaptive_backstepping": "rudder_hf1_rms_deg",
    "rudder_rate_lower_than_adaptive_backstepping": "mean_abs_rudder_rate_deg_s",
    "drift_fluctuation_lower_than_adaptive_backstepping": "drift_std_deg",
    "b_hat_hf_lower_than_adaptive_backstepping": "b_hat_hf_rms_deg_s",
}


def _ratio(a: Any, b: Any) -> float | None:
    """a/b for non-negative figures; x/∞ → 0, ∞/x → ∞; None if undefined (∞/∞, missing)."""
    if a is None or b is None or (math.isinf(a) and math.isinf(b)):
        return None
    if math.isinf(b):
        return 0.0
    return math.inf if (math.isinf(a) or b == 0) else a / b


def claims(
    means: dict[tuple[str, str, str], Any], controllers: tuple[str, ...], seeds: int
) -> list[dict[str, Any]]:
    """The §5.2 statements (CLAIMS) on the whole-episode means.  Comparative claims: ``ours``
    is whether the ratio (also in the row) is below 1 − CLAIM_MARGIN; paper True."""

    def m(label: str, metric: str) -> Any:
        return means.get(("episode", label, metric))

    def compare(label: str, other: str, metric: str, claim: str, paper: Any) -> dict[str, Any]:
        a, b = m(label, metric), m(other, metric)
        ratio = _ratio(a, b)
        if ratio is None:  # ∞ vs ∞ (neither settles): not lower; missing: unknown
            holds = None if a is None or b is None else False
        else:
            holds = bool(ratio < 1.0 - CLAIM_MARGIN)
        row = _row("claims", label, claim, holds, paper, seeds)
        row["ratio"] = ratio
        return row

    rows = []
    for label in controllers:
        rows.append(_row("claims", label, "reaches_goal", m(label, "success"), True, seeds))
    for label in (c for c in controllers if c in L1_VARIANTS or c == AB):
        paper = True if label in L1_VARIANTS else None  # the paper compares its L1 only
        if AB in controllers and label != AB:
            for claim, metric in FILTER_CLAIMS.items():
                rows.append(compare(label, AB, metric, claim, True))
            ratio = _ratio(m(label, "ace"), m(AB, "ace"))
            rows.append(
                _row("claims", label, "ace_ratio_to_adaptive_backstepping", ratio, 1.0, seeds)
            )
        for pid in (p for p in PIDS if p in controllers):
            rows.append(compare(label, pid, "ace", f"ace_lower_than_{pid}", paper))
            rows.append(compare(label, pid, "settle_time_s", f"settles_faster_than_{pid}", paper))
    return rows
