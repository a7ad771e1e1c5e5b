"""``shipgym train AGENT --settings tuned``: the study's chosen settings reach the trained
model, the refusal is one line naming the file, and the pipeline command resumes an
interrupted sweep."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from shipgym_baselines.cli import main
from shipgym_baselines.learned import policy
from shipgym_baselines.training.agents import load_agent_config
from shipgym_baselines.tuning.chosen import write_chosen

CHOSEN = {
    "hyperparams.learning_rate": 7.0e-4,
    "hyperparams.gamma": 0.97,
    "policy_kwargs.net_arch": "16x16",
}
STUDY = {"study": "ppo", "report": "configs/tuning/reports/ppo/tuning_report.json"}


@pytest.fixture
def tiny(tmp_path: Path) -> Path:
    """The ppo agent config at a tiny scale (its name stays ``ppo``: the ppo study's
    settings apply), as a YAML file."""
    data = load_agent_config("ppo").model_dump()
    data["env"].update({"n_envs": 2, "vec_env": "dummy"})
    data["hyperparams"].update({"n_steps": 64, "batch_size": 64, "n_epochs": 2})
    data["policy_kwargs"]["net_arch"] = [8, 8]
    data["eval"].update({"freq": 128, "n_episodes": 1})
    data["checkpoint_freq"] = 128
    file = tmp_path / "ppo_tiny.yaml"
    file.write_text(yaml.safe_dump(data))
    return file


def _train(tiny: Path, chosen: Path, *extra: str) -> list[str]:
    return [
        "train",
        "ppo",
        "--config",
        str(tiny),
        "--settings",
        "tuned",
        "--chosen-dir",
        str(chosen),
        "--timesteps",
        "256",
        "--no-progress",
        "--json",
        *extra,
    ]


def test_the_chosen_settings_reach_the_trained_model(
    tiny: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from stable_baselines3 import PPO

    file, _ = write_chosen("ppo", "all", CHOSEN, STUDY, folder=tmp_path / "chosen")
    out = tmp_path / "run"
    assert main([*_train(tiny, tmp_path / "chosen", "--seeds", "0", "--out", str(out))]) == 0
    meta = json.loads((out / "meta.json").read_text())
    assert meta["tuned_from"]["settings"] == CHOSEN
    assert meta["tuned_from"]["chosen"] == str(file)
    assert meta["tuned_from"]["report"] == STUDY["report"]
    assert meta["config"]["hyperparams"]["learning_rate"] == 7.0e-4
    assert meta["config"]["eval"]["select_on"] == "relative_cost"
    assert meta["plateau"]["min_gain"] == 0.02 and meta["selection"] == "relative_cost"
    model = PPO.load(str(out / "model.zip"), device="cpu")
    assert model.learning_rate == 7.0e-4 and model.gamma == 0.97
    assert model.policy.net_arch == [16, 16]
    assert model.n_steps == 64  # the config's own, not tuned
    capsys.readouterr()


def test_without_chosen_settings_the_command_refuses_in_one_line(
    tiny: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main([*_train(tiny, tmp_path / "none", "--out", str(tmp_path / "run"))]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(tmp_path / "none" / "ppo.yaml") in err[0], err
    assert not (tmp_path / "run").exists()


def test_a_killed_sweep_resumes_where_each_seed_stood(
    tiny: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Seed 0 finished, seed 1 killed after its first checkpoint (128 steps: no model, no
    meta), seed 2 killed before any checkpoint: the same pipeline command re-run exports
    seed 0 as it was, resumes seed 1 from 128 steps and trains seed 2 afresh."""
    monkeypatch.setattr(policy, "POLICY_DIR", tmp_path / "policies")
    chosen = tmp_path / "chosen"
    write_chosen("ppo", "all", CHOSEN, STUDY, folder=chosen)
    out = tmp_path / "runs"
    assert main([*_train(tiny, chosen, "--seeds", "0", "--out", str(out / "seed_0"))]) == 0
    finished = (out / "seed_0" / "meta.json").read_text()
    one = _train(tiny, chosen, "--seeds", "1", "--out", str(out / "seed_1"))
    one[one.index("--timesteps") + 1] = "128"
    assert main(one) == 0
    for name in ("model.zip", "meta.json", "best_model.zip"):  # killed before the end
        (out / "seed_1" / name).unlink()
    checkpoint = out / "seed_1" / "checkpoints" / "ckpt_128_steps.zip"
    stamp = checkpoint.stat().st_mtime_ns
    (out / "seed_2" / "eval").mkdir(parents=True)  # started, killed before a checkpoint
    (out / "seed_2" / "manifest.txt").write_text("eval\n")  # listed as a run starts
    capsys.readouterr()

    argv = [*_train(tiny, chosen, "--out", str(out), "--resume", "--ship")]
    argv += ["--seeds", "0", "1", "2"]
    assert main(argv) == 0
    metas = json.loads(capsys.readouterr().out)
    assert [m["seed"] for m in metas] == [0, 1, 2]
    assert (out / "seed_0" / "meta.json").read_text() == finished  # only exported
    assert all(m["env_steps"] == 256 for m in metas)
    assert checkpoint.stat().st_mtime_ns == stamp  # resumed from it, not trained afresh
    assert (out / "seed_1" / "checkpoints" / "ckpt_256_steps.zip").is_file()
    assert (out / "seed_2" / "checkpoints" / "ckpt_256_steps.zip").is_file()
    curve = json.loads((out / "seed_1" / "learning_curve.json").read_text())
    assert curve["env_steps"] == [128, 256]  # the first evaluation before the kill, kept
    for seed in (0, 1, 2):
        shipped = tmp_path / "policies" / "ppo" / f"seed_{seed}"
        meta = json.loads((shipped / "meta.json").read_text())
        assert meta["seed"] == seed and meta["tuned_from"]["settings"] == CHOSEN
        assert (shipped / "learning_curve.json").is_file()

    # the chosen settings changed under a killed run: resuming it is refused
    for name in ("model.zip", "meta.json"):
        (out / "seed_1" / name).unlink()
    write_chosen("ppo", "all", {**CHOSEN, "hyperparams.gamma": 0.9}, STUDY, folder=chosen)
    argv = [*_train(tiny, chosen, "--out", str(out / "seed_1"), "--resume", "--seeds", "1")]
    argv[argv.index("--timesteps") + 1] = "384"
    assert main(argv) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    err = [line for line in lines if not line.startswith("train: ")]  # the start-up line
    assert len(err) == 1 and "other settings" in err[0], lines
