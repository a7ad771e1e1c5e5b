"""A plain stable-baselines3 zip is scored by its path: algorithm
from the zip, action mode from its action space, ``vecnormalize.pkl`` beside it used (when trusted),
``meta.json`` optional and checked, a truncated or corrupt zip a clear error.  An agent
trained with several seeds is a folder of ``seed_<k>`` folders."""

from __future__ import annotations

import json
import shutil
import zipfile
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import shipgym  # noqa: F401  (registers the envs)
from shipgym_baselines.cli import main
from shipgym_baselines.errors import ControllerError
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET, ActGuard, evaluate, evaluate_batch
from shipgym_baselines.learned.policy import (
    AGENT_LOOKS,
    ALGORITHMS,
    BATCH_ROWS,
    LearnedPolicy,
    read_model,
    read_policy,
    shipped_policies,
)
from shipgym_baselines.learned.trust import trusting_pickle
from shipgym_baselines.plugins import ControllerEntry
from shipgym_baselines.registry import (
    controller_kind,
    controller_label,
    make_controller,
    resolve_controller,
    training_seeds,
)
from shipgym_baselines.training.agents import list_agent_configs

sb3 = pytest.importorskip("stable_baselines3")
sb3_contrib = pytest.importorskip("sb3_contrib")

ENV_ID = "ShipPathFollow-v0"


def _env(action_mode: str = "rudder") -> gym.Env:
    return gym.make(ENV_ID, action_mode=action_mode)


@pytest.fixture(scope="module", autouse=True)
def _one_torch_thread() -> None:
    """Tiny networks: one thread (several contend for the shared cores, 20× slower)."""
    import torch

    torch.set_num_threads(1)


