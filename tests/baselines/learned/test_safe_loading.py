"""Model files are read as data (docs/records.md): an SB3 zip's pickled values are never
unpickled, the weights load with ``weights_only``, observation statistics come from JSON; a
file that needs unpickling is refused unless ``--trust-pickle``.  The shipped agents act
exactly as through SB3's pickle loader (golden actions recorded before the change)."""

from __future__ import annotations

import base64
import json
import os
import pickle
import shutil
import zipfile
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

from shipgym_baselines.cli import main
from shipgym_baselines.errors import UnsafeFileError
from shipgym_baselines.learned.normalizer import NORMALIZER_FILE, ObsNormalizer, read_normalizer
from shipgym_baselines.learned.policy import POLICY_DIR, LearnedPolicy
from shipgym_baselines.learned.trust import TRUST_PICKLE_ENV, pickle_trusted, trusting_pickle
from shipgym_baselines.registry import make_controller

sb3 = pytest.importorskip("stable_baselines3")
GOLDEN = Path(__file__).resolve().parents[2] / "golden" / "shipped_policy_actions.npz"
#: actions (scaled to [-1, 1]) agree to this across machines (float32 kernels)
ACTION_ATOL = 1e-5


class _Payload:
    """Unpickling this creates the file ``target`` (what a hostile pickle could do)."""

    def __init__(self, target: Path) -> None:
        self.target = str(target)

    def __reduce__(self) -> tuple:
        return (open, (self.target, "w"))


def _serialized(target: Path) -> dict[str, str]:
    """An SB3 ``data`` value whose unpickling creates ``target``."""
    return {
        ":type:": "<class 'x'>",
        ":serialized:": base64.b64encode(pickle.dumps(_Payload(target))).decode(),
    }


def _rewrite(zip_path: Path, out: Path, data_change=None, entries=None) -> Path:
    """A copy of the model zip with its ``data`` JSON changed and entries replaced."""
    with zipfile.ZipFile(zip_path) as src, zipfile.ZipFile(out, "w") as dst:
        for item in src.infolist():
            content = src.read(item.filename)
            if item.filename == "data" and data_change is not None:
                data = json.loads(content)
                data_change(data)
                content = json.dumps(data).encode()
            if entries and item.filename in entries:
                content = entries[item.filename]
            dst.writestr(item.filename, content)
    return out


def _shipped_zip() -> Path:
    return POLICY_DIR / "ppo" / "seed_0" / "model.zip"


def test_finding7_shipped_agents_act_as_through_the_pickle_loader() -> None:
    import torch

    torch.set_num_threads(1)
    golden = np.load(GOLDEN, allow_pickle=False)
    keys = [k for k in golden.files if "__seed_" in k]
    assert len(keys) == 24  # 8 agents × 3 training seeds
    for key in keys:
        name, seed = key.split("__seed_")
        policy = LearnedPolicy(name, training_seed=int(seed))
        assert not pickle_trusted()
        # an agent trained with the context features reads them after the observation,
        # one trained with history_steps K then K steps of history
        if policy.history_steps:
            observations = golden[f"observations_history_{policy.history_steps}"]
        elif policy.context_features:
            observations = golden["observations_context"]
        else:
            observations = golden["observations"]
        actions = np.array([policy.act(obs, {}) for obs in observations])
        # to float32 rounding: torch's CPU kernels differ by a few ulp between machines
        # (≤ 8e-7 on an AMD EPYC against the recording machine); a wrong or
        # misordered tensor moves actions by O(0.1)
        np.testing.assert_allclose(actions, golden[key], rtol=0, atol=ACTION_ATOL, err_msg=key)


