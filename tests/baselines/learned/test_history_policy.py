"""``history_steps`` in agent configs and the learned-policy adapter: a policy trained with
K observes, at evaluation on the leaderboard's plain env, the window the training env gave
it, K read from its ``meta.json``; any mismatch is a clear error."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pydantic
import pytest

import shipgym  # noqa: F401  (registers the envs)
from shipgym.envs import core
from shipgym_baselines.errors import ControllerError
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET, evaluate_batch
from shipgym_baselines.learned.normalizer import NORMALIZER_FILE, ObsNormalizer
from shipgym_baselines.learned.policy import LearnedPolicy, read_policy
from shipgym_baselines.training.agents import AgentConfig, load_agent_config

sb3 = pytest.importorskip("stable_baselines3")

ENV_ID = "ShipPathFollow-v0"
K = 3


@pytest.fixture(scope="module", autouse=True)
def _one_torch_thread() -> None:
    import torch

    torch.set_num_threads(1)


@pytest.fixture(scope="module")
def model_zip(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An untrained PPO (seeded weights) on the env with context features and K steps of
    history, saved with plain ``model.save``: the tiny policy object of these tests."""
    env = gym.make(ENV_ID, context_features=True, history_steps=K)
    model = sb3.PPO("MlpPolicy", env, policy_kwargs={"net_arch": [16]}, device="cpu", seed=3)
    path = tmp_path_factory.mktemp("history") / "model.zip"
    model.save(path)
    return path


def _folder(tmp_path: Path, model_zip: Path, meta: dict[str, Any] | None) -> Path:
    folder = tmp_path / "agent"
    folder.mkdir(exist_ok=True)
    (folder / "model.zip").write_bytes(model_zip.read_bytes())
    if meta is not None:
        (folder / "meta.json").write_text(json.dumps(meta))
    return folder


def _spy(policy: LearnedPolicy) -> list[np.ndarray]:
    """The observation rows the policy feeds its network, recorded call by call."""
    seen: list[np.ndarray] = []
    act_rows = policy._act_rows

    def recording(obs: np.ndarray, memories: list) -> np.ndarray:
        seen.append(obs.copy())
        return act_rows(obs, memories)

    policy._act_rows = recording
    return seen


def test_the_adapter_builds_the_training_env_s_window_from_plain_observations(
    tmp_path: Path, model_zip: Path
) -> None:
    """On the plain env (the leaderboard's: 9 entries) the policy appends its context and
    the history window; the rows it feeds the model equal, bit for bit, the observations
    of the env made with ``context_features=True, history_steps=K``, step by step."""
    policy = LearnedPolicy(_folder(tmp_path, model_zip, {"history_steps": K, "algo": "ppo"}))
    assert policy.history_steps == K and policy.context_features
    assert policy.observation_width == core.observation_size(True, K)
    plain = gym.make(ENV_ID)
    rich = gym.make(ENV_ID, context_features=True, history_steps=K)
    seen = _spy(policy)
    for seed in (EVAL_SEED_OFFSET, EVAL_SEED_OFFSET + 1):  # the second episode: a reset
        obs, _ = plain.reset(seed=seed)
        want, _ = rich.reset(seed=seed)
        policy.reset(plain.unwrapped.controller_context, seed=seed)
        for step in range(2 * K + 3):
            action = policy.act(obs, {})
            np.testing.assert_array_equal(seen[-1][0], want, err_msg=str(step))
            if step == 0:
                assert not want[-K * core.HISTORY_WIDTH :].any()
            obs, *_ = plain.step(action)
            want, *_ = rich.step(action)
        assert want[-K * core.HISTORY_WIDTH :].any()


def test_lockstep_evaluation_acts_as_on_the_history_env(tmp_path: Path, model_zip: Path) -> None:
    """The leaderboard's lockstep evaluation (``act_batch``, one window per episode) gives
    each episode the cost of the policy acting on the history env alone."""
    folder = _folder(tmp_path, model_zip, {"history_steps": K})
    seeds = [EVAL_SEED_OFFSET + i for i in range(3)]
    results = evaluate_batch(LearnedPolicy(folder), "rudder_aging", seeds)
    policy = LearnedPolicy(folder)
    for seed, result in zip(seeds, results, strict=True):
        env = gym.make(
            ENV_ID, scenario="rudder_aging", context_features=True, history_steps=K, randomize=False
        )
        obs, _ = env.reset(seed=seed)
        policy.reset(env.unwrapped.controller_context, seed=seed)
        while True:
            obs, _, terminated, truncated, info = env.step(policy.act(obs, {}))
            if terminated or truncated:
                break
        assert result.metrics["cost"] == info["episode_metrics"]["cost"]


def test_k_is_read_from_the_training_config_in_the_meta(tmp_path: Path, model_zip: Path) -> None:
    """``shipgym train`` records the config: ``config.env.history_steps`` says K too."""
    folder = _folder(tmp_path, model_zip, {"config": {"env": {"history_steps": K}}})
    assert read_policy(folder).model.history_steps == K
    assert LearnedPolicy(folder).history_steps == K


