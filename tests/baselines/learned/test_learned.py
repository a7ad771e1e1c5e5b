"""Learned agents: distributions and splits, randomized env, train → save → reload → evaluate."""

from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import yaml

import shipgym
from shipgym.scenarios.loader import ScenarioError, load_scenario
from shipgym.scenarios.sampling import (
    DistributionError,
    load_distribution,
    train_rng,
    train_scenario_seed,
)
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET, evaluate
from shipgym_baselines.leaderboard.jobs import run_job
from shipgym_baselines.leaderboard.run import run_leaderboard
from shipgym_baselines.learned.policy import LearnedPolicy
from shipgym_baselines.training.agents import AgentConfig, load_agent_config
from shipgym_baselines.training.train import export_policy, latest_checkpoint, train

pytest.importorskip("stable_baselines3")


def _config_key(config) -> str:
    data = config.model_dump()
    data.pop("name")
    return json.dumps(data, sort_keys=True)


def test_train_and_test_splits_share_no_scenario() -> None:
    """500 training draws (from several env seeds) never hit a held-out/validation scenario."""
    train = load_distribution("train")
    tests = {}
    for name in ("heldout", "validation"):
        dist = load_distribution(name)
        assert dist.split == "test"
        for i in range(len(dist)):
            tests[_config_key(dist.test_scenario(i))] = f"{name}:{i}"
    assert len(tests) == len(load_distribution("heldout")) + len(load_distribution("validation"))
    seen = set()
    for env_seed in range(5):
        rng = np.random.default_rng(env_seed)
        for _ in range(100):
            seed = train_scenario_seed(rng)
            seen.add(seed)
            key = _config_key(train.sample(train_rng(seed)))
            assert key not in tests, f"training draw equals {tests[key]}"
    assert len(seen) == 500  # distinct scenario seeds


def test_heldout_contains_jumps_outside_the_training_ranges() -> None:
    """nomoto2's held-out jumps (the other ships': tests/shipgym/scenarios/test_sampling.py)."""
    nomoto2 = load_distribution("train").config.ships[0]
    assert nomoto2.model == "nomoto2"
    nominal, kinds = nomoto2.params, nomoto2.jumps.kinds
    tc_max = nominal["Tc"] * max(kinds["rudder_aging"].params["Tc"].range)
    d0_min = nominal["d0"] + min(kinds["current_shift"].params["d0"].range)
    heldout = load_distribution("heldout")
    outside = 0
    for i in range(len(heldout)):
        sc = heldout.test_scenario(i)
        if sc.ship.model != "nomoto2":
            continue
        for event in sc.events:
            p = event.params
            if p.get("Tc", 0.0) > tc_max * 1.01 or p.get("d0", 0.0) < d0_min or "T2" in p:
                outside += 1
    assert outside >= 3


def test_named_heldout_scenarios_load_and_bad_names_fail() -> None:
    sc = load_scenario("heldout:2")
    assert sc.name == "heldout:2"
    assert sc.config == load_scenario("heldout:2").config  # deterministic
    with pytest.raises(ScenarioError, match="out of range"):
        load_scenario("heldout:999")
    with pytest.raises(ScenarioError, match="unknown distribution"):
        load_scenario("nosuch:1")
    with pytest.raises(ScenarioError, match="only test splits"):
        load_scenario("train:0")


def test_bad_distribution_file_names_the_key(tmp_path: Path) -> None:
    data = yaml.safe_load(Path("configs/distributions/train.yaml").read_text())
    data["path"]["leg_length_L"] = [20.0, 10.0]
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(data))
    with pytest.raises(DistributionError, match="leg_length_L"):
        load_distribution(bad)


def test_randomized_env_conforms_and_is_reproducible() -> None:
    from gymnasium.utils.env_checker import check_env
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    env = gym.make(shipgym.RANDOMIZED_ENV_ID)
    check_env(env.unwrapped, skip_render_check=True)
    sb3_check_env(env.unwrapped)
    obs_a, info_a = env.reset(seed=5)
    name_a = env.unwrapped.scenario_name
    traj_a = [env.step(np.array([0.3], dtype=np.float32))[0] for _ in range(20)]
    obs_b, _ = env.reset(seed=5)
    traj_b = [env.step(np.array([0.3], dtype=np.float32))[0] for _ in range(20)]
    assert env.unwrapped.scenario_name == name_a
    assert "scenario" not in info_a  # the name identifies the schedule: not for controllers
    np.testing.assert_array_equal(obs_a, obs_b)
    np.testing.assert_array_equal(np.array(traj_a), np.array(traj_b))
    env.reset(seed=6)
    assert env.unwrapped.scenario_name != name_a


