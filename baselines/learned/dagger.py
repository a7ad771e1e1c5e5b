"""DAgger: a student policy distilled from a teacher by dataset aggregation.

DAgger (Ross, Gordon & Bagnell 2011) trains a student by supervised learning on the states
its own rollouts visit, each labelled with the teacher's action there:

1. round 0 rolls out the teacher (β₀ = 1) and labels every visited state;
2. round i ≥ 1 rolls out the mixture policy: at every step the teacher's action is executed
   with probability βᵢ, else the student's; the teacher labels every visited state;
3. after each round the student is fitted on all rounds' labels so far (the aggregate):
   mean squared error between its deterministic action (the mean of its Gaussian) and the
   teacher's action, both normalised to [-1, 1] (the env's action space must be that box).

The β schedule (:attr:`DaggerSettings.beta_schedule`):

==============  ==========================  ===============================================
schedule        βᵢ                          when
==============  ==========================  ===============================================
``indicator``   1 for i = 0, else 0         default: Ross et al.'s parameter-free choice,
                                            which they found often best in practice; the
                                            student meets its own mistakes from round 1,
                                            and the teacher labels every state anyway
``exponential`` pⁱ (p = ``beta_decay``)     a student that drifts far from the teacher's
                                            states early (its labels there are of no use)
==============  ==========================  ===============================================

The teacher (:class:`Teacher`) is called on the env in the state it is in, so a privileged
teacher may read the env's truth; it is told the action actually applied after each step
(a stateful teacher warm-starts from it).  The student (an SB3 ``ActorCriticPolicy``, the
policy of a PPO model) sees only the observations and never calls the teacher.  It saves
as a PPO zip (:func:`save_student`) that PPO can load and fine-tune, and that the data-only
loader (:func:`shipgym_baselines.learned.loading.load_data_only`) reads for the env's
spaces.  Its ``policy_kwargs`` are JSON data (``net_arch``, ``log_std_init``), so nothing in
the zip needs unpickling.

Run folder (:func:`run_dagger`; its files are :data:`DAGGER_OUTPUTS`)::

    dagger.json              settings, spaces and the caller's identity of env and teacher
    rollouts/r<R>_e<E>.npz   the label cache: one finished rollout each (round R, episode E)
    data/round_<R>.npz       the round's labelled states (:data:`DATA_KEYS`)
    students/round_<R>.zip   the student after training on rounds 0…R (a PPO zip)
    model.zip                the newest student
    rounds.json              one record per finished round (:data:`ROUND_KEYS`)

A killed run resumes (``resume=True``) from its last finished round: finished rounds are
not rolled out again, and in the unfinished round every rollout already in the cache is
read back instead of relabelled.  Every rollout is seeded by its key (round, episode), the
student's training by (seed, round), so a resumed run's data and students equal an
uninterrupted run's (tested).  A folder holding a run of other settings, or anything else,
is refused; ``force=True`` replaces a DAgger run.
"""

from __future__ import annotations

import concurrent.futures
import dataclasses
import hashlib
import io
import json
import pickle
import time
import zipfile
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any, Literal, Protocol

import numpy as np
from pydantic import Field, field_validator

from shipgym.config import StrictModel
from shipgym.limits import worker_count
from shipgym_baselines.errors import RunError
from shipgym_baselines.executor import Inline, task_pool
from shipgym_baselines.records.folders import check_out_usable
from shipgym_baselines.records.locking import LOCK_FILE, out_lock
from shipgym_baselines.records.manifest import MANIFEST_FILE, Manifest, clear_listed
from shipgym_baselines.records.outfiles import check_no_links, make_dir, write_bytes
from shipgym_baselines.records.runrecord import now, versions

