"""Whether a study's winner may replace the chosen settings a file already holds.

The *incumbent* is the section of the target file (``configs/tuning/chosen/<controller>.yaml``
under ``--promote``, else the study's own ``chosen`` folder) that the study would write.
Its objective on the study's validation trials is:

- **recorded**, when the file's study summary holds the same trials and seeds, scored under
  the current env and oracle revisions (:func:`recorded_ratios`);
- else **scored** now by the study's own scorer, with the incumbent's settings over the
  config's paper preset (:func:`incumbent_settings`).

Either way the comparison pairs the trials: the per-trial quotient new / incumbent, its
geometric mean and its 95 % bootstrap interval (:func:`compare`).  The winner replaces the
incumbent only when its objective is not worse (the quotient's geometric mean ≤ 1), or
with ``force``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from shipgym_baselines.scoring.intervals import geometric_mean
from shipgym_baselines.tuning.report import gmean_interval
from shipgym_baselines.tuning.space import TuningConfig
from shipgym_baselines.tuning.validation import ValidationTrial


def revisions() -> dict[str, int]:
    """The env and oracle revisions the cost ratios of a study are scored under."""
    from shipgym.envs.core import ENV_REVISION
    from shipgym_baselines.classical.oracle import ORACLE_REVISION

    return {"env_revision": ENV_REVISION, "oracle_revision": ORACLE_REVISION}


def validation_record(trials: Sequence[ValidationTrial], ratios: Sequence[float]) -> dict:
    """What a chosen file's study summary keeps of its winner's scoring: the trials, their
    seeds, the winner's cost ratio on each and the revisions they were scored under."""
    return {
        "trials": [t.name for t in trials],
        "seeds": [int(t.seed) for t in trials],
        "ratios": [float(r) for r in ratios],
        **revisions(),
    }


def recorded_ratios(
    summary: Mapping[str, Any], trials: Sequence[ValidationTrial]
) -> list[float] | None:
    """The incumbent's recorded cost ratios on ``trials`` (in their order), or None when
    the summary was not scored on exactly these trials under the current revisions."""
    record = summary.get("validation") or {}
    same = (
        record.get("trials") == [t.name for t in trials]
        and record.get("seeds") == [int(t.seed) for t in trials]
        and all(record.get(k) == v for k, v in revisions().items())
        and len(record.get("ratios") or []) == len(trials)
    )
    return [float(r) for r in record["ratios"]] if same else None


def incumbent_settings(config: TuningConfig, section: Mapping[str, Any]) -> dict[str, Any]:
    """The settings to score a chosen section with: the config's preset (a classical
    controller's paper design, which the study's trials also start from) under the
    section's settings."""
    preset = {"preset": config.default["preset"]} if "preset" in config.default else {}
    return {**preset, **section}


def compare(new: Sequence[float], incumbent: Sequence[float]) -> dict[str, Any]:
    """The paired comparison of the winner's and the incumbent's ratios on the same trials."""
    quotient = [n / i for n, i in zip(new, incumbent, strict=True)]
    return {
        "new_value": geometric_mean(new),
        "incumbent_value": geometric_mean(incumbent),
        "new_over_incumbent": {"gmean": geometric_mean(quotient), "ci95": gmean_interval(quotient)},
        "trials": len(quotient),
    }


def not_worse(comparison: Mapping[str, Any]) -> bool:
    """The winner's objective is at most the incumbent's (on the same trials)."""
    return comparison["new_value"] <= comparison["incumbent_value"]