def test_randomized_env_serves_every_ship_with_one_pair_of_spaces() -> None:
    """The training distribution's resets reach all four ships; observations stay in the one
    9-entry space and the actions are the same 1 (rudder) or 2 (guidance) entries."""
    for mode, n_actions in (("rudder", 1), ("guidance", 2)):
        env = gym.make(shipgym.RANDOMIZED_ENV_ID, action_mode=mode).unwrapped
        assert env.observation_space.shape == (9,) and env.action_space.shape == (n_actions,)
        ships = set()
        for seed in range(80):
            obs, _ = env.reset(seed=seed)
            ships.add(env.scenario.model.name)
            obs, *_ = env.step(env.action_space.sample())
            assert env.observation_space.contains(obs)
        assert ships == {"nomoto2", "esso_osaka", "mariner", "blanke"}


def test_randomized_env_vectorises_across_ships_without_samples() -> None:
    """Ships with different Ts/h in one Gymnasium vector env: ``info`` has every per-step key
    but ``samples`` (whose length, Ts/h, differs between ships), so the infos stack."""
    envs = gym.make_vec(shipgym.RANDOMIZED_ENV_ID, num_envs=4, vectorization_mode="sync")
    envs.reset(seed=[3, 4, 8, 9])  # nomoto2 (Ts/h = 50), blanke (4), mariner (10), nomoto2
    ships = [env.unwrapped.scenario.model.name for env in envs.unwrapped.envs]
    assert ships == ["nomoto2", "blanke", "mariner", "nomoto2"]
    _, _, _, _, info = envs.step(np.zeros((4, 1), dtype=np.float32))
    assert "samples" not in info
    assert {"t", "cross_track_error", "heading", "rudder_command", "position"} <= set(info)
    envs.close()


def _tiny_config(**env: object) -> AgentConfig:
    base = load_agent_config("ppo").model_dump()
    base.update(
        name="ppo_tiny",
        n_timesteps=256,
        hyperparams={"n_steps": 64, "batch_size": 64, "n_epochs": 2},
        policy_kwargs={"net_arch": [16, 16]},
        eval={"distribution": "validation", "freq": 128, "n_episodes": 1},
        checkpoint_freq=128,
    )
    base["env"] = {**base["env"], "n_envs": 2, "vec_env": "dummy", **env}
    return AgentConfig.model_validate(base)


def _policy_params(directory: Path) -> list[np.ndarray]:
    policy = LearnedPolicy(directory)
    return [p.detach().numpy().copy() for p in policy.model.policy.parameters()]


def test_ppo_trains_saves_reloads_and_evaluates_like_the_leaderboard(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "run"
    temp = tmp_path / "temp"  # the temp dir SB3's default logger would write into
    temp.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(temp))
    monkeypatch.delenv("SB3_LOGDIR", raising=False)
    meta = train(_tiny_config(), out_dir=out, progress=False, tensorboard=False)
    assert not list(temp.glob("SB3-*"))  # without TensorBoard, no SB3-<time> folder there
    assert meta["env_steps"] == 256 and meta["algo"] == "ppo"
    for name in ("model.zip", "best_model.zip", "meta.json"):
        assert (out / name).is_file(), name
    assert latest_checkpoint(out)[1] == 256
    # same seed → same trained weights (determinism of the whole pipeline)
    again = tmp_path / "again"
    train(_tiny_config(), out_dir=again, progress=False, tensorboard=False)
    (again / "best_model.zip").unlink()
    (out / "best_model.zip").rename(out / "best.zip")  # compare the final models
    for a, b in zip(_policy_params(out), _policy_params(again), strict=True):
        np.testing.assert_array_equal(a, b)
    # export → evaluate through the leaderboard's job function, twice: same numbers
    shipped = export_policy(out, tmp_path / "policy")
    first = run_job((str(shipped), "nominal", EVAL_SEED_OFFSET))
    second = run_job((str(shipped), "nominal", EVAL_SEED_OFFSET))
    assert first.kind == "learned" and first.controller == "policy"
    assert first.metrics["controller_stats"]["train_env_steps"] == 256.0
    for key in ("ace", "return", "rudder_travel"):
        assert first.metrics[key] == second.metrics[key]
    # the same episode through the plain evaluation loop
    direct = evaluate(LearnedPolicy(shipped), "nominal", [EVAL_SEED_OFFSET])[0]
    assert direct.metrics["return"] == first.metrics["return"]