SETTINGS_FILE = "dagger.json"
ROUNDS_FILE = "rounds.json"
ROLLOUT_DIR = "rollouts"
DATA_DIR = "data"
STUDENT_DIR = "students"
MODEL_FILE = "model.zip"
#: what a DAgger run writes into its folder, a staged ``.<name>.part`` a kill may leave
#: included (``force`` clears these, and only these)
DAGGER_OUTPUTS = (
    SETTINGS_FILE,
    ROUNDS_FILE,
    ROLLOUT_DIR,
    DATA_DIR,
    STUDENT_DIR,
    MODEL_FILE,
    ".*.part",
)
#: the arrays of a rollout and of a round file, one row per visited state: the observation,
#: the teacher's label and the applied action (normalised, float32), whether the teacher's
#: action was the one applied, the env's reward after the step
STEP_KEYS = ("obs", "label", "applied", "by_teacher", "reward")
#: a round file's arrays: :data:`STEP_KEYS` and, per row, its round, its episode id
#: (round × episodes_per_round + episode), the env seed and the step in the episode
DATA_KEYS = (*STEP_KEYS, "round", "episode", "seed", "step")
#: the keys of a round's record in ``rounds.json``: its β, rollouts and labels (this round's;
#: ``labels_total``: the aggregate's, the env steps so far), the share of steps the teacher's
#: action was applied, the rollouts' mean return, the teacher's and the rollouts' CPU seconds
#: and labels per CPU second of each, the rollouts read from the label cache, the previous
#: student's MSE on this round's labels (None in round 0), the fitted student's MSE on the
#: aggregate, its gradient steps and the training's CPU seconds
ROUND_KEYS = (
    "round",
    "beta",
    "episodes",
    "labels",
    "labels_total",
    "teacher_fraction",
    "mean_return",
    "teacher_cpu_s",
    "rollout_cpu_s",
    "labels_per_teacher_cpu_s",
    "labels_per_cpu_s",
    "cached_rollouts",
    "student_mse_before",
    "train_loss",
    "gradient_steps",
    "train_cpu_s",
)
#: the format of ``dagger.json`` and the cache files
FORMAT = 1
BETA_SCHEDULES = ("indicator", "exponential")


class Teacher(Protocol):
    """What labels the states: made afresh in each rollout's process by a factory.

    ``reset`` after the env's reset (``seed``: the episode's env seed); ``label`` the action
    for the state the env is in (``obs``, ``info``: what the env last returned; ``env``: for
    a privileged teacher's truth), in the env's action space [-1, 1]; ``observe_applied``
    the action the env was stepped with (the teacher's or the student's), after the step."""

    def reset(self, env: Any, seed: int) -> None: ...

    def label(self, obs: np.ndarray, info: dict[str, Any], env: Any) -> np.ndarray: ...

    def observe_applied(self, action: np.ndarray) -> None: ...


class DaggerSettings(StrictModel):
    """Everything that decides a DAgger run's data and student (recorded in
    ``dagger.json``; a resumed run must have the same).  The number of rounds is not among
    them: a finished run can be continued for more rounds."""

    #: seeds the student's initial weights, the mixture's coin flips and the minibatches
    seed: int = Field(0, ge=0)
    #: rollouts per round
    episodes_per_round: int = Field(8, ge=1)
    #: the env seed of round 0's first episode; episode e of round r gets
    #: ``env_seed_start + r * episodes_per_round + e``
    env_seed_start: int = Field(0, ge=0)
    beta_schedule: Literal["indicator", "exponential"] = "indicator"
    #: p of the exponential schedule βᵢ = pⁱ
    beta_decay: float = Field(0.5, gt=0, lt=1)
    #: the student's hidden layers (policy and value heads alike)
    net_arch: list[int] = Field(default_factory=lambda: [64, 64])
    #: log standard deviation of the student's Gaussian (untrained by imitation; what PPO
    #: fine-tuning starts from)
    log_std_init: float = 0.0
    #: passes over the aggregated data per round
    epochs: int = Field(20, ge=1)
    batch_size: int = Field(256, ge=1)
    #: Adam's step size (a fresh Adam each round)
    learning_rate: float = Field(1e-3, gt=0)
    #: True: each round continues from the previous round's student; False: from a fresh
    #: initialisation (Ross et al.'s literal algorithm)
    warm_start: bool = True

    @field_validator("net_arch")
    @classmethod
    def _layers(cls, value: list[int]) -> list[int]:
        if not value or any(n < 1 for n in value):
            raise ValueError("one or more layer widths, each ≥ 1")
        return value

    def beta(self, round_: int) -> float:
        """βᵢ of round ``round_``: the probability the teacher's action is executed."""
        if round_ == 0:
            return 1.0
        if self.beta_schedule == "indicator":
            return 0.0
        return float(self.beta_decay**round_)

    def episode_seed(self, round_: int, episode: int) -> int:
        """The env seed of rollout ``episode`` of round ``round_``."""
        return self.env_seed_start + round_ * self.episodes_per_round + episode

    def policy_kwargs(self) -> dict[str, Any]:
        """The student's SB3 ``policy_kwargs`` (JSON data only)."""
        return {"net_arch": list(self.net_arch), "log_std_init": float(self.log_std_init)}


