"""``shipgym train``: train an SB3 agent from a config, with evaluation and checkpoints.

Output directory (default ``results/agents/<name>``)::

    model.zip            final model            best_model.zip   best on validation scenarios
    meta.json            algo, action mode, env steps, wall time, seed, versions
    checkpoints/         ckpt_<steps>_steps.zip (+ replay buffer, VecNormalize, state.json)
    eval/evaluations.npz validation returns over training       tb/  TensorBoard logs

``resume=True`` continues from the newest checkpoint (model, replay buffer, reward
normalisation and the wall-time counter) up to the config's ``n_timesteps``; a finished run
(its ``meta.json`` has the ``n_timesteps``) is left as it is and its meta returned.
Otherwise an output directory that is not empty is refused, unless ``force=True`` (the
files its manifest lists are removed first; anything else in it is refused).  The folder is
written as a run folder is (:func:`~shipgym_baselines.learned.agent_folder.agent_run`):
locked, listed in ``manifest.txt``, through no link.

A checkpoint is pickles (the SB3 zip, its replay buffer and reward statistics): a resumed
run reads one only if this user's shipgym wrote those very bytes
(:func:`~shipgym_baselines.learned.trust.written_here`) or ``--trust-pickle`` is given.  A
checkpoint that is refused or cannot be read is named in one line and the next older one
is tried (:func:`load_checkpoint`).

:func:`export_policy` copies what
:class:`~shipgym_baselines.learned.policy.LearnedPolicy` needs (the
best model, its meta, the observation statistics ``vecnormalize.json`` if the run
normalises observations (data, not a pickle: :mod:`shipgym_baselines.learned.normalizer`); no
checkpoints, replay buffers or logs) into a policy directory; :func:`ship_policy` into the
shipped layout
``baselines/learned/policies/<name>/seed_<k>/``.  So ``shipgym train all --seeds 0 1 2
--ship --resume`` on finished runs only exports them.

An ``algo: dagger`` config (a student distilled from the oracle) is trained by
:func:`shipgym_baselines.training.dagger_agent.train_dagger`: the same folder contract,
rounds of DAgger instead of checkpoints.
"""

from __future__ import annotations

import io
import os
import pickle
import re
import sys
import time
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.limits import worker_count
from shipgym_baselines.errors import RunError
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET
from shipgym_baselines.executor import map_jobs
from shipgym_baselines.learned.agent_folder import (
    BEST_FILE,
    agent_run,
    check_tuned_from,
    read_record,
    write_best,
    write_json_file,
)
from shipgym_baselines.learned.trust import (
    TRUST_PICKLE_OPTION,
    pickle_trusted,
    remember_written,
    written_here,
)
from shipgym_baselines.records.manifest import Manifest
from shipgym_baselines.records.outfiles import make_dir, refuse_special, write_bytes
from shipgym_baselines.training.agents import (
    AgentConfig,
    algo_class,
    build_hyperparams,
    load_agent_config,
    make_eval_env,
    make_training_env,
)
from shipgym_baselines.training.meta import training_meta

_CKPT = re.compile(r"ckpt_(\d+)_steps\.zip$")


