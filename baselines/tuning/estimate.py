"""The estimate ``shipgym tune`` starts a study with: the shipped study's own CPU time
(``configs/tuning/reports/<name>/<ship or all>/tuning_report.json``: its ``cpu_s``); the
line itself is :func:`shipgym_baselines.tuning.study.start_line`."""

from __future__ import annotations

import json
from pathlib import Path

from shipgym.config import catalogue
from shipgym_baselines.tuning.report import REPORT_FILE

#: the shipped studies' reports, under the packaged tuning configs
REPORTS = "reports"
#: a shipped report's folder for a study over every ship
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


def cpu_duration(seconds: float) -> str:
    """CPU seconds as the start-up line says them: CPU s, or CPU min from 90 s."""
    return f"{seconds / 60:.0f} CPU min" if seconds >= 90 else f"{seconds:.0f} CPU s"