# --- the student ------------------------------------------------------------------------------


def build_student(observation_space: Any, action_space: Any, settings: DaggerSettings) -> Any:
    """A PPO model for the spaces, its policy the untrained student (weights seeded by
    ``settings.seed``), on the CPU, with PPO's default hyperparameters for fine-tuning."""
    import torch
    from stable_baselines3 import PPO

    torch.set_num_threads(1)  # small networks: threads only contend with the rollouts
    model = PPO(
        "MlpPolicy",
        env=None,
        policy_kwargs=settings.policy_kwargs(),
        seed=settings.seed,
        device="cpu",
        _init_setup_model=False,
    )
    model.observation_space, model.action_space, model.n_envs = observation_space, action_space, 1
    model._setup_model()  # seeds torch with settings.seed before the weights are drawn
    model.policy.set_training_mode(False)
    return model


def _mean_action(policy: Any, obs: Any) -> Any:
    """The policy's deterministic action (its Gaussian's mean) for a batch of observations,
    differentiable (before SB3's clipping to the action space)."""
    return policy.get_distribution(obs).mode()


def student_state(model: Any) -> dict[str, np.ndarray]:
    """The student's weights as numpy arrays (what a rollout process rebuilds it from)."""
    return {k: v.detach().cpu().numpy().copy() for k, v in model.policy.state_dict().items()}


def state_digest(state: Mapping[str, np.ndarray]) -> str:
    """A SHA-256 of weights (names, shapes, dtypes and bytes): which student rolled out."""
    digest = hashlib.sha256()
    for key in sorted(state):
        array = np.ascontiguousarray(state[key])
        digest.update(f"{key}:{array.dtype.str}:{array.shape};".encode())
        digest.update(array.tobytes())
    return digest.hexdigest()


def fit_student(
    model: Any,
    obs: np.ndarray,
    labels: np.ndarray,
    settings: DaggerSettings,
    round_: int,
) -> dict[str, float | int]:
    """Fit the student's mean action to ``labels`` (normalised) on ``obs`` by minibatch
    MSE and Adam, ``settings.epochs`` passes, minibatches drawn by (seed, round); returns
    ``train_loss`` (the final MSE over all rows), ``gradient_steps`` and ``train_cpu_s``."""
    import torch

    torch.set_num_threads(1)
    cpu = time.process_time()
    policy = model.policy
    x = torch.as_tensor(np.asarray(obs, dtype=np.float32))
    y = torch.as_tensor(np.asarray(labels, dtype=np.float32))
    optimizer = torch.optim.Adam(policy.parameters(), lr=settings.learning_rate)
    rng = np.random.default_rng([settings.seed, round_, 1])
    steps = 0
    policy.set_training_mode(True)
    for _ in range(settings.epochs):
        order = rng.permutation(len(x))
        for start in range(0, len(x), settings.batch_size):
            rows = torch.as_tensor(order[start : start + settings.batch_size])
            loss = torch.nn.functional.mse_loss(_mean_action(policy, x[rows]), y[rows])
            optimizer.zero_grad()
            loss.backward()
            optimizer.step()
            steps += 1
    policy.set_training_mode(False)
    return {
        "train_loss": student_mse(model, obs, labels),
        "gradient_steps": steps,
        "train_cpu_s": time.process_time() - cpu,
    }


def student_mse(model: Any, obs: np.ndarray, labels: np.ndarray) -> float:
    """Mean squared error of the student's mean action against ``labels`` (normalised)."""
    import torch

    with torch.no_grad():
        x = torch.as_tensor(np.asarray(obs, dtype=np.float32))
        y = torch.as_tensor(np.asarray(labels, dtype=np.float32))
        return float(torch.nn.functional.mse_loss(_mean_action(model.policy, x), y))


def save_student(model: Any, path: str | Path) -> Path:
    """Write the student as a PPO zip at ``path`` (replaced whole: a kill leaves the old
    file or the new one)."""
    buffer = io.BytesIO()
    model.save(buffer)
    return _write_bytes(Path(path), buffer.getvalue())


