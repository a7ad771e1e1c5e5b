"""``shipgym tune``'s start-up line: the study, its trials, what each scores, and an
estimate from the shipped study's recorded CPU time."""

from __future__ import annotations

import json
from pathlib import Path

from shipgym.config import catalogue
from shipgym_baselines.tuning.estimate import recorded_cpu_s
from shipgym_baselines.tuning.study import plan_studies, plan_trials, start_line


def test_the_estimate_is_the_shipped_studys_cpu_per_trial() -> None:
    file = Path(str(catalogue("tuning"))) / "reports" / "lqr" / "blanke" / "tuning_report.json"
    report = json.loads(file.read_text())
    per_trial, default = recorded_cpu_s("lqr", "blanke")
    assert per_trial == report["cpu_s"]["trials"] / len(report["trials"])
    assert default == report["cpu_s"]["default"]
    assert recorded_cpu_s("lqr", "no_such_ship") is None


def test_the_start_line_names_the_study_and_its_trials() -> None:
    (plan,) = [p for p in plan_studies("lqr", None, None, None, None) if p.ship == "blanke"]
    line = start_line(plan, 7)
    assert line.startswith(f"{plan.study_name}: 7 trials of lqr (blanke), each scored on ")
    assert f" on {len(plan_trials(plan))} validation trials" in line
    assert "the shipped study:" in line