@pytest.fixture(scope="module")
def trained(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A tiny PPO and a tiny SAC trained on the env, saved with plain ``model.save``."""
    folder = tmp_path_factory.mktemp("sb3")

    def small() -> dict[str, Any]:  # fresh: SB3 adds keys to the policy_kwargs it is given
        return {"policy_kwargs": {"net_arch": [16, 16]}, "device": "cpu", "seed": 0}

    ppo = sb3.PPO("MlpPolicy", _env(), n_steps=128, batch_size=64, n_epochs=2, **small())
    sac = sb3.SAC("MlpPolicy", _env(), learning_starts=100, buffer_size=1_000, **small())
    paths = {}
    for name, model in {"ppo": ppo, "sac": sac}.items():
        model.learn(total_timesteps=256)
        (folder / name).mkdir()
        model.save(folder / name / "agent")  # → agent.zip, nothing else beside it
        paths[name] = folder / name / "agent.zip"
    return paths


def _predict(model: Any, obs: np.ndarray) -> np.ndarray:
    """The model's deterministic action for ``obs`` in a batch of ``BATCH_ROWS`` rows, as the
    policy runs it (torch's GEMM gives a row the same bits whatever the other rows, for a
    fixed batch size, but not across batch sizes)."""
    batch = np.zeros((BATCH_ROWS, *obs.shape), dtype=obs.dtype)
    batch[3] = obs  # any row: the bits do not depend on the position
    actions, _ = model.predict(batch, deterministic=True)
    return actions[3]


def _observations(n: int = 20) -> list[np.ndarray]:
    env = _env()
    obs, _ = env.reset(seed=3)
    out = [obs]
    for _ in range(n - 1):
        obs, *_ = env.step(env.action_space.sample())
        out.append(obs)
    return out


@pytest.mark.parametrize(("algo", "cls"), [("ppo", "PPO"), ("sac", "SAC")])
def test_a_plain_sb3_zip_is_scored_by_its_path(
    trained: dict[str, Path], algo: str, cls: str
) -> None:
    path = trained[algo]
    policy, mode = make_controller(str(path))
    assert isinstance(policy, LearnedPolicy) and (policy.algo, mode) == (algo, "rudder")
    assert policy.name == "agent" and controller_kind(policy.name) == "learned"  # the stem
    model = getattr(sb3, cls).load(str(path), device="cpu")
    for obs in _observations():  # the policy acts as the model does, deterministically
        np.testing.assert_array_equal(policy.act(obs, {}), _predict(model, obs))
    (result,) = evaluate(str(path), "nominal", [EVAL_SEED_OFFSET])
    assert (result.controller, result.kind) == ("agent", "learned")
    assert np.isfinite(result.metrics["return"])
    assert "controller_stats" not in result.metrics  # no meta.json: no training cost shown


def test_the_policy_runs_torch_on_one_thread(trained: dict[str, Path]) -> None:
    import torch

    LearnedPolicy(trained["ppo"])
    assert torch.get_num_threads() == 1


class _Spaces(gym.Env):
    """An env with the given spaces (for models the ship env cannot make)."""

    def __init__(self, obs_shape: tuple[int, ...], action_shape: tuple[int, ...]) -> None:
        self.observation_space = gym.spaces.Box(-1, 1, obs_shape, dtype=np.float32)
        self.action_space = gym.spaces.Box(-1, 1, action_shape, dtype=np.float32)

    def reset(self, *, seed: int | None = None, options: Any = None) -> tuple[Any, dict]:
        return self.observation_space.sample(), {}

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict]:
        return self.observation_space.sample(), 0.0, False, False, {}


def _saved(folder: Path, algo: str, env: gym.Env, name: str | None = None) -> Path:
    module, cls = ALGORITHMS[algo]
    algorithm = getattr(sb3 if module == "stable_baselines3" else sb3_contrib, cls)
    policy = "MlpLstmPolicy" if algo == "recurrent_ppo" else "MlpPolicy"
    model = algorithm(policy, env, device="cpu", policy_kwargs={"net_arch": [8]})
    path = folder / f"{name or algo}.zip"
    model.save(path)
    return path


@pytest.mark.parametrize("algo", list(ALGORITHMS))
def test_the_algorithm_is_read_from_the_zip(tmp_path: Path, algo: str) -> None:
    path = _saved(tmp_path, algo, _env())
    assert read_model(path).algo == algo
    assert read_policy(path).algo == algo


def test_the_action_mode_comes_from_the_action_space(tmp_path: Path) -> None:
    guidance = _saved(tmp_path, "ppo", _env("guidance"), "guidance")
    policy, mode = make_controller(str(guidance))
    assert mode == policy.action_mode == "guidance"
    (result,) = evaluate(str(guidance), "nominal", [EVAL_SEED_OFFSET])
    assert result.kind == "learned"
    three = _saved(tmp_path, "ppo", _Spaces((9,), (3,)), "three")
    with pytest.raises(ControllerError, match=r"three\.zip: the model acts in Box of shape \(3,\)"):
        make_controller(str(three))
    other_obs = _saved(tmp_path, "ppo", _Spaces((4,), (1,)), "obs4")
    with pytest.raises(ControllerError, match=r"obs4\.zip: the model observes Box of shape \(4,\)"):
        make_controller(str(other_obs))


def test_vecnormalize_beside_the_zip_normalises_the_observation(tmp_path: Path) -> None:
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    venv = VecNormalize(DummyVecEnv([_env]), norm_obs=True, norm_reward=False)
    model = sb3.PPO("MlpPolicy", venv, n_steps=64, batch_size=64, n_epochs=1, device="cpu")
    model.learn(total_timesteps=64)  # the running mean and variance move away from 0, 1
    model.save(tmp_path / "model")
    venv.save(str(tmp_path / "vecnormalize.pkl"))
    with trusting_pickle(True):  # a pickle: read only when trusted
        policy = LearnedPolicy(tmp_path)
    assert policy.obs_normalizer is not None
    for obs in _observations(5):
        np.testing.assert_array_equal(policy.act(obs, {}), _predict(model, venv.normalize_obs(obs)))
    raw = np.array([_predict(model, o) for o in _observations(5)])
    acted = np.array([policy.act(o, {}) for o in _observations(5)])
    assert not np.array_equal(raw, acted)  # the statistics were used
    (tmp_path / "vecnormalize.pkl").write_bytes(b"not a pickle")
    with (
        trusting_pickle(True),
        pytest.raises(ControllerError, match=r"vecnormalize\.pkl: not a readable VecNormalize"),
    ):
        LearnedPolicy(tmp_path)


def _copy(trained: dict[str, Path], folder: Path) -> Path:
    folder.mkdir()
    return Path(shutil.copyfile(trained["ppo"], folder / "model.zip"))


def test_a_truncated_or_corrupt_zip_is_a_clear_error_naming_it(
    trained: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = trained["ppo"].read_bytes()
    truncated = tmp_path / "truncated.zip"
    truncated.write_bytes(data[: len(data) // 3])
    flipped = bytearray(data)
    flipped[len(data) // 2] ^= 0xFF
    corrupt = tmp_path / "corrupt.zip"
    corrupt.write_bytes(bytes(flipped))
    empty = tmp_path / "empty.zip"
    empty.write_bytes(b"")
    for path in (truncated, corrupt, empty):
        with pytest.raises(ControllerError, match=rf"{path}: .*(truncated|corrupt)"):
            make_controller(str(path))
    out = tmp_path / "out"
    assert main(["evaluate", str(truncated), "--suite", "smoke", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(truncated) in err and "Traceback" not in err
    assert not (out / "episodes.jsonl").exists()  # refused before any episode


@pytest.mark.parametrize(
    ("meta", "message"),
    [
        ("{not json", r"meta\.json: not JSON \(Expecting property name .* line 1, column 2\)"),
        ('{"algo": "sac"}', r"meta\.json: key 'algo' is 'sac', but model\.zip was saved by 'ppo'"),
        ('{"algo": "dqn"}', r"meta\.json: key 'algo': Input should be 'ppo', 'a2c'"),
        ('{"action_mode": "guidance"}', r"meta\.json: key 'action_mode' is 'guidance', but"),
        ('{"env_steps": "many", "wall_time_s": 1}', r"meta\.json: key 'env_steps': Input"),
        ('{"env_steps": 256}', r"meta\.json: .*both 'env_steps' and 'wall_time_s'"),
        ("[1, 2]", r"meta\.json: expected a mapping at the top level, got list"),
    ],
)
def test_a_bad_meta_json_is_a_clear_error_naming_file_and_key(
    trained: dict[str, Path], tmp_path: Path, meta: str, message: str
) -> None:
    model = _copy(trained, tmp_path / "agent")
    (model.parent / "meta.json").write_text(meta)
    with pytest.raises(ControllerError, match=message):
        resolve_controller(str(model.parent))  # before any episode


def test_a_meta_json_gives_name_and_training_cost(trained: dict[str, Path], tmp_path: Path) -> None:
    model = _copy(trained, tmp_path / "agent")
    meta = {"name": "mine", "algo": "ppo", "env_steps": 256, "wall_time_s": 1.5, "seed": 4}
    (model.parent / "meta.json").write_text(json.dumps(meta))
    assert LearnedPolicy(model.parent).name == "mine"
    (result,) = evaluate(str(model.parent), "nominal", [EVAL_SEED_OFFSET])
    assert result.controller == "agent"  # the table names a folder by its name
    assert (
        result.metrics["controller_stats"]["train_env_steps"],
        result.metrics["controller_stats"]["train_wall_s"],
    ) == (256.0, 1.5)


def test_a_meta_json_names_the_algorithm_the_zip_does_not(
    trained: dict[str, Path], tmp_path: Path
) -> None:
    """A zip whose policy class is the user's own (not one of SB3's) needs ``algo`` (and
    ``--trust-pickle``: the class is pickled)."""
    source = _copy(trained, tmp_path / "src")
    custom = tmp_path / "agent" / "model.zip"
    custom.parent.mkdir()
    with zipfile.ZipFile(source) as src, zipfile.ZipFile(custom, "w") as dst:
        for item in src.infolist():
            content = src.read(item)
            if item.filename == "data":
                data = json.loads(content)
                data["policy_class"]["__module__"] = "my_package.policies"
                content = json.dumps(data).encode()
            dst.writestr(item, content)
    with pytest.raises(ControllerError, match=r"cannot tell which algorithm saved it"):
        make_controller(str(custom))
    (custom.parent / "meta.json").write_text('{"algo": "ppo"}')
    # the user's own class lives only in the pickle
    with pytest.raises(ControllerError, match=r"my_package\.policies.*--trust-pickle"):
        make_controller(str(custom))
    with trusting_pickle(True):
        policy, _ = make_controller(str(custom))
    assert policy.algo == "ppo"


def test_a_folder_without_one_model_zip_is_a_clear_error(tmp_path: Path) -> None:
    (tmp_path / "a.zip").write_bytes(b"")
    (tmp_path / "b.zip").write_bytes(b"")
    with pytest.raises(ControllerError, match=r"holds model\.zip, .* it holds a\.zip, b\.zip"):
        make_controller(str(tmp_path))


# --------------------------------------------------------------------- training seeds


def _seeded_agent(trained: dict[str, Path], folder: Path) -> Path:
    """An agent folder of two training seeds as ``shipgym train --seeds 0 1 --ship`` lays
    it out: ``seed_0`` (the tiny PPO) and ``seed_1`` (the tiny SAC, to tell them apart),
    each with its meta (its seed and training cost)."""
    for seed, algo in enumerate(("ppo", "sac")):
        (folder / f"seed_{seed}").mkdir(parents=True)
        shutil.copyfile(trained[algo], folder / f"seed_{seed}" / "model.zip")
        meta = {"seed": seed, "env_steps": 100 * (seed + 1), "wall_time_s": 1.0 + seed}
        (folder / f"seed_{seed}" / "meta.json").write_text(json.dumps(meta))
    return folder


def test_a_folder_of_seed_folders_is_one_agent_with_its_training_seeds(
    trained: dict[str, Path], tmp_path: Path
) -> None:
    agent = str(_seeded_agent(trained, tmp_path / "agent"))
    (tmp_path / "agent" / "seed_2" / "checkpoints").mkdir(parents=True)  # a run not done yet
    assert training_seeds(agent) == [0, 1]
    assert controller_label(agent) == "agent" and controller_kind("agent") == "learned"
    policy, mode = make_controller(agent, training_seed=1)
    assert (policy.algo, policy.training_seed, policy.name, mode) == ("sac", 1, "agent", "rudder")
    first, _ = make_controller(agent)  # without a training seed: the first
    assert (first.algo, first.training_seed) == ("ppo", 0)
    (result,) = evaluate_batch(agent, "nominal", [EVAL_SEED_OFFSET], training_seed=1)
    assert (result.controller, result.training_seed) == ("agent", 1)
    assert (
        result.metrics["controller_stats"]["train_env_steps"],
        result.metrics["controller_stats"]["train_wall_s"],
    ) == (200.0, 2.0)
    with pytest.raises(ControllerError, match=r"'agent' was trained with seeds 0, 1: no .* 5"):
        make_controller(agent, training_seed=5)
    with pytest.raises(ControllerError, match=r"no training seed 5; it holds seed_0, seed_1"):
        LearnedPolicy(agent, training_seed=5)
    assert LearnedPolicy(tmp_path / "agent" / "seed_1").name == "agent/seed_1"


def test_a_single_model_is_one_training_seed_its_meta_names(
    trained: dict[str, Path], tmp_path: Path
) -> None:
    """The layout before training seeds (``policies/<name>/model.zip``) is one training seed,
    its meta's; a zip without one has [None], as classical controllers do."""
    model = _copy(trained, tmp_path / "flat")
    (model.parent / "meta.json").write_text(json.dumps({"seed": 3}))
    assert training_seeds(str(model.parent)) == [3]
    policy, _ = make_controller(str(model.parent), training_seed=3)
    assert policy.training_seed == 3
    with pytest.raises(ControllerError, match=r"no training seed 4: its meta\.json says seed 3"):
        LearnedPolicy(model.parent, training_seed=4)
    assert training_seeds(str(trained["ppo"])) == [None]
    assert training_seeds("pid_los") == [None]
    with pytest.raises(ControllerError, match=r"'pid_los' has no training seeds"):
        make_controller("pid_los", training_seed=0)