def load_student(
    path: str | Path, observation_space: Any, action_space: Any, settings: DaggerSettings
) -> Any:
    """The student saved at ``path``, rebuilt from ``settings`` for the spaces, its weights
    read as data (``torch.load(weights_only=True)``: nothing unpickled)."""
    import torch

    from shipgym_baselines.learned.loading import WEIGHTS_ENTRY

    model = build_student(observation_space, action_space, settings)
    try:
        with zipfile.ZipFile(path) as archive:
            weights = archive.read(WEIGHTS_ENTRY)
        state = torch.load(io.BytesIO(weights), map_location="cpu", weights_only=True)
        model.policy.load_state_dict(state, strict=True)
    except (
        OSError,
        KeyError,
        RuntimeError,
        EOFError,
        pickle.UnpicklingError,
        zipfile.BadZipFile,
    ) as exc:
        raise RunError(f"{path}: not a student of these settings ({exc})") from None
    model.policy.set_training_mode(False)
    return model


def policy_actions(model: Any) -> Callable[[np.ndarray], np.ndarray]:
    """The student as a function observation → action (deterministic, clipped to the
    action space): what an evaluation runs, with no teacher anywhere."""

    def act(obs: np.ndarray) -> np.ndarray:
        action, _ = model.policy.predict(obs, deterministic=True)
        return np.asarray(action, dtype=np.float32)

    return act


def evaluate(
    act: Callable[[np.ndarray], np.ndarray],
    make_env: Callable[[], Any],
    seeds: Sequence[int],
) -> np.ndarray:
    """The return (sum of rewards) of ``act`` in one episode per env seed."""
    returns = []
    for seed in seeds:
        env = make_env()
        obs, _ = env.reset(seed=int(seed))
        total, done = 0.0, False
        while not done:
            obs, reward, terminated, truncated, _ = env.step(act(obs))
            total += float(reward)
            done = terminated or truncated
        env.close()
        returns.append(total)
    return np.asarray(returns)


# --- rollouts ---------------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class RolloutJob:
    """One rollout: the mixture of teacher and student (weights ``student``; None: the
    teacher alone, β must be 1) in one episode of a fresh env.  Picklable when the
    factories are (top-level functions or ``functools.partial`` of them)."""

    round: int
    episode: int
    seed: int
    beta: float
    mix_seed: int
    make_env: Callable[[], Any]
    make_teacher: Callable[[], Teacher]
    policy_kwargs: dict[str, Any]
    student: dict[str, np.ndarray] | None = None


def _rollout_student(job: RolloutJob, env: Any) -> Any:
    """The SB3 policy of the job's student weights, for the env's spaces."""
    import torch
    from stable_baselines3.common.policies import ActorCriticPolicy

    policy = ActorCriticPolicy(
        env.observation_space, env.action_space, lambda _: 0.0, **job.policy_kwargs
    )
    policy.load_state_dict({k: torch.as_tensor(v) for k, v in job.student.items()}, strict=True)
    policy.set_training_mode(False)
    return policy


def rollout(job: RolloutJob) -> dict[str, Any]:
    """Run one rollout (top-level: process pools pickle it): the arrays of
    :data:`STEP_KEYS` and ``labels``, ``return``, ``teacher_cpu_s`` (the CPU time of every
    teacher call), ``cpu_s`` (the whole rollout's, env and teacher made included).  CPU
    times are the process's (``time.process_time``): exact here or in a process pool, an
    overcount in a thread pool, whose threads share the process."""
    import torch

    torch.set_num_threads(1)
    cpu = time.process_time()
    env = job.make_env()
    teacher = job.make_teacher()
    student = None if job.student is None else _rollout_student(job, env)
    if student is None and job.beta < 1.0:
        raise RunError(f"rollout {job.round}/{job.episode}: β = {job.beta} < 1 needs a student")
    shape = env.action_space.shape
    rng = np.random.default_rng([job.mix_seed, job.round, job.episode])
    rows: dict[str, list[Any]] = {key: [] for key in STEP_KEYS}
    obs, info = env.reset(seed=job.seed)
    spent = time.process_time()
    teacher.reset(env, job.seed)
    teacher_cpu = time.process_time() - spent
    done = False
    while not done:
        spent = time.process_time()
        label = np.asarray(teacher.label(obs, info, env), dtype=np.float64)
        teacher_cpu += time.process_time() - spent
        if label.shape != shape or not np.all(np.isfinite(label)):
            raise RunError(
                f"the teacher's label at step {len(rows['obs'])} of rollout "
                f"{job.round}/{job.episode} (seed {job.seed}) is {label.tolist()}: the action "
                f"space wants {shape} finite numbers"
            )
        label = np.clip(label, -1.0, 1.0).astype(np.float32)
        by_teacher = bool(rng.random() < job.beta)
        if by_teacher:
            applied = label
        else:
            applied, _ = student.predict(obs, deterministic=True)
            applied = np.asarray(applied, dtype=np.float32).reshape(shape)
        rows["obs"].append(np.asarray(obs, dtype=np.float32))
        rows["label"].append(label)
        rows["applied"].append(applied)
        rows["by_teacher"].append(by_teacher)
        obs, reward, terminated, truncated, info = env.step(applied)
        rows["reward"].append(float(reward))
        spent = time.process_time()
        teacher.observe_applied(applied)
        teacher_cpu += time.process_time() - spent
        done = bool(terminated or truncated)
    env.close()
    found: dict[str, Any] = {
        "obs": np.stack(rows["obs"]),
        "label": np.stack(rows["label"]),
        "applied": np.stack(rows["applied"]),
        "by_teacher": np.asarray(rows["by_teacher"], dtype=bool),
        "reward": np.asarray(rows["reward"], dtype=np.float64),
    }
    found.update(
        labels=len(rows["obs"]),
        teacher_cpu_s=teacher_cpu,
        cpu_s=time.process_time() - cpu,
    )
    found["return"] = float(found["reward"].sum())
    return found