@pytest.mark.parametrize(
    "meta, match",
    [
        (None, r"history_steps 0 .*needs \"history_steps\": K in its meta\.json"),
        ({"history_steps": 2}, r"with history_steps 2 .*observe shape \(23,\)"),
        ({"history_steps": 0}, r"with history_steps 0"),
        (
            {"history_steps": K, "config": {"env": {"history_steps": 1}}},
            r"key 'history_steps' is 3, but its training config's env\.history_steps is 1",
        ),
        ({"history_steps": -1}, r"history_steps"),
        ({"history_steps": "3"}, r"history_steps"),
        ({"config": {"env": {"history_steps": 1.5}}}, r"config\.env\.history_steps"),
    ],
)
def test_a_k_that_is_not_the_model_s_is_a_clear_error(
    tmp_path: Path, model_zip: Path, meta: dict | None, match: str
) -> None:
    with pytest.raises(ControllerError, match=match):
        LearnedPolicy(_folder(tmp_path, model_zip, meta))


def test_a_caller_s_k_or_an_env_s_other_than_the_model_s_is_refused(
    tmp_path: Path, model_zip: Path
) -> None:
    folder = _folder(tmp_path, model_zip, {"history_steps": K})
    assert LearnedPolicy(folder, history_steps=K).history_steps == K
    with pytest.raises(ControllerError, match="asked for history_steps 1, but it was trained"):
        LearnedPolicy(folder, history_steps=1)
    policy = LearnedPolicy(folder)
    env = gym.make(ENV_ID, context_features=True, history_steps=K + 2)
    obs, _ = env.reset(seed=0)
    policy.reset(env.unwrapped.controller_context)
    with pytest.raises(ControllerError, match=r"reads 37 .*history_steps 3.*another history"):
        policy.act(obs, {})


def test_observation_statistics_of_the_history_width(tmp_path: Path, model_zip: Path) -> None:
    """A ``vecnormalize.json`` of the model's width (with history) is used; another width
    is refused naming both."""
    width = core.observation_size(True, K)
    stats = {"norm_obs": True, "epsilon": 1e-8, "clip_obs": 10.0}
    folder = _folder(tmp_path, model_zip, {"history_steps": K})
    ObsNormalizer(mean=[0.0] * width, var=[1.0] * width, **stats)
    (folder / NORMALIZER_FILE).write_text(
        json.dumps({**stats, "mean": [0.5] * width, "var": [4.0] * width})
    )
    assert len(LearnedPolicy(folder).obs_normalizer.mean) == width
    narrow = core.observation_size(True, K - 1)
    (folder / NORMALIZER_FILE).write_text(
        json.dumps({**stats, "mean": [0.5] * narrow, "var": [4.0] * narrow})
    )
    with pytest.raises(ControllerError, match=f"statistics of {narrow} observation entries"):
        LearnedPolicy(folder)


# ------------------------------------------------------------------------- agent configs
def _config(**env: Any) -> AgentConfig:
    base = load_agent_config("ppo").model_dump()
    base["env"] = {**base["env"], **env}
    return AgentConfig.model_validate(base)


@pytest.mark.parametrize("bad", [-1, 1.5, "2", True])
def test_a_bad_history_steps_in_an_agent_config_is_named(bad: object) -> None:
    with pytest.raises(pydantic.ValidationError, match="history_steps"):
        _config(history_steps=bad)


def test_the_training_envs_observe_the_config_s_history() -> None:
    """Every training env a config builds (one env per process, the batched env on a
    scenario, the per-ship envs on a distribution) and the validation env observe K steps."""
    from shipgym_baselines.training.agents import make_eval_env, make_training_env

    k = 2
    assert _config().env.history_steps == 0
    for env in (
        {"vec_env": "dummy", "n_envs": 1},
        {"vec_env": "batched", "n_envs": 2, "distribution": None, "scenario": "nominal"},
        {"vec_env": "batched", "n_envs": 4},
    ):
        config = _config(history_steps=k, context_features=True, **env)
        venv = make_training_env(config.env, seed=0)
        assert venv.observation_space.shape == (core.observation_size(True, k),), env
        obs = venv.reset()
        assert not obs[:, -k * core.HISTORY_WIDTH :].any()
        venv.close()
    config = _config(history_steps=k)
    evaluation = make_eval_env(config.eval, config.env, 0)
    assert evaluation.observation_space.shape == (core.observation_size(False, k),)


def test_a_window_of_more_than_1000_entries_loads(tmp_path: Path) -> None:
    """SB3 records the bounds as numpy prints them, elided beyond 1000 entries: a model of
    a long window still loads, as data, and acts."""
    k = 150
    env = gym.make(ENV_ID, history_steps=k)
    model = sb3.PPO("MlpPolicy", env, policy_kwargs={"net_arch": [4]}, device="cpu", seed=0)
    folder = tmp_path / "long"
    folder.mkdir()
    model.save(folder / "model.zip")
    (folder / "meta.json").write_text(json.dumps({"history_steps": k}))
    policy = LearnedPolicy(folder)
    assert policy.observation_width == core.observation_size(False, k) > 1000
    obs, _ = gym.make(ENV_ID).reset(seed=0)
    policy.reset(env.unwrapped.controller_context)
    assert policy.act(obs, {}).shape == (1,)