def test_a_suite_long_form_can_name_one_training_seed(
    trained: dict[str, Path], tmp_path: Path, scratch_registry: None
) -> None:
    agent = str(_seeded_agent(trained, tmp_path / "agent"))
    entry = ControllerEntry(controller=agent, name="agent_s1", settings={"training_seed": 1})
    assert training_seeds(entry) == [1]
    assert make_controller(entry)[0].algo == "sac"
    with pytest.raises(ControllerError, match=r"no training seed 7"):
        training_seeds(ControllerEntry(controller=agent, settings={"training_seed": 7}))


def test_seed_folders_that_contradict_themselves_are_clear_errors(
    trained: dict[str, Path], tmp_path: Path
) -> None:
    both = _seeded_agent(trained, tmp_path / "both")
    shutil.copyfile(trained["ppo"], both / "model.zip")
    with pytest.raises(ControllerError, match=r"holds both a model \(model\.zip\) and training"):
        make_controller(str(both))
    mislabelled = _seeded_agent(trained, tmp_path / "mislabelled")
    (mislabelled / "seed_1" / "meta.json").write_text('{"seed": 0}')
    with pytest.raises(ControllerError, match=r"seed_1/meta\.json: key 'seed' is 0, but the"):
        make_controller(str(mislabelled))
    modes = _seeded_agent(trained, tmp_path / "modes")
    _saved(modes / "seed_1", "ppo", _env("guidance"), "model")
    with pytest.raises(ControllerError, match=r"its training seeds disagree: .* 'guidance' mode"):
        make_controller(str(modes))