def _cache_file(out: Path, round_: int, episode: int) -> Path:
    return out / ROLLOUT_DIR / f"r{round_:03d}_e{episode:05d}.npz"


def _cache_key(job: RolloutJob, digest: str | None) -> dict[str, Any]:
    """What a cached rollout must match to stand for ``job``."""
    return {
        "round": job.round,
        "episode": job.episode,
        "seed": job.seed,
        "beta": job.beta,
        "student": digest or "",
    }


def _write_rollout(file: Path, found: dict[str, Any], key: dict[str, Any]) -> None:
    stats = {k: found[k] for k in ("labels", "teacher_cpu_s", "cpu_s", "return")}
    meta = json.dumps({"format": FORMAT, "key": key, "stats": stats})
    _write_npz(file, {**{k: found[k] for k in STEP_KEYS}, "meta": np.array(meta)})


def _read_rollout(file: Path, key: dict[str, Any]) -> dict[str, Any]:
    """A cached rollout; a :class:`RunError` when it was made for another key."""
    try:
        with np.load(file, allow_pickle=False) as data:
            meta = json.loads(str(data["meta"]))
            found: dict[str, Any] = {k: data[k] for k in STEP_KEYS}
    except (OSError, KeyError, ValueError) as exc:
        raise RunError(f"{file}: not a readable cached rollout ({exc}); remove it") from None
    if meta.get("key") != key:
        raise RunError(
            f"{file}: a cached rollout of {meta.get('key')}, not of {key}: the folder was "
            "labelled under other settings (force=True replaces the run)"
        )
    found.update(meta["stats"])
    return found


# --- the run ----------------------------------------------------------------------------------


@dataclasses.dataclass
class DaggerRun:
    """A DAgger run's folder, its newest student (None before round 0 ends) and the records
    of its finished rounds (:data:`ROUND_KEYS`)."""

    out: Path
    student: Any
    rounds: list[dict[str, Any]]

    def summary(self) -> dict[str, float | int | None]:
        """Totals over the finished rounds: labels, the teacher's CPU seconds and labels
        per teacher CPU second, the rollouts' CPU seconds and labels per CPU second, the
        training's CPU seconds (a rate is None when no CPU time was measured)."""
        labels = sum(r["labels"] for r in self.rounds)
        teacher = sum(r["teacher_cpu_s"] for r in self.rounds)
        rollout_cpu = sum(r["rollout_cpu_s"] for r in self.rounds)
        return {
            "rounds": len(self.rounds),
            "labels": labels,
            "teacher_cpu_s": teacher,
            "labels_per_teacher_cpu_s": labels / teacher if teacher > 0 else None,
            "rollout_cpu_s": rollout_cpu,
            "labels_per_cpu_s": labels / rollout_cpu if rollout_cpu > 0 else None,
            "train_cpu_s": sum(r["train_cpu_s"] for r in self.rounds),
        }


