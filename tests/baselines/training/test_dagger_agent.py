"""``shipgym train dagger`` end to end on a tiny setting (baselines/training/dagger_agent.py):
the agent folder's contract, the selected student exported as every agent's and loaded as
data, its evaluation through the learned-policy adapter with no call of the privileged
channel, the resume of a run killed while scoring, the config's checks."""

from __future__ import annotations

import contextlib
import io
import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pydantic
import pytest
import yaml

import shipgym  # noqa: F401  (registers the envs)
from shipgym.config import ConfigError
from shipgym.envs import core
from shipgym_baselines.evaluation import evaluate, evaluate_batch
from shipgym_baselines.learned.curves import CURVE_KEYS, load_curve
from shipgym_baselines.learned.dagger import ROUND_KEYS, load_student, student_state
from shipgym_baselines.learned.dagger_config import settings
from shipgym_baselines.learned.loading import SavedModel, load_data_only
from shipgym_baselines.learned.policy import LearnedPolicy, read_policy
from shipgym_baselines.training.agents import AgentConfig, load_agent_config
from shipgym_baselines.training.dagger_agent import RUN_DIR, finished, train_dagger
from shipgym_baselines.training.train import POLICY_FILES, ship_policy

sb3 = pytest.importorskip("stable_baselines3")

K = 4
ROUNDS = 2
TINY: dict[str, Any] = {
    "name": "dagger_tiny",
    "algo": "dagger",
    "n_timesteps": 100_000,
    "seed": 1,
    "env": {
        "distribution": None,
        "scenario": "rudder_aging",  # nomoto2: ≈ 85 steps a rollout, the oracle ≈ 1 ms a step
        "action_mode": "rudder",
        "context_features": True,
        "history_steps": K,
    },
    "hyperparams": {"rounds": ROUNDS, "episodes_per_round": 2, "epochs": 2, "batch_size": 64},
    "policy_kwargs": {"net_arch": [16], "log_std_init": -1.0},
    "eval": {"distribution": "validation", "n_episodes": 2, "select_on": "relative_cost"},
}