def test_every_shipped_agent_loads_each_of_its_training_seeds() -> None:
    for name in shipped_policies():
        seeds = training_seeds(name)
        assert seeds and all(isinstance(seed, int) for seed in seeds), name
        for seed in seeds:
            policy, _ = make_controller(name, training_seed=seed)
            assert (policy.name, policy.training_seed) == (name, seed)
            assert policy.episode_stats()["train_env_steps"] > 0


def test_every_agent_has_one_look_of_its_own() -> None:
    """The looks of the learned agents: one per agent config (the shipped policies among
    them), no two alike."""
    assert set(AGENT_LOOKS) == set(list_agent_configs())
    assert set(shipped_policies()) <= set(AGENT_LOOKS)
    assert len({(s.color, s.linestyle) for s in AGENT_LOOKS.values()}) == len(AGENT_LOOKS)


def test_an_sb3_zip_is_named_by_its_file_stem(tmp_path: Path) -> None:
    """``work/ppo_ship.zip`` is ``ppo_ship``, not its folder's name; a trained
    agent's own model file is its folder's."""
    from shipgym_baselines.learned.policy import policy_label

    assert policy_label(tmp_path / "work" / "ppo_ship.zip") == "ppo_ship"
    assert policy_label(tmp_path / "work" / "model.zip") == "work"
    assert policy_label(tmp_path / "agent" / "seed_1" / "best_model.zip") == "agent/seed_1"