def run_dagger(
    out: str | Path,
    make_env: Callable[[], Any],
    make_teacher: Callable[[], Teacher],
    settings: DaggerSettings,
    n_rounds: int,
    *,
    identity: Mapping[str, Any] | None = None,
    resume: bool = False,
    force: bool = False,
    workers: int = 1,
    executor: concurrent.futures.Executor | None = None,
    on_round: Callable[[dict[str, Any], Any], bool] | None = None,
    progress: Callable[[str], object] | None = None,
) -> DaggerRun:
    """Run (or continue) DAgger in the folder ``out`` up to ``n_rounds`` finished rounds.

    ``make_env`` / ``make_teacher``: factories of a gymnasium env (its action space the box
    [-1, 1]) and of a :class:`Teacher`, called in the process of each rollout.
    ``identity``: JSON describing env and teacher (recorded; a resumed run must match).
    ``resume``: continue the run in ``out`` (an empty or missing folder starts afresh);
    ``force``: replace it.  Rollouts run in ``executor`` if given, else in a local process
    pool of ``workers`` (> 1), else here.  ``on_round(record, student)``, after each round:
    False stops the run there (a later ``resume`` continues it).  ``progress``: a sink of
    one-line messages."""
    if n_rounds < 1:
        raise RunError(f"n_rounds must be ≥ 1, got {n_rounds}")
    folder = check_out_usable(out, resume=resume, force=force)
    env = make_env()
    spaces = _spaces(env)
    env.close()
    try:
        described = json.loads(json.dumps(dict(identity or {})))
    except (TypeError, ValueError) as exc:
        raise RunError(f"the run's identity must be JSON data: {exc}") from None
    record = {
        "format": FORMAT,
        "settings": settings.model_dump(mode="json"),
        "identity": described,
        "spaces": spaces,
    }
    with out_lock(folder, now()):
        check_no_links(folder)
        if force and _entries(folder):
            clear_listed(folder)  # what runs wrote; refused if it holds anything else
        manifest = Manifest(folder)
        with manifest.recording():
            rounds = _prepare(folder, record, resume=resume)
            student = _rounds(
                folder,
                settings,
                make_env,
                make_teacher,
                env,
                rounds,
                n_rounds,
                workers,
                executor,
                on_round,
                progress,
            )
        manifest.compact()
    return DaggerRun(folder, student, rounds)


def _rounds(
    folder: Path,
    settings: DaggerSettings,
    make_env: Callable[[], Any],
    make_teacher: Callable[[], Teacher],
    env: Any,
    rounds: list[dict[str, Any]],
    n_rounds: int,
    workers: int,
    executor: concurrent.futures.Executor | None,
    on_round: Callable[[dict[str, Any], Any], bool] | None,
    progress: Callable[[str], object] | None,
) -> Any:
    """Run rounds after ``rounds`` (appended to it) up to ``n_rounds`` in the locked run
    folder (:func:`run_dagger`); the newest student."""
    state = _Run(folder, settings, make_env, make_teacher, env.observation_space, env.action_space)
    student = state.student_after(len(rounds) - 1) if rounds else None
    own = worker_count(workers, settings.episodes_per_round) if executor is None else 1
    with task_pool(own) as pool:
        # one worker: the rollouts run here one after the other, each stored as it ends
        runner = executor or (None if isinstance(pool, Inline) else pool)
        for round_ in range(len(rounds), n_rounds):
            found, student = state.round(round_, student, runner, progress)
            rounds.append(found)
            _write_json(folder / ROUNDS_FILE, rounds)
            if progress is not None:
                progress(_describe_round(found))
            if on_round is not None and not on_round(found, student):
                break
    return student


def _spaces(env: Any) -> dict[str, Any]:
    """The env's spaces as JSON; a :class:`RunError` unless its actions are the box
    [-1, 1] and its observations a flat box."""
    from gymnasium import spaces

    act, obs = env.action_space, env.observation_space
    if not (isinstance(act, spaces.Box) and np.all(act.low == -1.0) and np.all(act.high == 1.0)):
        raise RunError(
            f"DAgger fits normalised actions: the env's action space must be the box [-1, 1], "
            f"got {act}"
        )
    if not (isinstance(obs, spaces.Box) and len(obs.shape) == 1):
        raise RunError(f"the student reads a flat box observation, got {obs}")
    return {"observation": list(obs.shape), "action": list(act.shape)}


def _entries(folder: Path) -> list[str]:
    """The names in the run folder, its lock file and manifest aside."""
    return sorted(p.name for p in folder.iterdir() if p.name not in (LOCK_FILE, MANIFEST_FILE))


