"""A trained SB3 agent behind the common policy interface (``kind = "learned"``).

Any stable-baselines3 / sb3-contrib model zip is scored by its path, as ``model.save(path)``
wrote it: the algorithm is read from the zip (:func:`detect_algorithm`), the action mode from
its action space (shape (1,): rudder, (2,): guidance), and the observation statistics beside
it (``vecnormalize.json``; a ``vecnormalize.pkl`` only with ``--trust-pickle``) normalise
the observation as in training.  Nothing is unpickled unless the command trusts pickles
(:mod:`shipgym_baselines.learned.loading`, :mod:`shipgym_baselines.learned.trust`).
A ``meta.json`` beside
it (what ``shipgym train`` writes) is optional; its keys are checked (:class:`PolicyMeta`)
and its training cost becomes leaderboard columns.  Every unreadable file is a
:class:`~shipgym_baselines.errors.ControllerError` naming the file (and the key).

A policy trained with several seeds is a folder of ``seed_<k>/`` folders, each a policy
folder as above (``policies/<name>/seed_<k>/model.zip``; a ``shipgym train --seeds …`` run
folder ``results/agents/<name>/seed_<k>/`` alike): its name means all of them
(:func:`training_seeds`), and ``training_seed=k`` picks one.  A folder holding one model is
one training seed, the ``seed`` of its ``meta.json`` (None without one).

The policy sees exactly what the env's observation holds (measurements, no plant
parameters, no schedule) and acts deterministically.  A model trained with the context
features or with ``history_steps=K`` (its ``meta.json``'s ``history_steps``) gets them
appended to the env's plain observation by the policy, the window kept per episode by the
envs' own :class:`~shipgym.envs.core.ObservationHistory`.  Recurrent agents (RecurrentPPO) keep
their LSTM state within an episode and start afresh at every ``reset``.

**Batched and one-by-one actions are the same bits.**  The network always runs on a batch
of :data:`BATCH_ROWS` rows (one env's observation padded with zero rows, several envs'
observations in chunks of :data:`BATCH_ROWS`): torch's float32 GEMM gives a row the same bits
whatever the other rows and the row's position, for a fixed batch size, but not across batch
sizes (1 row and 64 rows differ by an ulp).  So :meth:`LearnedPolicy.act` (one env) and
:meth:`LearnedPolicy.act_batch` (several envs in lockstep, each with its own LSTM state and
episode start) give equal actions, and equal episodes.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import json
import pickle
import re
import zipfile
import zlib
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, StrictInt, model_validator

from shipgym.config import validate_model
from shipgym.envs.context import ControllerContext
from shipgym.envs.core import (
    HISTORY_WIDTH,
    OBS_NAMES,
    ObservationHistory,
    check_history_steps,
    observation_size,
)
from shipgym.limits import MAX_HISTORY_STEPS
from shipgym_baselines.errors import ControllerError, UnsafeFileError
from shipgym_baselines.learned.loading import SavedModel, load_data_only
from shipgym_baselines.learned.normalizer import ObsNormalizer, load_normalizer, normalizer_file
from shipgym_baselines.learned.trust import pickle_trusted
from shipgym_baselines.policy import Style, check_action_mode

POLICY_DIR = Path(__file__).resolve().parent / "policies"
#: the look of each learned agent (``configs/agents``: the shipped policies and ``bc``) in
#: every figure, its family ``learned`` (:func:`shipgym_baselines.registry.declared_traits`)
AGENT_LOOKS: dict[str, Style] = {
    "ppo": Style("#d62728", "-", "P"),
    "ppo_guidance": Style("#ff9896", "--", "P"),
    "recurrent_ppo": Style("#8c564b", "-", "X"),
    "sac": Style("#e377c2", "-.", "*"),
    "td3": Style("#c49c94", ":", "*"),
    "ppo_history": Style("#ad494a", "--", "P"),
    "dagger": Style("#67000d", "-", "h"),
    "bc": Style("#e7969c", ":", "h"),
}

#: algorithm id -> (module, class) of the SB3 / sb3-contrib algorithm that loads its zips
ALGORITHMS: dict[str, tuple[str, str]] = {
    "ppo": ("stable_baselines3", "PPO"),
    "a2c": ("stable_baselines3", "A2C"),
    "sac": ("stable_baselines3", "SAC"),
    "td3": ("stable_baselines3", "TD3"),
    "ddpg": ("stable_baselines3", "DDPG"),
    "recurrent_ppo": ("sb3_contrib", "RecurrentPPO"),
    "tqc": ("sb3_contrib", "TQC"),
}
#: algorithms whose policy carries a hidden state through the episode
RECURRENT = frozenset({"recurrent_ppo"})

#: the module of a zip's saved policy class -> the algorithm that saved it (for the two
#: modules several algorithms share, :func:`detect_algorithm` reads the saved settings)
_POLICY_MODULES = {
    "stable_baselines3.common.policies": "ppo",  # or a2c
    "stable_baselines3.sac.policies": "sac",
    "stable_baselines3.td3.policies": "td3",  # or ddpg
    "sb3_contrib.common.recurrent.policies": "recurrent_ppo",
    "sb3_contrib.tqc.policies": "tqc",
}

#: the env's action sizes (``shipgym.envs.core``: one rudder command; guidance: two)
ACTION_MODE_OF_SIZE = {1: "rudder", 2: "guidance"}

#: the optional files beside a model zip
META_FILE = "meta.json"
#: the model zips a policy folder is read from, in this order (else its one ``.zip``)
MODEL_FILES = ("model.zip", "best_model.zip")
#: the folder of one training seed inside a policy folder: ``seed_<k>``
SEED_FOLDER = re.compile(r"seed_(\d+)")
#: rows of every network forward (one env's observation is padded to it, more are chunked)
BATCH_ROWS = 16

#: saved training schedules a scoring run does not need (and that may not unpickle under
#: another Python version): replaced on load, as rl-baselines3-zoo's ``enjoy`` does
_INFERENCE_ONLY = {
    "learning_rate": 0.0,
    "lr_schedule": lambda _: 0.0,
    "clip_range": lambda _: 0.0,
}


def shipped_policies() -> list[str]:
    """Names of the pre-trained policies shipped in ``baselines/learned/policies`` (one
    model, or ``seed_<k>/`` folders of one each)."""
    return sorted(
        p.name
        for p in POLICY_DIR.iterdir()
        if (p / META_FILE).is_file() or any((s / META_FILE).is_file() for s in _seeds(p).values())
    )


def _seeds(folder: Path) -> dict[int, Path]:
    """Training seed -> its ``seed_<k>`` folder in ``folder`` (those holding a model zip),
    in seed order; empty for a folder of one model and for a file."""
    if not folder.is_dir():
        return {}
    found = {
        int(match.group(1)): sub
        for sub in folder.iterdir()
        if (match := SEED_FOLDER.fullmatch(sub.name)) and sub.is_dir() and any(sub.glob("*.zip"))
    }
    return dict(sorted(found.items()))


class PolicyMeta(BaseModel):
    """The keys of a ``meta.json`` this module reads (each optional; others are kept).

    ``name``: the policy's name; ``algo``: one of :data:`ALGORITHMS` (must be the zip's);
    ``action_mode``: must be the zip's; ``env_steps`` and ``wall_time_s`` [s]: the training
    cost, both or neither; ``seed``: the training seed; ``history_steps``: the K control
    steps of history the model observes (the training env's ``history_steps``; absent: 0,
    or the ``config.env.history_steps`` that ``shipgym train`` records).
    """

    model_config = ConfigDict(extra="allow", frozen=True)

    name: str | None = Field(None, min_length=1)
    algo: Literal[tuple(ALGORITHMS)] | None = None  # type: ignore[valid-type]
    action_mode: Literal[tuple(ACTION_MODE_OF_SIZE.values())] | None = None  # type: ignore[valid-type]
    env_steps: int | None = Field(None, ge=0)
    wall_time_s: float | None = Field(None, ge=0)
    seed: int | None = Field(None, ge=0)
    history_steps: StrictInt | None = Field(None, ge=0, le=MAX_HISTORY_STEPS)

    @model_validator(mode="after")
    def _cost_complete(self) -> PolicyMeta:
        if (self.env_steps is None) != (self.wall_time_s is None):
            raise ValueError("give both 'env_steps' and 'wall_time_s' (training cost) or neither")
        return self


@dataclasses.dataclass(frozen=True)
class PolicyFiles:
    """A learned policy's files: the model, its checked ``meta.json`` (``meta``: as written,
    empty without one), the observation statistics beside it, if any
    (:func:`~shipgym_baselines.learned.normalizer.normalizer_file`), and the training seed
    (its ``seed_<k>`` folder's, else the meta's; None when neither says)."""

    model: SavedModel
    algo: str
    meta: dict[str, Any]
    cost: PolicyMeta
    vecnormalize: Path | None
    training_seed: int | None = None


def _source(name_or_path: str | Path) -> Path:
    """A shipped policy name, a folder or a zip → its path (a clear error if none)."""
    path = Path(name_or_path).expanduser()
    if not path.exists() and (POLICY_DIR / str(name_or_path)).is_dir():
        path = POLICY_DIR / str(name_or_path)
    if not path.exists():
        raise ControllerError(
            f"{name_or_path!r} is not a trained policy (a model zip, or a folder holding one); "
            f"shipped: {', '.join(shipped_policies())}"
        )
    return path


def _seed_folder(path: Path, training_seed: int | None) -> tuple[Path, int | None]:
    """The folder of ``training_seed`` (None: the first) when ``path`` holds ``seed_<k>``
    folders, with that seed; else ``path`` itself and None."""
    seeds = _seeds(path)
    if not seeds:
        return path, None
    tops = sorted(z.name for z in path.glob("*.zip"))
    if tops:
        raise ControllerError(
            f"{path}: holds both a model ({', '.join(tops)}) and training-seed folders "
            f"({', '.join(p.name for p in seeds.values())}): name the one to use"
        )
    if training_seed is None:
        training_seed = next(iter(seeds))
    if training_seed not in seeds:
        raise ControllerError(
            f"{path}: no training seed {training_seed}; it holds "
            f"{', '.join(p.name for p in seeds.values())}"
        )
    return seeds[training_seed], training_seed


def training_seeds(name_or_path: str | Path) -> list[int | None]:
    """The training seeds of a learned policy: its ``seed_<k>`` folders' k, in order; for a
    single model, the ``seed`` of its ``meta.json`` ([None] when it gives none)."""
    seeds = _seeds(_source(name_or_path))
    return list(seeds) if seeds else [read_policy(name_or_path).training_seed]


def model_zip(name_or_path: str | Path, training_seed: int | None = None) -> Path:
    """A shipped policy name, a trained agent's folder or a model zip → the model zip.

    A folder means its ``model.zip``, else ``best_model.zip``, else its one ``.zip``; a
    folder of ``seed_<k>`` folders means that of ``training_seed`` (None: the first)."""
    path, _ = _seed_folder(_source(name_or_path), training_seed)
    return _folder_model(path)


def _folder_model(path: Path) -> Path:
    if not path.is_dir():
        return path
    for name in MODEL_FILES:
        if (path / name).is_file():
            return path / name
    zips = sorted(path.glob("*.zip"))
    if len(zips) != 1:
        found = f"it holds {', '.join(z.name for z in zips)}" if zips else "it holds none"
        raise ControllerError(
            f"{path}: a trained agent's folder holds model.zip, best_model.zip or one .zip "
            f"model; {found}"
        )
    return zips[0]


def policy_label(name_or_path: str | Path) -> str:
    """The table name of a learned policy: a shipped policy's name; a folder's name (a
    ``seed_<k>`` folder with its parent's: ``ppo/seed_1``); for an SB3 zip its file's stem
    (``work/ppo_ship.zip`` → ``ppo_ship``), except a trained agent's own model file
    (``model.zip``, ``best_model.zip``), which is named as its folder.  ``--name`` (the long
    form's ``name``) gives any other."""
    path = Path(name_or_path).expanduser()
    if path.suffix == ".zip":
        return _folder_label(path.resolve().parent) if path.name in MODEL_FILES else path.stem
    if not path.exists():
        return str(name_or_path)
    return _folder_label(path.resolve())


def _folder_label(path: Path) -> str:
    """A trained agent's folder's name (a ``seed_<k>`` folder with its parent's)."""
    return f"{path.parent.name}/{path.name}" if SEED_FOLDER.fullmatch(path.name) else path.name


def read_model(path: Path, history_steps: int = 0) -> SavedModel:
    """The algorithm and action mode of a model zip, read from its ``data`` entry; a
    truncated or corrupt zip, or one that is not an SB3 model of this env observing
    ``history_steps`` steps of history (its meta's), is a clear error naming the file."""
    stat = path.stat()
    return _read_model(path.resolve(), stat.st_mtime_ns, stat.st_size, history_steps)


@functools.lru_cache(maxsize=64)
def _read_model(path: Path, _mtime_ns: int, _size: int, history_steps: int) -> SavedModel:
    try:
        with zipfile.ZipFile(path) as archive:
            names = archive.namelist()
            broken = archive.testzip()
            text = archive.read("data").decode() if "data" in names else None
    except (zipfile.BadZipFile, zlib.error, EOFError, OSError, UnicodeDecodeError) as exc:
        raise ControllerError(
            f"{path}: not a readable model zip (truncated or corrupt: {exc})"
        ) from None
    if broken is not None:
        raise ControllerError(f"{path}: corrupt model zip: {broken!r} fails its CRC check")
    if text is None or "policy.pth" not in names:
        raise ControllerError(
            f"{path}: truncated, or not a stable-baselines3 model zip (it has no 'data' and "
            "'policy.pth' entries)"
        )
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ControllerError(
            f"{path}: corrupt model zip: its 'data' is not JSON ({exc})"
        ) from None
    observed = _box_shape(data.get("observation_space"))
    sizes = {(observation_size(flag, history_steps),): flag for flag in (False, True)}
    if observed not in sizes:
        raise ControllerError(
            f"{path}: the model observes {_describe(data.get('observation_space'))}; with "
            f"history_steps {history_steps} (its {META_FILE}'s, 0 without one) the "
            f"ShipPathFollow envs observe shape ({observation_size(False, history_steps)},) "
            f"({', '.join(OBS_NAMES)}, then {HISTORY_WIDTH} per step of history), or "
            f"({observation_size(True, history_steps)},) with context_features; a model "
            f'trained with history_steps K needs "history_steps": K in its {META_FILE}'
        )
    shape = _box_shape(data.get("action_space"))
    mode = ACTION_MODE_OF_SIZE.get(shape[0]) if shape is not None and len(shape) == 1 else None
    if mode is None:
        raise ControllerError(
            f"{path}: the model acts in {_describe(data.get('action_space'))}; the env takes "
            "a Box of shape (1,) (action_mode rudder) or (2,) (guidance)"
        )
    return SavedModel(
        path=path,
        algo=detect_algorithm(data),
        action_mode=mode,
        context_features=sizes[observed],
        history_steps=history_steps,
    )


def _box_shape(space: Any) -> tuple[int, ...] | None:
    """The shape of a saved ``Box`` space (None for any other space)."""
    if not isinstance(space, dict) or "Box" not in str(space.get(":type:", "")):
        return None
    shape = space.get("_shape")
    return tuple(shape) if isinstance(shape, list) else None


def _describe(space: Any) -> str:
    if not isinstance(space, dict):
        return "an unknown space"
    kind = str(space.get(":type:", "?")).removeprefix("<class '").removesuffix("'>")
    return f"{kind.rsplit('.', 1)[-1]} of shape {tuple(space.get('_shape') or ())}"


def detect_algorithm(data: dict[str, Any]) -> str | None:
    """The algorithm id that saved a model, from its zip's ``data`` (None: cannot tell).

    The saved policy class's module names it; PPO and A2C share ``ActorCriticPolicy`` (A2C
    saves no ``clip_range``), TD3 and DDPG ``TD3Policy`` (DDPG is TD3 without delayed
    policy updates and without target smoothing: ``policy_delay`` 1, ``target_noise_clip``
    0, SB3's DDPG settings)."""
    policy_class = data.get("policy_class")
    module = policy_class.get("__module__") if isinstance(policy_class, dict) else None
    algo = _POLICY_MODULES.get(str(module))
    if algo == "ppo" and "clip_range" not in data:
        return "a2c"
    if algo == "td3" and data.get("policy_delay") == 1 and data.get("target_noise_clip") == 0:
        return "ddpg"
    return algo


def _meta_file(zip_path: Path) -> Path | None:
    """``meta.json`` beside the zip, or one folder up for a training run's checkpoints."""
    folders = [zip_path.parent]
    if zip_path.parent.name == "checkpoints":
        folders.append(zip_path.parent.parent)
    return next((d / META_FILE for d in folders if (d / META_FILE).is_file()), None)


def _read_meta(file: Path) -> tuple[dict[str, Any], PolicyMeta]:
    try:
        data = json.loads(file.read_text(encoding="utf-8"))
    except UnicodeDecodeError as exc:
        raise ControllerError(f"{file}: not JSON (not UTF-8 text: {exc.reason})") from None
    except json.JSONDecodeError as exc:
        raise ControllerError(
            f"{file}: not JSON ({exc.msg} at line {exc.lineno}, column {exc.colno})"
        ) from None
    return data, validate_model(data, PolicyMeta, str(file), ControllerError)


def read_policy(name_or_path: str | Path, training_seed: int | None = None) -> PolicyFiles:
    """A learned policy's files, checked: the zip (:func:`read_model`), ``meta.json`` if
    present (its ``algo`` and ``action_mode`` must be the zip's, its ``seed`` the
    ``seed_<k>`` folder's), the observation statistics.  ``training_seed``: which seed's files
    (None: the first; a single model's must be its meta's seed)."""
    folder, seed = _seed_folder(_source(name_or_path), training_seed)
    model_file = _folder_model(folder)
    meta_file = _meta_file(model_file)
    meta, checked = _read_meta(meta_file) if meta_file else ({}, PolicyMeta())
    saved = read_model(model_file, _history_steps(meta, checked, meta_file))
    if seed is None:
        seed = checked.seed
        if training_seed is not None and training_seed != seed:
            said = f"its {META_FILE} says seed {seed}" if seed is not None else "it names none"
            raise ControllerError(f"{saved.path}: no training seed {training_seed}: {said}")
    elif checked.seed is not None and checked.seed != seed:
        raise ControllerError(
            f"{meta_file}: key 'seed' is {checked.seed}, but the folder is {folder.name}"
        )
    algo = saved.algo
    if checked.algo is not None:
        if algo is not None and checked.algo != algo:
            raise ControllerError(
                f"{meta_file}: key 'algo' is {checked.algo!r}, but {saved.path.name} was "
                f"saved by {algo!r}"
            )
        algo = checked.algo
    if algo is None:
        raise ControllerError(
            f"{saved.path}: cannot tell which algorithm saved it (its policy class is not "
            f"one of SB3's or sb3-contrib's); give a {META_FILE} beside it with \"algo\": one "
            f"of {', '.join(ALGORITHMS)}"
        )
    if checked.action_mode is not None and checked.action_mode != saved.action_mode:
        raise ControllerError(
            f"{meta_file}: key 'action_mode' is {checked.action_mode!r}, but "
            f"{saved.path.name} acts in {saved.action_mode!r} mode (its action space)"
        )
    return PolicyFiles(
        model=saved,
        algo=algo,
        meta=meta,
        cost=checked,
        vecnormalize=normalizer_file(saved.path.parent),
        training_seed=seed,
    )


def _history_steps(meta: dict[str, Any], checked: PolicyMeta, meta_file: Path | None) -> int:
    """The K control steps of history a model observes, from its ``meta.json``: the key
    ``history_steps``, else the training config's ``config.env.history_steps``, else 0; the
    two disagreeing is a clear error."""
    config = meta.get("config")
    env = config.get("env") if isinstance(config, dict) else None
    recorded = env.get("history_steps") if isinstance(env, dict) else None
    if recorded is not None:
        try:
            recorded = check_history_steps(recorded)
        except ValueError as exc:
            raise ControllerError(f"{meta_file}: key 'config.env.history_steps': {exc}") from None
    if checked.history_steps is None:
        return 0 if recorded is None else recorded
    if recorded is not None and recorded != checked.history_steps:
        raise ControllerError(
            f"{meta_file}: key 'history_steps' is {checked.history_steps}, but its training "
            f"config's env.history_steps is {recorded}"
        )
    return checked.history_steps


def load_model(saved: SavedModel, algo: str) -> Any:
    """The SB3 model of ``saved``'s zip, saved by ``algo``, on the CPU, read as data
    (:func:`load_data_only`); a zip that only unpickling can read is refused unless the
    command trusts pickles, then loaded by SB3; a zip that does not load is a clear error."""
    path = saved.path
    module, name = ALGORITHMS[algo]
    try:
        algorithm = getattr(importlib.import_module(module), name)
    except ImportError as exc:
        from shipgym_baselines.extras import install_hint

        raise ControllerError(
            f"{path}: a {name} model needs {module} ({exc}): {install_hint('rl')}"
        ) from exc
    try:
        return load_data_only(saved, algorithm)
    except UnsafeFileError:
        if not pickle_trusted():
            raise
    try:
        return algorithm.load(str(path), device="cpu", custom_objects=_INFERENCE_ONLY)
    except (
        zipfile.BadZipFile,
        zlib.error,
        EOFError,
        pickle.UnpicklingError,
        RuntimeError,
        ValueError,
        KeyError,
    ) as exc:
        raise ControllerError(f"{path}: cannot load it as a {name} model: {exc}") from exc


@functools.lru_cache(maxsize=32)
def _cached_model(saved: SavedModel, stamp: tuple[int, int], trusted: bool, algo: str) -> Any:
    """:func:`load_model`, once per process for a file (``saved.path``, resolved) of the
    same ``stamp`` (its modification time [ns] and size [bytes]) and the same trust in
    pickles: a leaderboard worker plays the same agents on many scenarios.  Inference leaves
    a model unchanged (evaluation mode, no gradient); episode state (history, LSTM) lives in
    the policy."""
    return load_model(saved, algo)


def lean_forward(policy: Any) -> Any:
    """The deterministic action of an SB3 policy as ``policy.predict(obs,
    deterministic=True)`` computes it, bit for bit, for a batch of observations (n, d),
    without what ``predict`` adds per call (the API checks, ``obs_to_tensor``'s shape
    handling, the action distribution object and its argument validation): a PPO
    ``ActorCriticPolicy`` with a diagonal Gaussian (the mean of ``action_net``, clipped
    to the action space), a SAC actor (deterministic) or a TD3 actor (rescaled from the
    squashed [-1, 1]); None for any other policy (it keeps ``predict``).  The shipped
    agents' actions are a golden file (``tests/golden/shipped_policy_actions.npz``)."""
    import torch
    from gymnasium import spaces
    from stable_baselines3.common.distributions import DiagGaussianDistribution
    from stable_baselines3.common.policies import ActorCriticPolicy
    from stable_baselines3.sac.policies import SACPolicy
    from stable_baselines3.td3.policies import TD3Policy

    box = policy.action_space
    if not isinstance(box, spaces.Box):
        return None
    shape = (-1, *box.shape)
    if (
        type(policy) is ActorCriticPolicy
        and type(policy.action_dist) is DiagGaussianDistribution
        and not policy.squash_output
    ):

        def actor(obs: Any) -> Any:
            features = policy.extract_features(obs, policy.pi_features_extractor)
            return policy.action_net(policy.mlp_extractor.forward_actor(features))

    elif type(policy) is SACPolicy:

        def actor(obs: Any) -> Any:
            return policy.actor(obs, True)

    elif type(policy) is TD3Policy:
        actor = policy.actor
    else:
        return None

    def forward(obs: np.ndarray) -> np.ndarray:
        with torch.no_grad():
            actions = actor(torch.as_tensor(obs, device=policy.device)).cpu().numpy()
        actions = actions.reshape(shape)
        if policy.squash_output:
            return policy.unscale_action(actions)
        return np.clip(actions, box.low, box.high)

    return forward


def _eval_mode_once(policy: Any) -> None:
    """Put the network in evaluation mode once, for good: SB3's ``predict`` calls
    ``set_training_mode(False)`` on every call, which walks every module (≈ 30 % of a
    small network's forward time, measured on the leaderboard's steps); the mode never
    changes during evaluation, so later calls are skipped.  Same actions, bit for bit."""
    policy.set_training_mode(False)
    policy.set_training_mode = lambda mode: None  # instance attribute: this policy only


@dataclasses.dataclass
class _Memory:
    """What a policy carries from one step of an episode to the next: the LSTM state
    ``(h, c)`` (each of shape (layers, hidden); None before the first step) and whether
    the next step starts the episode."""

    state: tuple[np.ndarray, np.ndarray] | None = None
    start: bool = True


class LearnedPolicy:
    """A trained agent from a policy folder or model zip (see :func:`read_policy`).

    ``name``: its name (default: the meta's, else :func:`policy_label`);
    ``training_seed``: which of a multi-seed policy's seeds (None: the first), kept as the
    attribute ``training_seed`` (a single model's: its meta's seed); ``history_steps``: the
    K the caller expects (None: the meta's, :class:`PolicyMeta`; another than the meta's is
    a clear error)."""

    kind = "learned"

    def __init__(
        self,
        path: str | Path,
        name: str | None = None,
        training_seed: int | None = None,
        history_steps: int | None = None,
    ) -> None:
        files = read_policy(path, training_seed)
        if history_steps is not None and history_steps != files.model.history_steps:
            raise ControllerError(
                f"{files.model.path}: asked for history_steps {history_steps}, but it was "
                f"trained with history_steps {files.model.history_steps} (its {META_FILE})"
            )
        self.model_path = files.model.path
        self.algo = files.algo
        self.meta: dict[str, Any] = files.meta
        self._cost = files.cost
        self.training_seed = files.training_seed
        self.name = name or files.cost.name or policy_label(path)
        self.action_mode: str = files.model.action_mode
        import torch

        torch.set_num_threads(1)  # one small MLP per episode; leaderboard workers share cores
        #: the model reads the controller-context features after the observation: the
        #: policy appends them from the context at reset (shipgym.envs.core.CONTEXT_NAMES)
        self.context_features = files.model.context_features
        self._context_rows: list[np.ndarray] = []
        #: K: the model reads the last K control steps after them: the policy keeps the
        #: window of each episode from the observations it is given (core.ObservationHistory)
        self.history_steps = files.model.history_steps
        self._history: ObservationHistory | None = None
        stat = Path(self.model_path).stat()
        self.model = _cached_model(
            dataclasses.replace(files.model, path=Path(self.model_path).resolve()),
            (stat.st_mtime_ns, stat.st_size),
            pickle_trusted(),
            self.algo,
        )
        _eval_mode_once(self.model.policy)
        self.obs_normalizer: ObsNormalizer | None = (
            load_normalizer(files.vecnormalize) if files.vecnormalize is not None else None
        )
        #: the number of observation entries the model reads
        self.observation_width = width = observation_size(self.context_features, self.history_steps)
        if self.obs_normalizer is not None and len(self.obs_normalizer.mean) != width:
            raise ControllerError(
                f"{files.vecnormalize}: statistics of {len(self.obs_normalizer.mean)} "
                f"observation entries, the model reads {width}"
            )
        self.recurrent = self.algo in RECURRENT
        #: the deterministic action without ``predict``'s per-call checks and distribution
        #: object (None: ``predict``, e.g. a recurrent or another policy class)
        self._lean = None if self.recurrent else lean_forward(self.model.policy)
        self._memory = _Memory()
        self._batch: list[_Memory] = []

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        check_action_mode(self, context)
        self._memory = _Memory()
        self._context_rows = [context.feature_row] if self.context_features else []
        self._history = ObservationHistory(1, self.history_steps) if self.history_steps else None

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        rows = self._model_rows(np.asarray(obs)[None], [0])
        return self._act_rows(rows, [self._memory])[0]

    def reset_batch(self, contexts: Sequence[ControllerContext]) -> None:
        """Start one episode per context (envs in lockstep, :meth:`act_batch`)."""
        for context in contexts:
            check_action_mode(self, context)
        self._batch = [_Memory() for _ in contexts]
        self._context_rows = [c.feature_row for c in contexts] if self.context_features else []
        self._history = (
            ObservationHistory(len(contexts), self.history_steps) if self.history_steps else None
        )

    def act_batch(self, obs: np.ndarray, episodes: Sequence[int]) -> np.ndarray:
        """The actions (one row each) for the observations ``obs`` (one row each) of the
        episodes ``episodes`` (indices into :meth:`reset_batch`'s contexts); each is the
        action :meth:`act` would give in that episode alone, bit for bit."""
        rows = self._model_rows(np.asarray(obs), episodes)
        return self._act_rows(rows, [self._batch[i] for i in episodes])

    def _model_rows(self, obs: np.ndarray, episodes: Sequence[int]) -> np.ndarray:
        """The observations the model reads, one row per episode of ``episodes``: the env's
        own when they have the model's width (an env made with its context_features and
        history_steps); from the env's plain observation (its first entries, OBS_NAMES) the
        episodes' context features appended, then their history windows, advanced by one
        control step per call after the episode's first (each call is the next step)."""
        width = obs.shape[1]
        if width == self.observation_width:
            return obs
        if width not in (len(OBS_NAMES), observation_size(True)):
            raise ControllerError(
                f"{self.name}: observations of {width} entries; the model reads "
                f"{self.observation_width} (context_features {self.context_features}, "
                f"history_steps {self.history_steps}), or takes the env's plain "
                f"{len(OBS_NAMES)} (or {observation_size(True)} with context features) and "
                "appends the rest: an env made with another history_steps?"
            )
        parts = [obs[:, : len(OBS_NAMES)]]
        if self.context_features:
            parts.append(np.stack([self._context_rows[i] for i in episodes]))
        if self._history is not None:
            self._history.stepped(episodes)
            parts.append(self._history.update(parts[0], episodes))
        return np.concatenate(parts, axis=1) if len(parts) > 1 else parts[0]

    def _act_rows(self, obs: np.ndarray, memories: list[_Memory]) -> np.ndarray:
        if self.obs_normalizer is not None:
            obs = self.obs_normalizer.normalize_obs(obs)  # elementwise: batch-independent
        chunks = range(0, len(obs), BATCH_ROWS)
        return np.concatenate(
            [self._forward(obs[i : i + BATCH_ROWS], memories[i : i + BATCH_ROWS]) for i in chunks]
        )

    def _forward(self, obs: np.ndarray, memories: list[_Memory]) -> np.ndarray:
        """One network forward on ``obs`` (at most :data:`BATCH_ROWS` rows) padded with zero
        rows to :data:`BATCH_ROWS` (padding rows start an episode with a zero state)."""
        n = len(obs)
        padded = np.zeros((BATCH_ROWS, *obs.shape[1:]), dtype=obs.dtype)
        padded[:n] = obs
        if not self.recurrent:
            if self._lean is not None:
                return self._lean(padded)[:n]
            actions, _ = self.model.predict(padded, deterministic=True)
            return actions[:n]
        layers, _, hidden = self.model.policy.lstm_hidden_state_shape
        h = np.zeros((layers, BATCH_ROWS, hidden), dtype=np.float32)
        c = np.zeros_like(h)
        starts = np.ones(BATCH_ROWS, dtype=bool)
        for i, memory in enumerate(memories):
            if memory.state is not None:
                h[:, i], c[:, i] = memory.state
            starts[i] = memory.start
        actions, (h, c) = self.model.predict(
            padded, state=(h, c), episode_start=starts, deterministic=True
        )
        for i, memory in enumerate(memories):
            memory.state = (h[:, i].copy(), c[:, i].copy())
            memory.start = False
        return actions[:n]

    def episode_stats(self) -> dict[str, float]:
        """Training cost, reported beside the metrics on the leaderboard (when the meta
        gives it)."""
        if self._cost.env_steps is None or self._cost.wall_time_s is None:
            return {}
        return {
            "train_env_steps": float(self._cost.env_steps),
            "train_wall_s": float(self._cost.wall_time_s),
        }
