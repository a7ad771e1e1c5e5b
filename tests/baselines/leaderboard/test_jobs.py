"""The leaderboard's jobs (:mod:`shipgym_baselines.leaderboard.jobs`): a job carries what its
episodes are labelled with, and the evaluation loop labels them so."""

from __future__ import annotations

from pathlib import Path

from shipgym_baselines.leaderboard.jobs import Job, run_batch, run_job, trials, work
from shipgym_baselines.plugins import ControllerEntry
from shipgym_baselines.records.episodes import EpisodeLabel

ROOT = Path(__file__).resolve().parents[3]


def test_a_jobs_episodes_carry_its_scenario_controller_and_training_seed(tmp_path: Path) -> None:
    """A scenario given by its YAML path keeps that path (not the trials' ``name:``), a
    controller's long form its display name, on every path a job's episodes run."""
    nominal = (ROOT / "configs/scenarios/nominal.yaml").read_text()
    case = tmp_path / "case.yaml"
    case.write_text(nominal.replace("name: nominal", "name: my_case"))
    idle = ControllerEntry(controller="zero_rudder", name="idle")
    job = Job(idle, str(case), (10_000, 10_001))
    assert job.label == EpisodeLabel(str(case), "idle", None)
    assert {trial.name for trial in trials(job)} == {"my_case"}
    results = [*run_batch(job), run_job((idle, str(case), 10_002)), *work(job._replace(seeds=(7,)))]
    assert [(r.scenario, r.controller, r.training_seed, r.seed) for r in results] == [
        (str(case), "idle", None, seed) for seed in (10_000, 10_001, 10_002, 7)
    ]
    assert Job("ppo", "nominal", (10_000,), 2).label == EpisodeLabel("nominal", "ppo", 2)