def _prepare(folder: Path, record: dict[str, Any], resume: bool) -> list[dict[str, Any]]:
    """Make ``folder`` ready for the run ``record`` describes; the finished rounds'
    records (none for a fresh run; ``force`` cleared the folder before).  Refuses
    (:class:`RunError`) a folder holding anything but a DAgger run, a run of other
    settings, or a run without ``resume``."""
    entries = _entries(folder)
    settings_file = folder / SETTINGS_FILE
    if entries and not settings_file.is_file():
        shown = ", ".join(entries[:3]) + (", …" if len(entries) > 3 else "")
        raise RunError(f"{folder} is not empty ({shown}) and holds no DAgger run ({SETTINGS_FILE})")
    if not entries:
        _write_json(settings_file, {**record, "started": now(), "versions": versions()})
        return []
    held = _read_json(settings_file)
    if not resume:
        raise RunError(
            f"{folder} holds a DAgger run: pass resume=True to continue it, force=True to "
            "replace it, or another folder"
        )
    differing = sorted(k for k in record if held.get(k) != record[k])
    if differing:
        detail = "; ".join(f"{k}: {held.get(k)} there, {record[k]} now" for k in differing)
        raise RunError(f"{folder} holds a DAgger run of other settings ({detail})")
    rounds_file = folder / ROUNDS_FILE
    rounds = _read_json(rounds_file) if rounds_file.is_file() else []
    for found in rounds:
        r = found["round"]
        for file in (_round_file(folder, r), student_file(folder, r)):
            if not file.is_file():
                raise RunError(f"{rounds_file} lists round {r} but {file} is missing")
    return rounds


@dataclasses.dataclass
class _Run:
    """One run's rounds: rollouts (cached), the round file, the student's training."""

    folder: Path
    settings: DaggerSettings
    make_env: Callable[[], Any]
    make_teacher: Callable[[], Teacher]
    observation_space: Any
    action_space: Any

    def student_after(self, round_: int) -> Any:
        """The student saved after round ``round_``."""
        return load_student(
            student_file(self.folder, round_),
            self.observation_space,
            self.action_space,
            self.settings,
        )

    def round(
        self,
        round_: int,
        student: Any,
        executor: concurrent.futures.Executor | None,
        progress: Callable[[str], object] | None,
    ) -> tuple[dict[str, Any], Any]:
        """Roll out, label, aggregate and train round ``round_`` (``student``: the one of
        the round before, None in round 0); its record and the new student."""
        s = self.settings
        beta = s.beta(round_)
        weights = None if round_ == 0 else student_state(student)
        digest = None if weights is None else state_digest(weights)
        jobs = [
            RolloutJob(
                round=round_,
                episode=e,
                seed=s.episode_seed(round_, e),
                beta=beta,
                mix_seed=s.seed,
                make_env=self.make_env,
                make_teacher=self.make_teacher,
                policy_kwargs=s.policy_kwargs(),
                student=weights,
            )
            for e in range(s.episodes_per_round)
        ]
        found: dict[int, dict[str, Any]] = {}
        missing = []
        for job in jobs:
            file = _cache_file(self.folder, round_, job.episode)
            if file.is_file():
                found[job.episode] = _read_rollout(file, _cache_key(job, digest))
            else:
                missing.append(job)
        cached = len(found)
        if progress is not None and missing:
            progress(f"round {round_}: {len(missing)} rollouts to label (β = {beta:.3g})")
        for job, result in _map(executor, missing):
            _write_rollout(
                _cache_file(self.folder, round_, job.episode), result, _cache_key(job, digest)
            )
            found[job.episode] = result
        data = self._write_round(round_, [found[e] for e in range(s.episodes_per_round)])
        before = None if student is None else student_mse(student, data["obs"], data["label"])
        if student is None or not s.warm_start:
            student = build_student(self.observation_space, self.action_space, s)
        everything = load_dataset(self.folder, round_ + 1)
        fitted = fit_student(student, everything["obs"], everything["label"], s, round_)
        save_student(student, student_file(self.folder, round_))
        save_student(student, self.folder / MODEL_FILE)
        rollouts = [found[e] for e in range(s.episodes_per_round)]
        labels = int(sum(r["labels"] for r in rollouts))
        teacher_cpu = float(sum(r["teacher_cpu_s"] for r in rollouts))
        rollout_cpu = float(sum(r["cpu_s"] for r in rollouts))
        record = {
            "round": round_,
            "beta": beta,
            "episodes": s.episodes_per_round,
            "labels": labels,
            "labels_total": len(everything["obs"]),
            "teacher_fraction": float(np.mean(data["by_teacher"])),
            "mean_return": float(np.mean([r["return"] for r in rollouts])),
            "teacher_cpu_s": teacher_cpu,
            "rollout_cpu_s": rollout_cpu,
            "labels_per_teacher_cpu_s": labels / teacher_cpu if teacher_cpu > 0 else None,
            "labels_per_cpu_s": labels / rollout_cpu if rollout_cpu > 0 else None,
            "cached_rollouts": cached,
            "student_mse_before": before,
            **fitted,
        }
        return record, student

    def _write_round(self, round_: int, rollouts: list[dict[str, Any]]) -> dict[str, np.ndarray]:
        """Write ``data/round_<R>.npz`` from the round's rollouts (in episode order)."""
        s = self.settings
        data = {key: np.concatenate([r[key] for r in rollouts]) for key in STEP_KEYS}
        lengths = [len(r["obs"]) for r in rollouts]
        episodes = np.arange(s.episodes_per_round)
        data["round"] = np.full(sum(lengths), round_, dtype=np.int64)
        data["episode"] = np.repeat(round_ * s.episodes_per_round + episodes, lengths)
        data["seed"] = np.repeat([s.episode_seed(round_, e) for e in episodes], lengths)
        data["step"] = np.concatenate([np.arange(n) for n in lengths])
        _write_npz(_round_file(self.folder, round_), data)
        return data


