"""Borkowski (2018) §5: adaptive LQR lowers J against fixed LQR, by up to 15 %."""

from __future__ import annotations

from typing import Any

from shipgym_baselines.reproduce.rows import reproduction_row

#: Borkowski (2018) §5: "reduction of the control quality indicator value to 15 %"
PAPER_MAX_REDUCTION = 0.15


def case_claims(case: str, ratio: float, seeds: int) -> list[dict[str, Any]]:
    """Rows ``J_ratio`` (``ratio`` = J_adaptive/J_fixed) and ``adaptive_lower_J`` (paper:
    True) of one initial guess."""
    return [
        reproduction_row(case, "adaptive_lqr", "J_ratio", ratio, None, seeds),
        reproduction_row(case, "adaptive_lqr", "adaptive_lower_J", ratio < 1.0, True, seeds),
    ]


def summary_claims(ratios: list[float], seeds: int) -> list[dict[str, Any]]:
    """Over every guess: the largest reduction 1 − J_adaptive/J_fixed beside the paper's
    "to 15 %" (read as "by up to 15 %", module doc) and whether J is lower in every case."""
    return [
        reproduction_row(
            "all", "adaptive_lqr", "max_J_reduction", 1.0 - min(ratios), PAPER_MAX_REDUCTION, seeds
        ),
        reproduction_row(
            "all", "adaptive_lqr", "adaptive_lower_J", all(r < 1.0 for r in ratios), True, seeds
        ),
    ]
