"""What ``shipgym tune`` says as a study starts, after its checks: one line with the
study, its trials, the validation trials each scores, and an estimate from the shipped
study's own CPU time (``configs/tuning/reports/<name>/<ship or all>/tuning_report.json``:
its ``cpu_s``)."""

from __future__ import annotations

import json
from pathlib import Path

from shipgym.config import catalogue
from shipgym_baselines.tuning.study import REPORT_FILE, StudyPlan, plan_trials

#: the shipped studies' reports, under the packaged tuning configs
REPORTS = "reports"
#: a shipped or single-study report's folder for a study over every ship
ALL_SHIPS_FOLDER = "all"


def recorded_cpu_s(name: str, ship: str | None) -> tuple[float, float] | None:
    """(CPU s per trial, CPU s of scoring the default) of the shipped study ``name`` on
    ``ship`` (None: the study over every ship); None when none is shipped."""
    folder = Path(str(catalogue("tuning"))) / REPORTS / name / (ship or ALL_SHIPS_FOLDER)
    file = folder / REPORT_FILE
    if not file.is_file():
        return None
    report = json.loads(file.read_text(encoding="utf-8"))
    cpu, trials = report.get("cpu_s") or {}, report.get("trials") or []
    if not trials or not isinstance(cpu.get("trials"), int | float):
        return None
    return float(cpu["trials"]) / len(trials), float(cpu.get("default") or 0.0)


def _cpu_duration(seconds: float) -> str:
    return f"{seconds / 60:.0f} CPU min" if seconds >= 90 else f"{seconds:.0f} CPU s"


def start_line(plan: StudyPlan, trials: int) -> str:
    """The start-up line of ``plan``'s study run to ``trials`` finished trials (a resumed
    study runs only those it lacks: the estimate is then an upper bound)."""
    config = plan.config
    validation = len(plan_trials(plan))
    where = plan.ship or "every ship"
    each = "a training run scored on" if config.kind == "learned" else "scored on"
    recorded = recorded_cpu_s(config.name, plan.ship)
    if recorded is None:
        estimate = "no shipped study of this name and ship to estimate from"
    else:
        per_trial, default = recorded
        estimate = (
            f"at most about {_cpu_duration(per_trial * trials + default)} (the shipped study: "
            f"{per_trial:.1f} CPU s a trial)"
        )
    return (
        f"{plan.study_name}: {trials} trials of {config.controller} ({where}), each "
        f"{each} {validation} validation trials, after the default settings; {estimate}"
    )