def _map(executor: concurrent.futures.Executor | None, jobs: list[RolloutJob]) -> Any:
    """(job, result) of each rollout as it finishes: here one after the other, or in the
    executor (the first failure cancels the rest and is raised)."""
    if executor is None:
        for job in jobs:
            yield job, rollout(job)
        return
    futures = {executor.submit(rollout, job): job for job in jobs}
    try:
        for future in concurrent.futures.as_completed(futures):
            yield futures[future], future.result()
    finally:
        for future in futures:
            future.cancel()


def load_dataset(out: str | Path, rounds: int | None = None) -> dict[str, np.ndarray]:
    """The aggregated labelled states of rounds 0 … ``rounds`` − 1 (None: the finished
    rounds ``rounds.json`` lists), :data:`DATA_KEYS` concatenated in round order."""
    folder = Path(out)
    if rounds is None:
        file = folder / ROUNDS_FILE
        rounds = len(_read_json(file)) if file.is_file() else 0
    if rounds < 1:
        raise RunError(f"{folder}: no round of labelled states to read")
    parts = []
    for round_ in range(rounds):
        file = _round_file(folder, round_)
        if not file.is_file():
            raise RunError(f"{folder}: round {round_}'s labelled states ({file}) are missing")
        try:
            with np.load(file, allow_pickle=False) as data:
                parts.append({key: data[key] for key in DATA_KEYS})
        except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
            raise RunError(
                f"{file}: round {round_}'s labelled states are unreadable ({exc}): train the "
                "run afresh (--force)"
            ) from None
    return {key: np.concatenate([p[key] for p in parts]) for key in DATA_KEYS}


def _describe_round(record: dict[str, Any]) -> str:
    rate = record["labels_per_teacher_cpu_s"]
    return (
        f"round {record['round']}: β = {record['beta']:.3g}, {record['labels']} labels "
        f"({record['cached_rollouts']} rollouts from the cache), "
        f"{'—' if rate is None else f'{rate:.0f}'} labels per teacher CPU second, "
        f"student MSE {record['train_loss']:.3g} on {record['labels_total']} labels"
    )


# --- files ------------------------------------------------------------------------------------


def _round_file(out: Path, round_: int) -> Path:
    return out / DATA_DIR / f"round_{round_:03d}.npz"


def student_file(out: Path, round_: int) -> Path:
    """The student saved after DAgger round ``round_`` in the run folder ``out``."""
    return out / STUDENT_DIR / f"round_{round_:03d}.zip"


def _write_bytes(file: Path, payload: bytes) -> Path:
    """Write ``file`` whole, through no link (:func:`~shipgym_baselines.records.outfiles.
    write_bytes`: staged beside it, then renamed over it; listed in the run's manifest
    first), its folder made if missing."""
    if not file.parent.is_dir():
        make_dir(file.parent)
    write_bytes(file, payload)
    return file


def _write_npz(file: Path, arrays: Mapping[str, np.ndarray]) -> Path:
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    return _write_bytes(file, buffer.getvalue())


def _write_json(file: Path, value: Any) -> Path:
    return _write_bytes(file, (json.dumps(value, indent=1) + "\n").encode())


def _read_json(file: Path) -> Any:
    try:
        return json.loads(file.read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise RunError(f"{file}: not readable JSON ({exc})") from None