@pytest.fixture(scope="module")
def trained(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The tiny agent trained through the CLI (``train dagger --config … --json``)."""
    from shipgym_baselines.cli import main

    folder = tmp_path_factory.mktemp("dagger_agent")
    config = folder / "tiny.yaml"
    config.write_text(yaml.safe_dump(TINY))
    out = folder / "agent"
    args = ["train", "dagger", "--config", str(config), "--out", str(out), "--no-progress"]
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert main([*args, "--json"]) == 0
    return {"out": out, "meta": json.loads(printed.getvalue()), "config": config, "args": args}


def test_the_agent_folder_holds_what_every_agent_writes(trained: dict[str, Any]) -> None:
    out, meta = trained["out"], trained["meta"]
    for name in ("model.zip", "best_model.zip", "meta.json", "learning_curve.json"):
        assert (out / name).is_file(), name
    assert json.loads((out / "meta.json").read_text()) == {
        k: v for k, v in meta.items() if k != "out_dir"
    }
    assert (meta["name"], meta["algo"], meta["trainer"]) == ("dagger_tiny", "ppo", "dagger")
    assert (meta["history_steps"], meta["seed"], meta["selection"]) == (K, 1, "relative_cost")
    rounds = json.loads((out / RUN_DIR / "rounds.json").read_text())
    assert [r["round"] for r in rounds] == list(range(ROUNDS))
    assert all(set(r) == set(ROUND_KEYS) for r in rounds)
    assert meta["env_steps"] == meta["teacher_labels"] == rounds[-1]["labels_total"] > 100
    assert meta["dagger"]["rounds"] == ROUNDS and meta["dagger"]["labels"] == meta["env_steps"]
    assert meta["dagger"]["labels_per_teacher_cpu_s"] > 0
    curve = load_curve(out)
    assert curve is not None and set(curve) >= {*CURVE_KEYS, "selection", "teacher_labels"}
    assert curve["env_steps"] == [r["labels_total"] for r in rounds] == curve["teacher_labels"]
    assert curve["round"] == list(range(ROUNDS))
    assert all(s > 0 and np.isfinite(s) for s in curve["selection"])
    best = int(np.argmin(curve["selection"]))
    assert meta["dagger"]["best_round"] == best
    selected = out / RUN_DIR / "students" / f"round_{best:03d}.zip"
    assert (out / "best_model.zip").read_bytes() == selected.read_bytes()
    newest = out / RUN_DIR / "students" / f"round_{ROUNDS - 1:03d}.zip"
    assert (out / "model.zip").read_bytes() == newest.read_bytes()
    assert finished(out, AgentConfig.model_validate(TINY)) is not None


def test_the_selected_student_ships_loads_as_data_and_is_scored_without_truth(
    trained: dict[str, Any], tmp_path: Path, truth_calls: list[str]
) -> None:
    """Exported as every agent is; its zip read by the data-only loader has the selected
    round's weights; the adapter (K from meta.json) evaluates it on the plain env, and no
    truth function is called meanwhile (the spies do see the oracle's own run)."""
    target = ship_policy(trained["out"], tmp_path / "policies")
    assert target == tmp_path / "policies" / "dagger_tiny" / "seed_1"
    assert sorted(p.name for p in target.iterdir()) == sorted(
        n for n in POLICY_FILES if (target / n).is_file()
    )
    assert {"model.zip", "meta.json", "learning_curve.json"} <= {p.name for p in target.iterdir()}
    model = load_data_only(SavedModel(target / "model.zip", "ppo", "rudder", True, K), sb3.PPO)
    assert model.observation_space.shape == (core.observation_size(True, K),)
    best = trained["meta"]["dagger"]["best_round"]
    config = AgentConfig.model_validate({**TINY, "seed": 1})
    student = load_student(
        trained["out"] / RUN_DIR / "students" / f"round_{best:03d}.zip",
        model.observation_space,
        model.action_space,
        settings(config),
    )
    for key, value in student_state(student).items():
        np.testing.assert_array_equal(student_state(model)[key], value)
    files = read_policy(target)
    assert (files.algo, files.model.history_steps, files.model.context_features) == (
        "ppo",
        K,
        True,
    )

    calls = truth_calls
    policy = LearnedPolicy(target)
    assert policy.history_steps == K
    seeds = [10_000, 10_001]
    batched = evaluate_batch(policy, "rudder_aging", seeds)
    alone = evaluate(LearnedPolicy(target), "rudder_aging", seeds[:1])
    assert calls == []
    assert alone[0].metrics["cost"] == batched[0].metrics["cost"]
    assert all(np.isfinite(r.metrics["cost"]) and r.metrics["steps"] > 0 for r in batched)
    evaluate("oracle", "rudder_aging", seeds[:1])  # the spies work
    assert "reset_with_truth" in calls and "plant_truth" in calls
    assert "teacher_truth" not in calls


def test_a_run_killed_while_scoring_resumes_without_relabelling(
    trained: dict[str, Any], tmp_path: Path
) -> None:
    """The last round finished but its score was lost (and no meta written): ``resume``
    rescores it, rolls nothing out, and ends where the uninterrupted run ended; a finished
    run resumed trains nothing."""
    out = tmp_path / "agent"
    shutil.copytree(trained["out"], out)
    selection = out / "eval" / "selection.json"
    data = json.loads(selection.read_text())
    kept = {k: (v[:-1] if k not in ("trials", "references") else v) for k, v in data.items()}
    selection.write_text(json.dumps(kept))
    (out / "meta.json").unlink()
    rollouts = {p.name: p.stat().st_mtime_ns for p in (out / RUN_DIR / "rollouts").iterdir()}
    config = AgentConfig.model_validate({**TINY, "seed": 1})
    meta = train_dagger(config, out, resume=True, progress=False)
    assert {p.name: p.stat().st_mtime_ns for p in (out / RUN_DIR / "rollouts").iterdir()} == (
        rollouts
    )
    assert meta["env_steps"] == trained["meta"]["env_steps"]
    assert load_curve(out)["selection"] == pytest.approx(load_curve(trained["out"])["selection"])
    again = train_dagger(config, out, resume=True, progress=False)
    assert again == meta
    with pytest.raises(Exception, match="not empty"):
        train_dagger(config, out, progress=False)
    with pytest.raises(Exception, match="no DAgger run"):
        train_dagger(config, tmp_path / "empty", resume=True, progress=False)


@pytest.mark.parametrize("damaged", ["rounds.json", "data/round_001.npz"])
def test_a_damaged_record_of_a_dagger_run_is_one_line(
    damaged: str, trained: dict[str, Any], tmp_path: Path
) -> None:
    """``resume`` on a run whose round record or labelled states are damaged: one line
    naming the file, not a traceback."""
    from shipgym_baselines.errors import RunError

    out = tmp_path / "agent"
    shutil.copytree(trained["out"], out)
    (out / "meta.json").unlink()  # not finished: the run's files are read
    selection = out / "eval" / "selection.json"
    data = json.loads(selection.read_text())
    selection.write_text(
        json.dumps(
            {
                k: v[:1] if isinstance(v, list) and k not in ("trials", "references") else v
                for k, v in data.items()
            }
        )
    )
    (out / RUN_DIR / damaged).write_text("{not json")
    config = AgentConfig.model_validate(
        {**TINY, "seed": 1, "hyperparams": {**TINY["hyperparams"], "rounds": ROUNDS + 1}}
    )
    with pytest.raises(RunError) as refused:
        train_dagger(config, out, resume=True, progress=False)
    assert str(out / RUN_DIR / damaged) in str(refused.value)
    assert "\n" not in str(refused.value)


def test_the_packaged_configs() -> None:
    """bc: the student dagger's study chose (``--settings tuned``) but the history;
    ppo_history: PPO with a window."""
    from shipgym_baselines.tuning.tuned import tuned_agent

    dagger, bc, ppo = (load_agent_config(n) for n in ("dagger", "bc", "ppo_history"))
    assert (dagger.algo, bc.algo, ppo.algo) == ("dagger", "dagger", "ppo")
    assert dagger.env.history_steps == ppo.env.history_steps > 0 == bc.env.history_steps
    assert dagger.env.context_features and bc.env.context_features and ppo.env.context_features
    assert dagger.env.distribution == bc.env.distribution == ppo.env.distribution == "train"
    tuned, _ = tuned_agent(dagger)
    assert tuned.env.history_steps > 0
    strip = {"name": None, "env": None}
    assert tuned.model_copy(update=strip) == bc.model_copy(update=strip)
    assert tuned.env.model_copy(update={"history_steps": 0}) == bc.env
    assert settings(dagger).net_arch == dagger.policy_kwargs["net_arch"]


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"hyperparams": {"round": 3}}, "did you mean 'rounds'"),
        ({"hyperparams": {"rounds": 0}}, "rounds"),
        ({"policy_kwargs": {"activation_fn": "tanh"}}, "policy_kwargs"),
        ({"eval": {"n_episodes": 2, "select_on": "return"}}, "eval.select_on"),
        ({"env": {**TINY["env"], "action_mode": "guidance"}}, "env.action_mode"),
        ({"env": {**TINY["env"], "history_steps": 1001}}, r"env\.history_steps\n.* 1000"),
    ],
)
def test_a_bad_dagger_config_names_the_key(change: dict[str, Any], message: str) -> None:
    with pytest.raises(pydantic.ValidationError, match=message):
        AgentConfig.model_validate({**TINY, **change})


def test_a_history_beyond_the_limit_is_refused_when_the_config_is_read(tmp_path: Path) -> None:
    """A million steps of history (gigabytes of rollouts) is refused before any work, in
    one line naming the key and the limit."""
    config = tmp_path / "dagger_long.yaml"
    env = {**TINY["env"], "history_steps": 1_000_000}
    config.write_text(json.dumps({**TINY, "env": env}))
    with pytest.raises(ConfigError) as refused:
        load_agent_config(config)
    assert "key 'env.history_steps'" in str(refused.value)
    assert "less than or equal to 1000" in str(refused.value)