def test_training_resumes_from_the_last_checkpoint(tmp_path: Path) -> None:
    out = tmp_path / "run"
    config = _tiny_config()
    train(config, out_dir=out, progress=False, tensorboard=False)
    meta = train(config, out_dir=out, n_timesteps=384, resume=True, progress=False)
    assert meta["env_steps"] == 384
    assert meta["wall_time_s"] > 0
    with pytest.raises(ValueError, match="no checkpoint"):
        train(config, out_dir=tmp_path / "empty", resume=True, progress=False)


def test_training_refuses_seeds_that_reach_the_evaluation_seeds(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="evaluation seeds"):
        train(_tiny_config(), out_dir=tmp_path, seed=EVAL_SEED_OFFSET - 1, progress=False)


def test_agent_configs_load_and_bad_ones_name_the_key(tmp_path: Path) -> None:
    for name in ("ppo", "ppo_guidance", "recurrent_ppo", "sac", "td3"):
        config = load_agent_config(name)
        assert config.name == name
    data = yaml.safe_load(Path("configs/agents/ppo.yaml").read_text())
    data["env"].update(vec_env="batched", n_envs=6)  # batched: one env per ship, 4 ships
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(data))
    with pytest.raises(ValueError, match="env"):
        load_agent_config(bad)
    with pytest.raises(ValueError, match="unknown agent config"):
        load_agent_config("nosuch")


def test_recurrent_policy_keeps_its_state_within_an_episode(tmp_path: Path) -> None:
    base = _tiny_config().model_dump()
    base.update(name="rppo_tiny", algo="recurrent_ppo", policy="MlpLstmPolicy")
    base["hyperparams"] = {"n_steps": 64, "batch_size": 64, "n_epochs": 1}
    base["policy_kwargs"] = {"net_arch": [16], "lstm_hidden_size": 8}
    base["n_timesteps"] = 128
    out = tmp_path / "rppo"
    train(AgentConfig.model_validate(base), out_dir=out, progress=False, tensorboard=False)
    result = evaluate(LearnedPolicy(out), "nominal", [EVAL_SEED_OFFSET])[0]
    assert math.isfinite(result.metrics["return"])


def test_ray_backend_returns_the_process_pool_table(tmp_path: Path) -> None:
    ray = pytest.importorskip("ray")
    suite = tmp_path / "tiny.yaml"
    suite.write_text(
        yaml.safe_dump(
            {"name": "tiny", "scenarios": ["nominal"], "controllers": ["pid_los", "zero_rudder"]}
        )
    )
    local = run_leaderboard(
        str(suite), seeds=2, out_dir=tmp_path / "a", workers=2, show_progress=False
    )
    from shipgym_baselines.training.train import train_sweep

    job = {"config": _tiny_config(), "seed": 3, "n_timesteps": 128, "tensorboard": False}
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        remote = run_leaderboard(
            str(suite), seeds=2, out_dir=tmp_path / "b", backend="ray", show_progress=False
        )
        # a training sweep job on Ray equals the same job run here
        on_ray = train_sweep([{**job, "out_dir": str(tmp_path / "ray")}], backend="ray")
    finally:
        ray.shutdown()
    here = train_sweep([{**job, "out_dir": str(tmp_path / "here")}])
    assert on_ray[0]["env_steps"] == here[0]["env_steps"] == 128
    for name in ("ray", "here"):
        (tmp_path / name / "best_model.zip").unlink()
    for x, y in zip(
        _policy_params(tmp_path / "ray"), _policy_params(tmp_path / "here"), strict=True
    ):
        np.testing.assert_array_equal(x, y)

    def strip(rows: list[dict]) -> list[dict]:  # wall-clock timings aside
        return [{k: v for k, v in r.items() if not k.startswith("compute_ms")} for r in rows]

    assert strip(local) == strip(remote)


