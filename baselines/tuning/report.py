"""``tuning_report.json``: a study's trials, its best settings, and best vs default on the
validation trials with 95 % intervals.

The intervals are percentile bootstraps over the validation trials (scipy, 2000 resamples,
seeded): of the geometric mean of the best settings' ratios, of the default's, and of the
paired quotient best / default (the geometric mean of the per-trial quotients; below 1: the
tuned settings are better).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from shipgym_baselines.scoring.intervals import geometric_mean

#: a study's report, in its folder (and the shipped studies' under configs/tuning/reports)
REPORT_FILE = "tuning_report.json"

#: bootstrap resamples and confidence of the report's intervals
RESAMPLES = 2000
CONFIDENCE = 0.95
#: what the report says about its intervals
INTERVAL_METHOD = (
    f"percentile bootstrap over the validation trials (scipy.stats.bootstrap, {RESAMPLES} "
    "resamples, seed 0), 95 %; 'best_over_default' pairs the trials"
)


def gmean_interval(ratios: Sequence[float], seed: int = 0) -> list[float]:
    """95 % bootstrap interval of the geometric mean of ``ratios`` over the trials."""
    from scipy.stats import bootstrap

    logs = np.log(np.asarray(ratios, dtype=float))
    if logs.size < 2 or np.ptp(logs) == 0:
        value = geometric_mean(ratios)
        return [value, value]
    result = bootstrap(
        (logs,),
        np.mean,
        n_resamples=RESAMPLES,
        confidence_level=CONFIDENCE,
        method="percentile",
        random_state=np.random.default_rng(seed),
    )
    interval = result.confidence_interval
    return [float(np.exp(interval.low)), float(np.exp(interval.high))]


def best_vs_default(
    best: Sequence[float], default: Sequence[float], trials: Sequence[str]
) -> dict[str, Any]:
    """The comparison block of the report (module doc); ``trials``: the trial names."""
    quotient = [b / d for b, d in zip(best, default, strict=True)]
    return {
        "trials": list(trials),
        "best": {"cost_ratio_gmean": geometric_mean(best), "ci95": gmean_interval(best)},
        "default": {"cost_ratio_gmean": geometric_mean(default), "ci95": gmean_interval(default)},
        "best_over_default": {
            "gmean": geometric_mean(quotient),
            "ci95": gmean_interval(quotient),
        },
        "best_ratios": list(best),
        "default_ratios": list(default),
        "interval": INTERVAL_METHOD,
    }


def trial_rows(study: Any) -> list[dict[str, Any]]:
    """The report's ``trials`` list: number, params, value, state, intermediate values
    (pruning reports, by trials scored) and CPU seconds."""
    rows = []
    for t in study.trials:
        rows.append(
            {
                "number": t.number,
                "params": dict(t.params),
                "value": t.value,
                "state": t.state.name,
                "intermediate": {str(k): v for k, v in sorted(t.intermediate_values.items())},
                "cpu_s": t.user_attrs.get("cpu_s"),
            }
        )
    return rows
