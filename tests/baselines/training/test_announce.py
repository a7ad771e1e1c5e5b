"""``shipgym train``'s start-up line (what, how long, when it validates, an estimate from
the shipped training's rate) and its note after a run too short to validate."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from shipgym_baselines.cli import main
from shipgym_baselines.learned.policy import POLICY_DIR
from shipgym_baselines.training.agents import load_agent_config
from shipgym_baselines.training.announce import (
    recorded_step_seconds,
    start_line,
    too_short_line,
)


def test_the_estimate_is_the_shipped_trainings_median_rate() -> None:
    rates = sorted(
        json.loads(m.read_text())["wall_time_s"] / json.loads(m.read_text())["env_steps"]
        for m in (Path(POLICY_DIR) / "ppo").glob("seed_*/meta.json")
    )
    assert recorded_step_seconds("ppo") == rates[len(rates) // 2]
    assert recorded_step_seconds("no_such_agent") is None
    config = load_agent_config("ppo")
    line = start_line(config, 300_000, 0, "results/agents/ppo")
    minutes = rates[len(rates) // 2] * 300_000 / 60
    assert line.startswith("train: ppo (ppo), seed 0, 300,000 env steps into results/agents/ppo")
    assert f"validation every {config.eval.freq:,} env steps" in line
    assert f"about {minutes:.0f} min" in line


def test_a_run_shorter_than_the_first_validation_says_so(tmp_path: Path) -> None:
    config = load_agent_config("ppo")
    short = config.eval.freq // 10
    assert "likely no validation: it runs every" in start_line(config, short, 1, "out")
    note = too_short_line(config, {"env_steps": short, "seed": 1, "out_dir": str(tmp_path)})
    assert note is not None and "no best_model.zip and no learning curve" in note
    (tmp_path / "learning_curve.json").write_text("{}")
    assert too_short_line(config, {"env_steps": short, "seed": 1, "out_dir": str(tmp_path)}) is None


@pytest.mark.timeout(300)
def test_the_train_command_prints_both_lines(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "agent"
    assert main(["train", "ppo", "--out", str(out), "--timesteps", "64", "--no-progress"]) == 0
    err = capsys.readouterr().err
    assert "train: ppo (ppo), seed 0, 64 env steps into" in err
    assert "no best_model.zip and no learning curve" in err
    assert not (out / "best_model.zip").exists()