def test_training_sweep_gives_the_same_runs_in_a_process_pool(tmp_path: Path) -> None:
    """Two seeds trained in a local process pool equal the same runs trained in turn."""
    from shipgym_baselines.training.train import train_sweep

    def jobs(root: Path) -> list[dict]:
        return [
            {
                "config": _tiny_config(),
                "out_dir": str(root / f"seed_{s}"),
                "seed": s,
                "n_timesteps": 128,
                "tensorboard": False,
            }
            for s in (1, 2)
        ]

    pooled = train_sweep(jobs(tmp_path / "pool"), workers=2)
    serial = train_sweep(jobs(tmp_path / "serial"), workers=1)
    assert [m["seed"] for m in serial] == [1, 2]
    assert [m["seed"] for m in pooled] == [1, 2] and [m["env_steps"] for m in pooled] == [128] * 2
    for s in (1, 2):
        for root in ("pool", "serial"):
            (tmp_path / root / f"seed_{s}" / "best_model.zip").unlink()
        a = _policy_params(tmp_path / "pool" / f"seed_{s}")
        b = _policy_params(tmp_path / "serial" / f"seed_{s}")
        for x, y in zip(a, b, strict=True):
            np.testing.assert_array_equal(x, y)
    with pytest.raises(ValueError, match="unknown backend"):
        train_sweep(jobs(tmp_path / "x"), backend="slurm")


def test_train_seeds_ship_lays_out_a_folder_per_training_seed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``train --seeds 1 2`` trains a run per seed; ``--ship --resume`` on the finished runs
    exports them (without training again) into ``policies/<name>/seed_<k>`` — what
    LearnedPolicy reads, nothing else — and the agent's single-model files are removed."""
    from shipgym_baselines.cli import main
    from shipgym_baselines.registry import training_seeds

    policies = tmp_path / "policies"
    monkeypatch.setattr("shipgym_baselines.learned.policy.POLICY_DIR", policies)
    (policies / "ppo_tiny").mkdir(parents=True)
    for old in ("model.zip", "meta.json"):  # the layout before training seeds
        (policies / "ppo_tiny" / old).write_text("old")
    config = tmp_path / "tiny.yaml"
    config.write_text(yaml.safe_dump(_tiny_config().model_dump()))
    out = tmp_path / "agents"
    args = ["train", "ppo", "--config", str(config), "--out", str(out), "--no-progress"]
    args += ["--seeds", "1", "2", "--timesteps", "128", "--json"]
    assert main(args) == 0
    trained = json.loads(capsys.readouterr().out)
    assert [(m["seed"], m["env_steps"]) for m in trained] == [(1, 128), (2, 128)]
    models = {s: out / f"seed_{s}" / "model.zip" for s in (1, 2)}
    written = {s: path.stat().st_mtime_ns for s, path in models.items()}
    assert main([*args, "--ship", "--resume"]) == 0
    shipped = json.loads(capsys.readouterr().out)
    assert [m["wall_time_s"] for m in shipped] == [m["wall_time_s"] for m in trained]
    assert {s: path.stat().st_mtime_ns for s, path in models.items()} == written  # not retrained
    agent = policies / "ppo_tiny"
    assert [m["shipped_to"] for m in shipped] == [str(agent / "seed_1"), str(agent / "seed_2")]
    assert sorted(p.name for p in agent.iterdir()) == ["seed_1", "seed_2"]
    for s in (1, 2):
        assert sorted(p.name for p in (agent / f"seed_{s}").iterdir()) == [
            "learning_curve.json",
            "meta.json",
            "model.zip",
        ]
    assert training_seeds("ppo_tiny") == [1, 2]
    assert training_seeds(str(out)) == [1, 2]  # the run folder resolves the same way
    policy = LearnedPolicy("ppo_tiny", training_seed=2)
    assert (policy.name, policy.training_seed) == ("ppo_tiny", 2)


def test_train_takes_seed_as_an_alias_of_seeds() -> None:
    from shipgym_baselines.cli import build_parser

    parser = build_parser()
    assert parser.parse_args(["train", "ppo", "--seed", "3"]).seeds == [3]
    assert parser.parse_args(["train", "all", "--seeds", "0", "1", "2"]).seeds == [0, 1, 2]
