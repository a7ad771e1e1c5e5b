"""Training writes learning curves, selects on the relative cost and stops on a plateau;
the per-ship batched path with context features trains end to end."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from shipgym_baselines.learned.curves import load_curve
from shipgym_baselines.training.agents import AgentConfig, load_agent_config
from shipgym_baselines.training.train import export_policy, train


def _tiny(**changes: object) -> AgentConfig:
    base = load_agent_config("ppo").model_dump()
    env = changes.pop("env", {})
    base.update(
        {
            "name": "ppo_tiny",
            "n_timesteps": 256,
            "hyperparams": {"n_steps": 64, "batch_size": 64, "n_epochs": 2},
            "policy_kwargs": {"net_arch": [16, 16]},
            "eval": {"distribution": "validation", "freq": 128, "n_episodes": 1},
            "checkpoint_freq": 128,
            **changes,
        }
    )
    base["env"] = {**base["env"], "n_envs": 2, "vec_env": "dummy", **env}
    return AgentConfig.model_validate(base)


def test_training_writes_its_learning_curve_and_exports_it(tmp_path: Path) -> None:
    out = tmp_path / "run"
    meta = train(_tiny(), out_dir=out, progress=False, tensorboard=False)
    curve = load_curve(out)
    assert curve["env_steps"] == [128, 256]
    evaluations = np.load(out / "eval" / "evaluations.npz")
    np.testing.assert_allclose(curve["mean_return"], evaluations["results"].mean(axis=1))
    assert meta["plateau"] is None and meta["stopped_on_plateau_at"] is None
    assert meta["selection"] == "return"
    policy = export_policy(out, tmp_path / "policy")
    assert load_curve(policy) == curve


def test_batched_context_relative_cost_and_plateau(tmp_path: Path) -> None:
    """The per-ship batched envs with context features, per-ship γ and normalisation train;
    the relative cost selects; a plateau rule that no gain meets stops at the second
    evaluation (the first before the window)."""
    config = _tiny(
        n_timesteps=2048,
        env={
            "vec_env": "batched",
            "n_envs": 4,
            "context_features": True,
            "gamma_seconds": 30.0,
            "normalize_per_ship": True,
        },
        eval={
            "distribution": "validation",
            "freq": 128,
            "n_episodes": 1,
            "select_on": "relative_cost",
        },
        plateau={"min_gain": 10.0, "window": 0.25, "min_evaluations": 2, "metric": "selection"},
    )
    out = tmp_path / "run"
    meta = train(config, out_dir=out, progress=False, tensorboard=False)
    assert meta["stopped_on_plateau_at"] == 256 and meta["env_steps"] == 256
    assert meta["plateau"]["min_gain"] == 10.0
    curve = load_curve(out)
    assert curve["env_steps"] == [128, 256] and len(curve["selection"]) == 2
    refs = json.loads((out / "eval" / "reference_costs.json").read_text())
    assert refs["trials"] == [["validation:0", 10_000]]
    assert refs["references"][0]["reference"] in ("oracle", "pid_los")
    assert (out / "best_model.zip").is_file()


def test_a_context_feature_agent_is_evaluated_with_its_features(tmp_path: Path) -> None:
    """An agent trained with context features loads as a LearnedPolicy that appends the
    features from the controller context: on the leaderboard's env (9 observations) it acts
    as the model does on the env with context_features=True."""
    import pytest

    from shipgym_baselines.evaluation import EVAL_SEED_OFFSET, evaluate
    from shipgym_baselines.learned.policy import LearnedPolicy
    from shipgym_baselines.training.selection import run_agent_episode

    out = tmp_path / "run"
    train(_tiny(env={"context_features": True}), out_dir=out, progress=False, tensorboard=False)
    policy = LearnedPolicy(export_policy(out, tmp_path / "policy"))
    assert policy.context_features
    seed = EVAL_SEED_OFFSET
    on_board = evaluate(policy, "nominal", [seed])[0].metrics
    _, direct_cost = run_agent_episode(policy.model, "nominal", seed, "rudder", True)
    assert on_board["cost"] == pytest.approx(direct_cost, rel=1e-6)


def test_a_per_ship_normalised_run_resumes_from_its_checkpoint(tmp_path: Path) -> None:
    """A run with per-ship reward normalisation resumes (its statistics are re-estimated,
    not loaded: they are not checkpointed), as a study's second part does."""
    env = {"vec_env": "batched", "n_envs": 4, "normalize_per_ship": True}
    out = tmp_path / "run"
    train(_tiny(n_timesteps=256, env=env), out_dir=out, progress=False, tensorboard=False)
    meta = train(
        _tiny(n_timesteps=512, env=env), out_dir=out, resume=True, progress=False, tensorboard=False
    )
    assert meta["env_steps"] == 512
    assert load_curve(out)["env_steps"] == [128, 256, 384, 512]


def _relative(**changes: object) -> AgentConfig:
    return _tiny(
        eval={
            "distribution": "validation",
            "freq": 128,
            "n_episodes": 1,
            "select_on": "relative_cost",
        },
        **changes,
    )


def test_a_run_stopped_on_its_plateau_is_finished_for_resume(tmp_path: Path) -> None:
    """``--resume`` on a run the plateau rule stopped returns it as it is (the final
    pipeline then only exports it): no evaluation is added, nothing is retrained."""
    config = _relative(
        n_timesteps=2048,
        plateau={"min_gain": 10.0, "window": 0.25, "min_evaluations": 2, "metric": "selection"},
    )
    out = tmp_path / "run"
    first = train(config, out_dir=out, progress=False, tensorboard=False)
    assert first["stopped_on_plateau_at"] == 256
    model_bytes = (out / "model.zip").read_bytes()
    again = train(config, out_dir=out, resume=True, progress=False, tensorboard=False)
    assert again == first
    assert load_curve(out)["env_steps"] == [128, 256]
    assert (out / "model.zip").read_bytes() == model_bytes


def test_a_run_killed_after_an_evaluation_past_its_checkpoint_resumes(tmp_path: Path) -> None:
    """Evaluations after the newest checkpoint belong to the stretch a resumed run trains
    again: the history keeps those up to the checkpoint, so the curve stays strictly
    increasing (before: the evaluation at 384 was repeated and the curve refused)."""
    out = tmp_path / "run"
    train(
        _relative(n_timesteps=384, checkpoint_freq=256),
        out_dir=out,
        progress=False,
        tensorboard=False,
    )
    first = load_curve(out)
    assert first["env_steps"] == [128, 256, 384]
    for name in ("model.zip", "meta.json"):  # killed before the end: unfinished
        (out / name).unlink()
    meta = train(
        _relative(n_timesteps=512, checkpoint_freq=256),
        out_dir=out,
        resume=True,
        progress=False,
        tensorboard=False,
    )
    assert meta["env_steps"] == 512
    second = load_curve(out)
    assert second["env_steps"] == [128, 256, 384, 512]
    # best_model.zip's value: the best ever evaluated, the dropped evaluation at 384 too,
    # kept on disk for a further resume (the history no longer holds it)
    best = json.loads((out / "eval" / "best.json").read_text())["value"]
    assert best == min(first["selection"] + second["selection"][3:])