@pytest.mark.parametrize("name", ["ppo", "ppo_guidance", "sac", "td3", "recurrent_ppo"])
def test_the_lean_forward_is_predict_bit_for_bit(name: str) -> None:
    """The evaluation's forward without ``predict``'s per-call overhead (≈ 30
    CPU s of the default run, docs/leaderboard-cost.md) gives ``predict``'s deterministic
    actions exactly; a recurrent policy keeps ``predict``."""
    import torch

    from shipgym_baselines.learned.policy import BATCH_ROWS, LearnedPolicy, lean_forward

    torch.set_num_threads(1)
    policy = LearnedPolicy(name)
    lean = lean_forward(policy.model.policy)
    if name == "recurrent_ppo":
        assert lean is None
        return
    rng = np.random.default_rng(7)
    obs = rng.uniform(-1.2, 1.2, (BATCH_ROWS, *policy.model.observation_space.shape))
    obs = obs.astype(np.float32)
    expected, _ = policy.model.predict(obs, deterministic=True)
    np.testing.assert_array_equal(lean(obs), expected)


def test_an_sb3_zip_with_nan_weights_fails_its_episodes_not_the_run(tmp_path: Path) -> None:
    """Its actions are NaN: each episode ends as controller_error at its first step, in
    lockstep as one by one, with the one-line message."""
    import torch

    model = sb3.PPO("MlpPolicy", _env(), device="cpu", policy_kwargs={"net_arch": [4]}, seed=0)
    with torch.no_grad():
        for weights in model.policy.parameters():
            weights.fill_(float("nan"))
    model.save(tmp_path / "broken")
    path = str(tmp_path / "broken.zip")
    seeds = [EVAL_SEED_OFFSET, EVAL_SEED_OFFSET + 1]
    lockstep = evaluate_batch(path, "rudder_aging", seeds, guard=ActGuard())
    alone = evaluate(path, "rudder_aging", seeds[:1], guard=ActGuard())
    for result in [*lockstep, *alone]:
        m = result.metrics
        assert (m["termination_reason"], m["steps"]) == ("controller_error", 1)
        assert m["error"].startswith("ValueError: action contains NaN or inf: array([nan]")