def _callbacks(
    config: AgentConfig,
    out: Path,
    n_envs: int,
    progress: bool,
    wall_offset: float,
    manifest: Manifest,
    resumed_at: int | None = None,
):
    """Progress, checkpoints and the periodic validation; ``resumed_at``: the env steps of
    the checkpoint a resumed run starts from (None: a fresh run); what SB3 writes itself
    (checkpoints, TensorBoard logs) is listed in ``manifest`` before it is written."""
    from stable_baselines3.common.callbacks import BaseCallback, CallbackList, CheckpointCallback

    class _Progress(BaseCallback):
        """tqdm bar on stderr, and the wall-time counter saved beside each checkpoint."""

        def __init__(self) -> None:
            super().__init__()
            self.bar = None
            self.start = time.perf_counter()

        def _on_training_start(self) -> None:
            from tqdm import tqdm

            self.bar = tqdm(
                total=config.n_timesteps,
                initial=self.model.num_timesteps,
                desc=f"train {config.name}",
                file=sys.stderr,
                disable=not progress,
                unit="step",
            )

        def _on_step(self) -> bool:
            self.bar.update(self.model.num_timesteps - self.bar.n)
            return True

        def _on_training_end(self) -> None:
            self.bar.close()

        def wall(self) -> float:
            return wall_offset + time.perf_counter() - self.start

    progress_cb = _Progress()

    class _Checkpoint(CheckpointCallback):
        """SB3's checkpoint files (:func:`checkpoint_names`), each written atomically
        through no link (:func:`~shipgym_baselines.records.outfiles.write_bytes`), listed
        before it is written, its SHA-256 recorded after (:func:`remember_written`)."""

        def _init_callback(self) -> None:
            make_dir(out / "checkpoints")  # a link in its place is refused

        def _on_step(self) -> bool:
            if self.n_calls % self.save_freq:
                return True
            steps = self.num_timesteps
            manifest.claim(*[f"checkpoints/{name}" for name in checkpoint_names(steps)])
            state = {"num_timesteps": self.model.num_timesteps, "wall_time_s": progress_cb.wall()}
            write_json_file(out / "checkpoints" / "state.json", state, None)
            model, statistics, buffer = (out / "checkpoints" / n for n in checkpoint_names(steps))
            save_model(self.model, model)
            replay = getattr(self.model, "replay_buffer", None)
            if self.save_replay_buffer and replay is not None:  # SB3's pickles, as it saves them
                write_bytes(buffer, pickle.dumps(replay, protocol=pickle.HIGHEST_PROTOCOL))
            normalizer = self.model.get_vec_normalize_env()
            if self.save_vecnormalize and normalizer is not None:
                write_bytes(statistics, pickle.dumps(normalizer))
            for file in checkpoint_files(out, steps):  # the bytes this run wrote
                remember_written(file)
            return True

    off_policy = config.algo in ("sac", "td3")
    checkpoint = _Checkpoint(
        save_freq=max(config.checkpoint_freq // n_envs, 1),
        save_path=str(out / "checkpoints"),
        name_prefix="ckpt",
        save_replay_buffer=off_policy,
        save_vecnormalize=True,
    )
    if config.eval.select_on == "relative_cost":
        evaluation = _relative_cost_callback(config, out, n_envs, resumed_at)
    else:
        evaluation = _return_callback(config, out, n_envs, resumed_at)
    callbacks = CallbackList([progress_cb, checkpoint, evaluation])
    return callbacks, progress_cb, evaluation.curves


class _Curves:
    """Bookkeeping of the periodic validation: the learning curve it writes after every
    evaluation (``learning_curve.json``) and the plateau rule's verdict."""

    def __init__(self, config: AgentConfig, out: Path) -> None:
        self.config, self.out = config, out
        self.stopped_at: int | None = None

    def after_evaluation(
        self, steps: list[int], returns: list[list[float]], selection: list[float] | None
    ) -> bool:
        """Write the curve; False (stop training) when the plateau rule says so."""
        from shipgym_baselines.learned.curves import write_curve

        write_curve(self.out, steps, returns, selection)
        rule = self.config.plateau
        if rule is None:
            return True
        values = (
            selection if rule.metric == "selection" else [float(sum(r) / len(r)) for r in returns]
        )
        if rule.plateaued(steps, values, self.config.n_timesteps):
            self.stopped_at = int(steps[-1])
            return False
        return True


def _kept_history(steps: list[int], resumed_at: int) -> int:
    """How many of a run's evaluations to keep when it resumes from the checkpoint at
    ``resumed_at`` env steps: the strictly increasing first ones up to it.  Evaluations
    after the checkpoint belong to the interrupted stretch of training, which the resumed
    run trains again (its curve then stays strictly increasing); the best model file keeps
    the best value ever evaluated (:data:`BEST_FILE`)."""
    kept = 0
    for step in steps:
        if step > resumed_at or (kept and step <= steps[kept - 1]):
            break
        kept += 1
    return kept


def _read_best(out: Path, history_best: float) -> float:
    """The value of the saved best model: from :data:`BEST_FILE`, else (a run from before
    the file) the best of the history on disk."""
    file = out / "eval" / BEST_FILE
    return float(read_record(file, "value")) if file.is_file() else history_best


def _return_callback(config: AgentConfig, out: Path, n_envs: int, resumed_at: int | None):
    """SB3's EvalCallback on the validation env (best model by mean return), writing the
    learning curve and applying the plateau rule after each evaluation."""
    from stable_baselines3.common.callbacks import BaseCallback, EvalCallback
    from stable_baselines3.common.vec_env import VecMonitor, VecNormalize

    curves = _Curves(config, out)

    class _Evaluation(EvalCallback):
        """SB3's EvalCallback, its files written through no link: its history
        (``np.savez``) into memory, written by :class:`_AfterEval`; the best model by
        :class:`_NewBest`."""

        def _init_callback(self) -> None:
            super()._init_callback()  # no folder made: no path given
            make_dir(out / "eval")  # a link in its place is refused
            self.log_path = io.BytesIO()

    class _AfterEval(BaseCallback):
        def _on_step(self) -> bool:
            parent = self.parent
            write_bytes(out / "eval" / "evaluations.npz", parent.log_path.getvalue())
            parent.log_path = io.BytesIO()  # the next evaluation's history
            return curves.after_evaluation(
                parent.evaluations_timesteps, parent.evaluations_results, None
            )

    class _NewBest(BaseCallback):  # a new best: save it, and record its value
        def _on_step(self) -> bool:
            save_model(self.model, out / "best_model.zip")
            write_best(out, float(self.parent.best_mean_reward), int(self.num_timesteps))
            return True

    eval_env = make_eval_env(config.eval, config.env, seed=config.seed)
    eval_env = VecNormalize(VecMonitor(eval_env), norm_obs=False, norm_reward=False, training=False)
    evaluation = _Evaluation(
        eval_env,
        callback_after_eval=_AfterEval(),
        callback_on_new_best=_NewBest(),
        eval_freq=max(config.eval.freq // n_envs, 1),
        n_eval_episodes=config.eval.n_episodes,
        deterministic=True,
        verbose=0,
    )
    evaluation.curves = curves
    previous = out / "eval" / "evaluations.npz"
    if resumed_at is not None and previous.is_file():  # keep the history and the best
        import numpy as np

        try:
            with np.load(previous, allow_pickle=False) as data:
                steps, results = data["timesteps"].tolist(), data["results"].tolist()
                lengths = data["ep_lengths"].tolist()
                history_best = float(np.max(np.mean(data["results"], axis=1)))
        except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
            raise RunError(
                f"{previous}: unreadable ({exc}): a damaged record of the run (--force trains "
                "it afresh)"
            ) from None
        keep = _kept_history(steps, resumed_at)
        evaluation.evaluations_timesteps = steps[:keep]
        evaluation.evaluations_results = results[:keep]
        evaluation.evaluations_length = lengths[:keep]
        evaluation.best_mean_reward = _read_best(out, history_best)
    return evaluation


def _relative_cost_callback(config: AgentConfig, out: Path, n_envs: int, resumed_at: int | None):
    """Every ``eval.freq`` env steps: the agent on the fixed validation trials, scored by
    the geometric-mean cost ratio to the reference (:mod:`shipgym_baselines.learned.
    selection`); the best (lowest) model saved as ``best_model.zip``."""
    import numpy as np
    from stable_baselines3.common.callbacks import BaseCallback

    from shipgym_baselines.training.selection import (
        evaluate_relative,
        reference_costs,
        validation_trials,
    )

    trials = validation_trials(config.eval.distribution, config.eval.n_episodes)
    references = reference_costs(trials, out / "eval")  # once per run
    curves = _Curves(config, out)
    history = out / "eval" / "selection.json"

    class _RelativeCostEval(BaseCallback):
        def __init__(self) -> None:
            super().__init__()
            self.freq = max(config.eval.freq // n_envs, 1)
            self.steps: list[int] = []
            self.returns: list[list[float]] = []
            self.selection: list[float] = []
            self.best = float("inf")
            if resumed_at is not None and history.is_file():
                data = read_record(history)
                keep = _kept_history(read_record(history, "env_steps"), resumed_at)
                self.steps, self.returns = data["env_steps"][:keep], data["returns"][:keep]
                self.selection = data["selection"][:keep]
                self.best = _read_best(out, min(data["selection"], default=float("inf")))
            self.curves = curves

        def _on_step(self) -> bool:
            if self.n_calls % self.freq:
                return True
            found = evaluate_relative(
                self.model,
                trials,
                references,
                config.env.action_mode,
                config.env.context_features,
                config.env.history_steps,
            )
            self.steps.append(int(self.num_timesteps))
            self.returns.append(found["returns"])
            self.selection.append(found["selection"])
            record = {
                "env_steps": self.steps,
                "returns": self.returns,
                "selection": self.selection,
                "trials": [list(t) for t in trials],
                "references": references,
            }
            write_json_file(history, record, None)
            data = io.BytesIO()
            np.savez(
                data,
                timesteps=np.array(self.steps),
                results=np.array(self.returns),
                ep_lengths=np.zeros_like(np.array(self.returns)),
            )
            write_bytes(out / "eval" / "evaluations.npz", data.getvalue())
            if found["selection"] < self.best:
                self.best = found["selection"]
                save_model(self.model, out / "best_model.zip")
                write_best(out, self.best, int(self.num_timesteps))
            return curves.after_evaluation(self.steps, self.returns, self.selection)

    return _RelativeCostEval()


#: the folder of a run's TensorBoard logs, one ``<name>_<k>`` folder per fresh start
TB_FOLDER = "tb"


def training_logger(out: Path, name: str, tensorboard: bool, manifest: Manifest, resumed: bool):
    """SB3's logger of a training run: TensorBoard's events in ``tb/<name>_<k>/`` (``k``:
    the next number on a fresh run, the newest on a resumed one, as SB3 numbers them), or
    no output at all (``tensorboard`` False, or TensorBoard not installed).  The folders
    are made through no link (:func:`~shipgym_baselines.records.outfiles.make_dir`) and the
    events file gets a random suffix, so no link can be waiting in its place; it is listed
    in the manifest as soon as it exists."""
    from stable_baselines3.common.logger import Logger, TensorBoardOutputFormat
    from stable_baselines3.common.utils import get_latest_run_id

    if tensorboard:
        try:
            from torch.utils.tensorboard import SummaryWriter
        except ImportError:
            sys.stderr.write("tensorboard not installed: no TensorBoard logs\n")
            tensorboard = False
    if not tensorboard:
        return Logger(folder=None, output_formats=[])
    latest = get_latest_run_id(str(out / TB_FOLDER), name)
    folder = out / TB_FOLDER / f"{name}_{max(latest, 1) if resumed else latest + 1}"
    make_dir(folder.parent)
    make_dir(folder)
    suffix = f".{os.urandom(8).hex()}"

    class _TensorBoard(TensorBoardOutputFormat):
        def __init__(self) -> None:
            self.writer = SummaryWriter(log_dir=str(folder), filename_suffix=suffix)
            self._is_closed = False

    output = _TensorBoard()
    manifest.record([p.absolute() for p in folder.iterdir() if p.name.endswith(suffix)])
    return Logger(folder=str(folder), output_formats=[output])


def checkpoints(out: Path) -> list[tuple[Path, int]]:
    """The checkpoints in ``out`` (zip, env steps), newest first."""
    found = [
        (p, int(m.group(1)))
        for p in (out / "checkpoints").glob("ckpt_*_steps.zip")
        if (m := _CKPT.search(p.name))
    ]
    return sorted(found, key=lambda item: item[1], reverse=True)


def latest_checkpoint(out: Path) -> tuple[Path, int] | None:
    found = checkpoints(out)
    return found[0] if found else None


def checkpoint_names(steps: int) -> tuple[str, str, str]:
    """The files of the checkpoint at ``steps`` env steps in ``checkpoints/``: the model
    zip, its reward statistics and its replay buffer (SB3's ``CheckpointCallback`` names)."""
    return (
        f"ckpt_{steps}_steps.zip",
        f"ckpt_vecnormalize_{steps}_steps.pkl",
        f"ckpt_replay_buffer_{steps}_steps.pkl",
    )


def checkpoint_files(out: Path, steps: int) -> list[Path]:
    """Those of the checkpoint's files (:func:`checkpoint_names`) that exist in ``out``."""
    folder = out / "checkpoints"
    return [folder / name for name in checkpoint_names(steps) if (folder / name).is_file()]


def save_model(model: Any, file: Path) -> None:
    """``model`` saved as the zip ``file``, atomically and through no link."""
    data = io.BytesIO()
    model.save(data)
    write_bytes(file, data.getvalue())


def load_checkpoint(
    out: Path, config: AgentConfig, cls: Any, venv: Any
) -> tuple[Any, Any, int] | None:
    """(model, its env, env steps) of the newest checkpoint in ``out`` that may be read
    and can be: its files written by this user's shipgym (or ``--trust-pickle``), then
    loaded without error.  Each checkpoint passed over is named in one line on stderr.
    None when there is none."""
    from stable_baselines3.common.vec_env import VecNormalize

    for ckpt, steps in checkpoints(out):
        files = checkpoint_files(out, steps)
        foreign = [f for f in files if not (pickle_trusted() or written_here(f))]
        if foreign:
            sys.stderr.write(
                f"train --resume: {foreign[0]} is not what a shipgym run of yours wrote (no "
                "record of its SHA-256: changed since, or made elsewhere), and reading it "
                f"means unpickling: skipped (pass {TRUST_PICKLE_OPTION} if you trust whoever "
                "made it)\n"
            )
            continue
        _, statistics, buffer = (out / "checkpoints" / name for name in checkpoint_names(steps))
        try:
            env = venv
            if config.env.normalize_reward and not config.env.normalize_per_ship:
                env = VecNormalize.load(str(statistics), venv)
            model = cls.load(str(ckpt), env=env, device="cpu")
            if buffer.is_file():
                model.load_replay_buffer(str(buffer))
        except Exception as exc:  # a damaged checkpoint: any error of its readers
            sys.stderr.write(
                f"train --resume: the checkpoint {ckpt} is unreadable ({type(exc).__name__}: "
                f"{exc}): skipped\n"
            )
            continue
        return model, env, steps
    return None


def train(
    config: AgentConfig | str,
    out_dir: str | Path | None = None,
    seed: int | None = None,
    n_timesteps: int | None = None,
    resume: bool = False,
    progress: bool = True,
    tensorboard: bool = True,
    force: bool = False,
    tuned_from: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Train (or resume) an agent; returns the meta written to ``out_dir/meta.json``.

    Without ``resume``, an ``out_dir`` that is not empty is refused (:class:`RunError`)
    unless ``force`` (its earlier outputs are removed first).  ``tuned_from``: the study
    settings applied to ``config`` (:func:`shipgym_baselines.tuning.tuned.tuned_agent`),
    recorded in the meta; a resumed run must be resumed with the settings it started with."""
    import torch

    torch.set_num_threads(1)  # small networks: threads only contend with the env workers
    if not isinstance(config, AgentConfig):
        config = load_agent_config(config)
    updates: dict[str, Any] = {}
    if seed is not None:
        updates["seed"] = seed
    if n_timesteps is not None:
        updates["n_timesteps"] = n_timesteps
    if updates:
        config = config.model_copy(update=updates)
    out = Path(out_dir or f"results/agents/{config.name}")
    if config.algo == "dagger":  # a student distilled from the oracle
        from shipgym_baselines.training.dagger_agent import train_dagger

        return train_dagger(config, out, resume, progress, force, tuned_from)
    if resume and (finished := finished_run(out, config.n_timesteps)) is not None:
        if int(finished.get("env_steps", 0)) < config.n_timesteps:
            sys.stderr.write(
                f"{out}: stopped by its plateau rule at {finished['stopped_on_plateau_at']} env "
                "steps, so finished: nothing trained (--force trains it afresh)\n"
            )
        return finished
    with agent_run(out, config.name, resume, force) as manifest:
        return _train(config, out, resume, progress, tensorboard, tuned_from, manifest)


def _train(
    config: AgentConfig,
    out: Path,
    resume: bool,
    progress: bool,
    tensorboard: bool,
    tuned_from: dict[str, Any] | None,
    manifest: Manifest,
) -> dict[str, Any]:
    """:func:`train` in the agent folder ``out``, open (locked, ``manifest`` recording)."""
    from stable_baselines3.common.vec_env import VecNormalize

    cls = algo_class(config.algo)
    previous = latest_checkpoint(out) if resume else None
    if resume and previous is None:
        raise RunError(f"--resume: no checkpoint in {out / 'checkpoints'}")
    check_tuned_from(out, tuned_from, resuming=previous is not None)
    if previous is not None and previous[1] >= config.n_timesteps:
        raise RunError(
            f"--resume: the newest checkpoint has {previous[1]} steps, n_timesteps is "
            f"{config.n_timesteps}: nothing to train (raise --timesteps)"
        )
    # a resumed run continues with fresh scenario draws: the env seeds move on by n_envs per
    # checkpoint reached (still below the evaluation seeds)
    env_seed = config.seed
    if previous is not None:
        env_seed += config.env.n_envs * (previous[1] // config.checkpoint_freq)
    if env_seed + config.env.n_envs > EVAL_SEED_OFFSET:
        raise RunError(
            f"training env seeds {env_seed}… would reach the evaluation seeds "
            f"(≥ {EVAL_SEED_OFFSET}); use a smaller seed"
        )
    venv = make_training_env(config.env, env_seed)
    gamma: Any = float(config.hyperparams.get("gamma", 0.99))
    groups = None
    if config.env.gamma_seconds is not None or config.env.normalize_per_ship:
        from shipgym_baselines.learned.per_ship import env_gammas, ship_groups

        ship_envs = venv.venv.envs  # VecMonitor(SB3ShipsVecEnv): one env per ship
        groups = ship_groups(ship_envs)
        if config.env.gamma_seconds is not None:
            gamma = env_gammas(ship_envs, config.env.gamma_seconds)
    wall_offset = 0.0
    if previous is not None:
        if config.env.normalize_per_ship:  # its statistics are not checkpointed: re-estimated
            from shipgym_baselines.learned.per_ship import VecNormalizePerShip

            venv = VecNormalizePerShip(venv, groups, gamma)
        loaded = load_checkpoint(out, config, cls, venv)
        if loaded is None:
            venv.close()
            raise RunError(
                f"--resume: no checkpoint in {out / 'checkpoints'} can be read (each is named "
                "above): train it afresh with --force"
            )
        model, venv, steps = loaded
        if steps != previous[1]:
            sys.stderr.write(f"train --resume: resuming from {steps} env steps\n")
            previous = (previous[0], steps)
        state_file = out / "checkpoints" / "state.json"
        if state_file.is_file():
            wall_offset = float(read_record(state_file, "wall_time_s"))
    else:
        if config.env.normalize_per_ship:
            from shipgym_baselines.learned.per_ship import VecNormalizePerShip

            venv = VecNormalizePerShip(venv, groups, gamma)
        elif config.env.normalize_reward:
            # an array γ (gamma_seconds) broadcasts over the envs in VecNormalize's returns
            venv = VecNormalize(venv, norm_obs=False, norm_reward=True, gamma=gamma)
        model = cls(
            config.policy,
            venv,
            seed=config.seed,
            device="cpu",
            verbose=0,
            **build_hyperparams(config, venv.action_space.shape[0]),
        )
    # the run's own logger (SB3 would make an empty SB3-<time> folder in /tmp without
    # TensorBoard, and write where a resumed zip says with it)
    logger = training_logger(out, config.name, tensorboard, manifest, resumed=previous is not None)
    model.set_logger(logger)
    if config.env.gamma_seconds is not None:
        # the rollout buffer's GAE broadcasts an (n_envs,) γ: each env its ship's
        # exp(−Ts/τ); SB3's time-limit bootstrap keeps the scalar hyperparams γ
        model.rollout_buffer.gamma = np.asarray(gamma)
    callbacks, progress_cb, curves = _callbacks(
        config,
        out,
        config.env.n_envs,
        progress,
        wall_offset,
        manifest,
        resumed_at=previous[1] if previous is not None else None,
    )
    remaining = config.n_timesteps - model.num_timesteps
    if remaining > 0:
        model.learn(
            total_timesteps=remaining,
            callback=callbacks,
            reset_num_timesteps=previous is None,
            tb_log_name=config.name,
        )
    logger.close()  # the TensorBoard events flushed
    save_model(model, out / "model.zip")
    meta = training_meta(
        config,
        algo=config.algo,
        env_steps=model.num_timesteps,
        wall_time_s=progress_cb.wall(),
        stopped_at=curves.stopped_at,
        tuned_from=tuned_from,
    )
    write_json_file(out / "meta.json", meta)
    save_obs_statistics(venv, out)
    venv.close()
    return meta


def save_obs_statistics(venv: Any, out: Path) -> Path | None:
    """Write the observation statistics of a training env that normalises observations as
    ``out/vecnormalize.json`` (data: :class:`~shipgym_baselines.learned.normalizer.ObsNormalizer`);
    None (and no file) for one that does not."""
    from stable_baselines3.common.vec_env import VecNormalize

    from shipgym_baselines.learned.normalizer import NORMALIZER_FILE, ObsNormalizer

    (out / NORMALIZER_FILE).unlink(missing_ok=True)  # not a stale one
    if not (isinstance(venv, VecNormalize) and venv.norm_obs):
        return None
    return ObsNormalizer.of(venv).save(out / NORMALIZER_FILE)


def finished_run(out: str | Path, n_timesteps: int) -> dict[str, Any] | None:
    """The meta of the run in ``out`` if it is finished (its ``model.zip`` saved and its
    ``meta.json`` counting at least ``n_timesteps`` env steps, or saying the plateau rule
    stopped it), else None."""
    meta_file = Path(out) / "meta.json"
    if not (meta_file.is_file() and (Path(out) / "model.zip").is_file()):
        return None
    meta = read_record(meta_file)
    done = int(meta.get("env_steps", 0)) >= n_timesteps
    return meta if done or meta.get("stopped_on_plateau_at") is not None else None


#: the files of a policy folder (what LearnedPolicy reads, and the run's learning curve),
#: written by export_policy (and the pickled statistics an earlier version exported,
#: removed on export)
POLICY_FILES = (
    "model.zip",
    "meta.json",
    "vecnormalize.json",
    "learning_curve.json",
    "vecnormalize.pkl",
)


def export_policy(out_dir: str | Path, dest: str | Path) -> Path:
    """Copy the best model (else the final one) as ``model.zip``, ``meta.json`` and the
    run's ``vecnormalize.json`` (if any) into ``dest`` (a policy dir); nothing else (no
    pickle: a stale ``vecnormalize.pkl`` there is removed).  Each file is written through
    no link: a link in place of one is refused in one line, before any is written."""
    src = Path(out_dir)
    model = src / "best_model.zip"
    if not model.is_file():
        model = src / "model.zip"
    if not model.is_file() or not (src / "meta.json").is_file():
        raise RunError(f"{src}: no trained model (model.zip / meta.json) to export")
    target = Path(dest)
    target.mkdir(parents=True, exist_ok=True)
    for name in POLICY_FILES:  # written through no link: refused before any is written
        refuse_special(target / name)
    write_bytes(target / "model.zip", model.read_bytes())
    write_bytes(target / "meta.json", (src / "meta.json").read_bytes())
    for name in POLICY_FILES[2:]:
        (target / name).unlink(missing_ok=True)  # not a stale one
    for name in POLICY_FILES[2:4]:  # the observation statistics and the learning curve
        if (src / name).is_file():
            write_bytes(target / name, (src / name).read_bytes())
    return target


def ship_policy(out_dir: str | Path, root: str | Path | None = None) -> Path:
    """Export the run in ``out_dir`` into the shipped layout ``root/<name>/seed_<k>/``
    (name and seed from its ``meta.json``; ``root``: default ``baselines/learned/policies``).
    A single-model policy folder of that name (the layout before training seeds) has its
    files removed: the agent is its ``seed_<k>`` folders from now on."""
    from shipgym_baselines.learned.policy import POLICY_DIR

    meta_file = Path(out_dir) / "meta.json"
    if not meta_file.is_file():
        raise RunError(f"{out_dir}: no trained model (model.zip / meta.json) to export")
    meta = read_record(meta_file)
    if not isinstance(meta.get("name"), str) or not isinstance(meta.get("seed"), int):
        raise RunError(f"{meta_file}: a shipped policy needs its 'name' and its 'seed'")
    agent = Path(root if root is not None else POLICY_DIR) / meta["name"]
    target = export_policy(out_dir, agent / f"seed_{meta['seed']}")
    for name in POLICY_FILES:
        (agent / name).unlink(missing_ok=True)
    return target


def run_train_job(job: dict[str, Any]) -> dict[str, Any]:
    """One training run of a sweep (top-level: process pools and Ray pickle it).

    ``job``: ``config`` (name, path or AgentConfig), ``out_dir``, optional ``seed``,
    ``n_timesteps``, ``resume``, ``force``, ``progress``, ``ship`` (export to the shipped
    policies, :func:`ship_policy`), ``tuned_from`` (recorded in the meta),
    ``fresh_if_unstarted`` (with ``resume``: a run without a checkpoint, killed before its
    first one or never started, is trained afresh instead of refused).
    """
    config = job["config"]
    if not isinstance(config, AgentConfig):
        config = load_agent_config(config)
    resume, force = job.get("resume", False), job.get("force", False)
    if resume and job.get("fresh_if_unstarted"):
        # a sweep re-run after a kill: a run that reached no checkpoint (and saved no
        # model) starts afresh; its partial logs are all it had
        from shipgym_baselines.training.dagger_agent import started

        out = Path(job["out_dir"])
        unstarted = latest_checkpoint(out) is None and not started(out)
        if unstarted and not (out / "model.zip").is_file():
            resume, force = False, True
    meta = train(
        config,
        out_dir=job["out_dir"],
        seed=job.get("seed"),
        n_timesteps=job.get("n_timesteps"),
        resume=resume,
        progress=job.get("progress", False),
        tensorboard=job.get("tensorboard", True),
        force=force,
        tuned_from=job.get("tuned_from"),
    )
    if job.get("ship"):
        meta["shipped_to"] = str(ship_policy(job["out_dir"]))
    meta["out_dir"] = str(job["out_dir"])
    return meta


def train_sweep(
    jobs: list[dict[str, Any]], backend: str = "local", workers: int = 1
) -> list[dict[str, Any]]:
    """Run training jobs (agents × seeds) sequentially, in a local process pool
    (``workers`` > 1) or on Ray (``backend="ray"``, ``RAY_ADDRESS`` or a local instance);
    the metas come back in job order.  Each run is seeded, so where it runs does not change
    its result (tested).  ``workers`` below 1 is refused, more than the jobs clamped."""
    workers = worker_count(workers, len(jobs))
    # a failed run lets the runs already training finish, their outputs kept; the workers
    # have no initializer, so Ctrl-C reaches them too
    return list(map_jobs(run_train_job, jobs, backend, workers, ordered=True, finish_running=True))