def test_finding7_a_pickle_payload_in_a_zip_is_not_executed(tmp_path: Path) -> None:
    """Pickled values scoring does not need (schedules, buffers, spaces) are never read."""
    target = tmp_path / "pwned"

    def plant(data: dict) -> None:
        for key in ("lr_schedule", "clip_range", "_last_obs", "ep_info_buffer"):
            data[key] = _serialized(target)
        for key in ("policy_class", "observation_space", "action_space"):  # kept as JSON
            data[key][":serialized:"] = _serialized(target)[":serialized:"]

    (tmp_path / "agent").mkdir()
    hostile = _rewrite(_shipped_zip(), tmp_path / "agent" / "model.zip", plant)
    policy = LearnedPolicy(hostile)
    golden = np.load(GOLDEN, allow_pickle=False)
    obs = golden["observations_context" if policy.context_features else "observations"][0]
    np.testing.assert_allclose(
        policy.act(obs, {}), golden["ppo__seed_0"][0], rtol=0, atol=ACTION_ATOL
    )
    assert not target.exists()


def test_finding7_a_zip_that_needs_unpickling_is_refused_naming_the_option(
    tmp_path: Path, capsys
) -> None:
    target = tmp_path / "pwned"

    def kwargs(data: dict) -> None:
        data["policy_kwargs"]["activation_fn"] = _serialized(target)

    (tmp_path / "agent").mkdir()
    hostile = _rewrite(_shipped_zip(), tmp_path / "agent" / "model.zip", kwargs)
    refused = r"policy_kwargs hold pickled objects.*--trust-pickle"
    with pytest.raises(UnsafeFileError, match=refused):
        LearnedPolicy(hostile)
    out = tmp_path / "out"
    code = main(["run", "nominal", str(hostile), "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "--trust-pickle" in err
    assert not target.exists()
    assert TRUST_PICKLE_ENV not in os.environ  # the command restored the setting


def test_finding7_weights_are_loaded_with_weights_only(tmp_path: Path) -> None:
    import io

    import torch

    target = tmp_path / "pwned"
    buffer = io.BytesIO()
    torch.save({"weights": _Payload(target)}, buffer)
    (tmp_path / "agent").mkdir()
    hostile = _rewrite(
        _shipped_zip(), tmp_path / "agent" / "model.zip", entries={"policy.pth": buffer.getvalue()}
    )
    with pytest.raises(UnsafeFileError, match=r"policy\.pth holds objects"):
        LearnedPolicy(hostile)
    assert not target.exists()


def test_finding7_a_pickled_vecnormalize_is_refused_unless_trusted(tmp_path: Path) -> None:
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    target = tmp_path / "pwned"
    folder = tmp_path / "agent"
    folder.mkdir()
    shutil.copyfile(_shipped_zip(), folder / "model.zip")
    (folder / "vecnormalize.pkl").write_bytes(pickle.dumps(_Payload(target)))
    with pytest.raises(UnsafeFileError, match=r"vecnormalize\.pkl: .*--trust-pickle"):
        LearnedPolicy(folder)
    assert not target.exists()
    # a genuine one, converted to data, normalises exactly as SB3's VecNormalize (of the
    # observation the shipped model reads: with the context features if it was so trained)
    wide = LearnedPolicy(_shipped_zip().parent).context_features
    venv = VecNormalize(
        DummyVecEnv([lambda: gym.make("ShipPathFollow-v0", context_features=wide)]),
        norm_obs=True,
    )
    venv.reset()
    for _ in range(30):
        venv.step(np.array([[0.5]], dtype=np.float32))
    venv.save(str(folder / "vecnormalize.pkl"))
    with trusting_pickle(True):
        trusted = LearnedPolicy(folder)
    from shipgym_baselines.learned.normalizer import main as convert

    assert convert([str(folder / "vecnormalize.pkl")]) == 0
    data = LearnedPolicy(folder)  # the JSON beside it: no unpickling
    assert isinstance(data.obs_normalizer, ObsNormalizer)
    assert read_normalizer(folder / NORMALIZER_FILE) == trusted.obs_normalizer
    golden = np.load(GOLDEN, allow_pickle=False)["observations_context" if wide else "observations"]
    np.testing.assert_array_equal(
        data.obs_normalizer.normalize_obs(golden), venv.normalize_obs(golden)
    )
    for obs in golden[:10]:
        np.testing.assert_array_equal(data.act(obs, {}), trusted.act(obs, {}))


def test_finding7_trust_pickle_reads_a_zip_sb3_alone_can(tmp_path: Path, capsys) -> None:
    """A custom activation lives only in the pickle: with --trust-pickle SB3 loads it."""
    import torch

    model = sb3.PPO(
        "MlpPolicy",
        gym.make("ShipPathFollow-v0"),
        device="cpu",
        policy_kwargs={"net_arch": [8], "activation_fn": torch.nn.ReLU},
    )
    (tmp_path / "relu").mkdir()
    model.save(tmp_path / "relu" / "model.zip")
    zip_path = tmp_path / "relu" / "model.zip"
    with pytest.raises(UnsafeFileError, match="--trust-pickle"):
        make_controller(str(zip_path))[0]
    code = main(["run", "nominal", str(zip_path), "--trust-pickle", "--out", str(tmp_path / "o")])
    assert code == 0, capsys.readouterr().err
    assert json.loads((tmp_path / "o" / "metrics.json").read_text())["kind"] == "learned"


def test_finding7_train_writes_the_statistics_as_data(tmp_path: Path) -> None:
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    from shipgym_baselines.training.train import export_policy, save_obs_statistics

    wide = LearnedPolicy(_shipped_zip().parent).context_features  # the observation it reads
    env = DummyVecEnv([lambda: gym.make("ShipPathFollow-v0", context_features=wide)])
    assert save_obs_statistics(VecNormalize(env, norm_obs=False), tmp_path) is None
    venv = VecNormalize(env, norm_obs=True)
    venv.reset()
    for _ in range(20):
        venv.step(np.array([[-0.4]], dtype=np.float32))
    run = tmp_path / "run"
    run.mkdir()
    written = save_obs_statistics(venv, run)
    assert written == run / NORMALIZER_FILE
    assert read_normalizer(written) == ObsNormalizer.of(venv)
    shutil.copyfile(_shipped_zip(), run / "model.zip")
    (run / "meta.json").write_text("{}")
    dest = tmp_path / "policy"
    dest.mkdir()
    (dest / "vecnormalize.pkl").write_bytes(b"stale")
    export_policy(run, dest)
    assert sorted(p.name for p in dest.iterdir()) == ["meta.json", "model.zip", NORMALIZER_FILE]
    assert LearnedPolicy(dest).obs_normalizer == ObsNormalizer.of(venv)


def test_statistics_of_another_width_than_the_model_s_are_refused(tmp_path: Path) -> None:
    """A normaliser whose mean and var lengths differ, or whose width is not what the model
    reads (the shipped PPO reads the context features when so trained), is a clear error."""
    from pydantic import ValidationError

    with pytest.raises(ValidationError, match="mean has 9 entries, var 16"):
        ObsNormalizer(norm_obs=True, mean=[0.0] * 9, var=[1.0] * 16, epsilon=1e-8, clip_obs=10.0)
    folder = tmp_path / "agent"
    folder.mkdir()
    shutil.copyfile(_shipped_zip(), folder / "model.zip")
    wide = LearnedPolicy(folder).context_features
    other = 9 if wide else 16
    stats = ObsNormalizer(
        norm_obs=True, mean=[0.0] * other, var=[1.0] * other, epsilon=1e-8, clip_obs=10.0
    )
    (folder / NORMALIZER_FILE).write_text(stats.model_dump_json())
    with pytest.raises(Exception, match=f"statistics of {other} observation entries"):
        LearnedPolicy(folder)


@pytest.mark.parametrize("size, ok", [(9, True), (16, True), (10, False), (0, False)])
def test_observation_statistics_have_an_observation_s_length(size: int, ok: bool) -> None:
    """9 entries (the env's observation) or 9 + the context features; other lengths are
    refused naming both."""
    from pydantic import ValidationError

    fields = {"norm_obs": True, "mean": [0.0] * size, "var": [1.0] * size}
    if ok:
        assert len(ObsNormalizer(**fields, epsilon=1e-8, clip_obs=10.0).mean) == size
    else:
        with pytest.raises(ValidationError, match="the observation has 9, or 16 with the context"):
            ObsNormalizer(**fields, epsilon=1e-8, clip_obs=10.0)
