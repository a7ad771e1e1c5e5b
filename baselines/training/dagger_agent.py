"""``shipgym train dagger`` / ``bc``: an agent config of ``algo: dagger`` trained by DAgger.

The student (an SB3 PPO policy, :mod:`shipgym_baselines.learned.dagger`) is distilled from
the causal oracle (:class:`~shipgym_baselines.learned.teachers.OracleTeacher`) on the
config's training envs: the randomised env of ``env.distribution`` (a fresh trial of any of
its ships and change families per rollout), or one fixed ``env.scenario``, with the config's
``context_features`` and ``history_steps``.  The teacher reads the true plant while it
labels; the student sees the observation alone, at training and at evaluation.

The config's blocks (``configs/agents/dagger.yaml``):

=================  ==========================================================================
block              for ``algo: dagger``
=================  ==========================================================================
``hyperparams``    the DAgger settings
(:class:`~shipgym_baselines.learned.dagger_config.DaggerHyperparams`): ``rounds``,
                   ``episodes_per_round``, ``beta_schedule``, ``beta_decay``, ``epochs``,
                   ``batch_size``, ``learning_rate``, ``warm_start``, and ``workers`` (label
                   processes; the data do not depend on it)
``policy_kwargs``  the student's ``net_arch`` and ``log_std_init`` (nothing else: the zip
                   must load as data)
``n_timesteps``    a budget of env steps (= teacher labels): no round starts once the
                   aggregate holds that many
``eval``           the validation trials every round's student is scored on (the
                   relative cost, :mod:`shipgym_baselines.training.selection`)
``plateau``        the plateau rule over the rounds' scores (optional)
=================  ==========================================================================

The env's ``n_envs``, ``vec_env``, ``normalize_reward`` do not apply: every rollout is one
single env in the rollout's own process.  Training seed k draws its rollouts' env seeds
from ``k ×`` :data:`~shipgym_baselines.learned.dagger_config.ENV_SEED_STRIDE` on (disjoint between
seeds while a run has fewer
rollouts than that).

Agent folder (``results/agents/<name>``; what every agent writes, plus ``dagger/``)::

    model.zip             the newest round's student     best_model.zip  the selected one
    meta.json             as every agent's (``algo``: ``ppo``, the zip's; ``trainer``:
                          ``dagger``; ``history_steps``), with the DAgger totals
    learning_curve.json   per round: env_steps, mean_return, std_return, selection,
                          teacher_labels, round
    eval/                 selection.json (per round), reference_costs.json, best.json
    dagger/               the DAgger run (rounds, label cache, students)

After each round the student is scored on the validation trials; the best round (lowest
cost ratio) is ``best_model.zip``; the plateau rule stops the run.  ``resume=True``
continues a killed run: finished rounds are neither relabelled nor rescored, cached
rollouts are read back.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from shipgym_baselines.errors import RunError
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET
from shipgym_baselines.learned.agent_folder import read_record
from shipgym_baselines.learned.dagger_config import check_config, hyperparams, settings
from shipgym_baselines.records.outfiles import write_bytes
from shipgym_baselines.training.meta import training_meta

#: the ``algo`` of an agent config trained by DAgger
DAGGER_ALGO = "dagger"
#: the DAgger run's folder inside the agent folder
RUN_DIR = "dagger"
SELECTION_FILE = "selection.json"


def make_env(
    source: dict[str, Any], action_mode: str, context_features: bool, history_steps: int
) -> Any:
    """One env of a rollout (top-level: process pools pickle its partial): the randomised
    env of ``source["distribution"]`` or the env of ``source["scenario"]``."""
    import gymnasium as gym

    import shipgym

    options = {
        "action_mode": action_mode,
        "context_features": context_features,
        "history_steps": history_steps,
    }
    # the scenario itself or each drawn scenario, truncated at its own time limit
    if source.get("scenario") is not None:
        return gym.make(
            "ShipPathFollow-v0",
            scenario=source["scenario"],
            randomize=False,
            max_episode_steps=-1,
            **options,
        )
    return gym.make(
        shipgym.RANDOMIZED_ENV_ID,
        distribution=source["distribution"],
        max_episode_steps=-1,
        **options,
    )


def env_factory(config: Any) -> functools.partial:
    """The picklable env factory of the config's training envs."""
    env = config.env
    source = {"distribution": env.distribution, "scenario": env.scenario}
    return functools.partial(
        make_env, source, env.action_mode, env.context_features, env.history_steps
    )


def identity(config: Any) -> dict[str, Any]:
    """What the DAgger run records of env and teacher (a resumed run must match)."""
    from shipgym.envs.core import ENV_REVISION
    from shipgym_baselines.classical.oracle import ORACLE_REVISION, OracleSettings
    from shipgym_baselines.privileged import ORACLE

    env = config.env
    return {
        "env": {
            "distribution": env.distribution,
            "scenario": env.scenario,
            "action_mode": env.action_mode,
            "context_features": env.context_features,
            "history_steps": env.history_steps,
            "env_revision": ENV_REVISION,
        },
        "teacher": {
            "name": ORACLE,
            "revision": ORACLE_REVISION,
            "settings": dataclasses.asdict(OracleSettings()),
        },
    }


def finished(out: Path, config: Any) -> dict[str, Any] | None:
    """The meta of a finished dagger run in ``out`` (all rounds, the env-step budget, or
    stopped by its plateau rule), else None."""
    meta_file = out / "meta.json"
    if not (meta_file.is_file() and (out / "model.zip").is_file()):
        return None
    meta = read_record(meta_file)
    done = meta.get("dagger", {}).get("rounds", 0) >= hyperparams(config).rounds
    done = done or int(meta.get("env_steps", 0)) >= config.n_timesteps
    return meta if done or meta.get("stopped_on_plateau_at") is not None else None


def started(out: str | Path) -> bool:
    """True when ``out`` holds a dagger run that started (its run folder's record)."""
    from shipgym_baselines.learned.dagger import SETTINGS_FILE

    return (Path(out) / RUN_DIR / SETTINGS_FILE).is_file()


@dataclasses.dataclass
class _Selection:
    """The rounds' validation scores (``eval/selection.json``), the best one's student
    copied to ``best_model.zip``, the learning curve and the stopping rules."""

    config: Any
    out: Path
    trials: list[tuple[str, int]]
    references: list[dict[str, Any]]
    rounds: list[int] = dataclasses.field(default_factory=list)
    steps: list[int] = dataclasses.field(default_factory=list)
    returns: list[list[float]] = dataclasses.field(default_factory=list)
    selection: list[float] = dataclasses.field(default_factory=list)
    wall: list[float] = dataclasses.field(default_factory=list)
    eval_cpu: list[float] = dataclasses.field(default_factory=list)
    stopped_at: int | None = None

    @property
    def file(self) -> Path:
        return self.out / "eval" / SELECTION_FILE

    def read(self, finished_rounds: int) -> None:
        """The scores of the first ``finished_rounds`` rounds kept from an earlier session."""
        if not self.file.is_file():
            return
        data = read_record(self.file)
        if data.get("trials") != [list(t) for t in self.trials]:
            return  # scored on other trials: rescored
        keep = [i for i, r in enumerate(data["rounds"]) if r < finished_rounds]
        for key in ("rounds", "steps", "returns", "selection", "wall", "eval_cpu"):
            source = "env_steps" if key == "steps" else key
            setattr(self, key, [data[source][i] for i in keep])

    def score(self, record: dict[str, Any], student: Any, wall_s: float) -> bool:
        """Score the student of the round ``record`` describes; False when the run stops
        here (the plateau rule, or the env-step budget reached)."""
        from shipgym_baselines.learned.agent_folder import write_best
        from shipgym_baselines.learned.dagger import student_file
        from shipgym_baselines.training.selection import evaluate_relative

        env = self.config.env
        cpu = time.process_time()
        found = evaluate_relative(
            student,
            self.trials,
            self.references,
            env.action_mode,
            env.context_features,
            env.history_steps,
        )
        round_ = int(record["round"])
        self.rounds.append(round_)
        self.steps.append(int(record["labels_total"]))
        self.returns.append([float(r) for r in found["returns"]])
        self.selection.append(float(found["selection"]))
        self.wall.append(float(wall_s))
        self.eval_cpu.append(time.process_time() - cpu)
        if found["selection"] <= min(self.selection):
            best = student_file(self.out / RUN_DIR, round_).read_bytes()
            write_bytes(self.out / "best_model.zip", best)
            write_best(self.out, float(found["selection"]), int(record["labels_total"]))
        self.write()
        return self.go_on()

    def go_on(self) -> bool:
        """False once the plateau rule says so or the env-step budget is reached."""
        rule = self.config.plateau
        if rule is not None and rule.plateaued(self.steps, self.selection, self.config.n_timesteps):
            self.stopped_at = self.steps[-1]
            return False
        return not self.steps or self.steps[-1] < self.config.n_timesteps

    def write(self) -> None:
        from shipgym_baselines.learned.agent_folder import write_json_file
        from shipgym_baselines.learned.curves import CURVE_FILE, write_curve

        record = {
            "rounds": self.rounds,
            "env_steps": self.steps,
            "returns": self.returns,
            "selection": self.selection,
            "wall": self.wall,
            "eval_cpu": self.eval_cpu,
            "trials": [list(t) for t in self.trials],
            "references": self.references,
        }
        write_json_file(self.file, record, None)
        write_curve(self.out, self.steps, self.returns, self.selection)
        curve_file = self.out / CURVE_FILE
        curve = json.loads(curve_file.read_text())
        # every visited state is labelled: the teacher's labels are the env steps so far
        curve["teacher_labels"] = list(self.steps)
        curve["round"] = list(self.rounds)
        write_json_file(curve_file, curve, 1)

    def best_round(self) -> int | None:
        return self.rounds[int(np.argmin(self.selection))] if self.selection else None


def train_dagger(
    config: Any,
    out: Path,
    resume: bool = False,
    progress: bool = True,
    force: bool = False,
    tuned_from: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Train (or resume) the ``algo: dagger`` agent ``config`` in ``out``; the meta written
    to ``out/meta.json`` (module doc).  Refusals as :func:`~shipgym_baselines.learned.
    train.train`'s: a folder that is not empty without ``resume`` / ``force``, a
    ``resume`` without a started run."""
    import torch

    from shipgym_baselines.learned.agent_folder import agent_run

    torch.set_num_threads(1)
    check_config(config)
    hyper, run_settings = hyperparams(config), settings(config)
    if resume and (done := finished(out, config)) is not None:
        return done
    last_seed = run_settings.episode_seed(hyper.rounds - 1, hyper.episodes_per_round - 1)
    if last_seed >= EVAL_SEED_OFFSET:
        raise RunError(
            f"training env seeds up to {last_seed} would reach the evaluation seeds "
            f"(≥ {EVAL_SEED_OFFSET}); use a smaller seed or fewer rounds × episodes"
        )
    if resume and not started(out):
        raise RunError(f"--resume: no DAgger run in {out / RUN_DIR}")
    with agent_run(out, config.name, resume, force):
        return _train_dagger(config, out, resume, progress, tuned_from)


def _train_dagger(
    config: Any, out: Path, resume: bool, progress: bool, tuned_from: dict[str, Any] | None
) -> dict[str, Any]:
    """:func:`train_dagger` in the agent folder ``out``, open (locked, its manifest
    recording)."""
    from shipgym_baselines.learned import dagger
    from shipgym_baselines.learned.agent_folder import check_tuned_from, write_json_file
    from shipgym_baselines.learned.teachers import oracle_teacher
    from shipgym_baselines.training.selection import reference_costs, validation_trials

    hyper, run_settings = hyperparams(config), settings(config)
    check_tuned_from(out, tuned_from, resuming=resume)
    trials = validation_trials(config.eval.distribution, config.eval.n_episodes)
    scores = _Selection(config, out, trials, reference_costs(trials, out / "eval"))
    run_dir = out / RUN_DIR
    make_env = env_factory(config)
    done_rounds: list[dict[str, Any]] = []
    if resume:
        rounds_file = run_dir / dagger.ROUNDS_FILE
        done_rounds = read_record(rounds_file) if rounds_file.is_file() else []
        scores.read(len(done_rounds))
    start = time.perf_counter()
    wall_offset = scores.wall[-1] if scores.wall else 0.0

    def wall() -> float:
        return wall_offset + time.perf_counter() - start

    say = (lambda text: sys.stderr.write(f"{config.name}: {text}\n")) if progress else None
    if done_rounds:  # rounds finished but not scored (killed while scoring)
        env = make_env()
        spaces = (env.observation_space, env.action_space)
        env.close()
        for record in done_rounds[len(scores.rounds) :]:
            student = dagger.load_student(
                dagger.student_file(run_dir, record["round"]), *spaces, run_settings
            )
            scores.score(record, student, wall())
    run = None
    if scores.go_on() and len(done_rounds) < hyper.rounds:
        run = dagger.run_dagger(
            run_dir,
            make_env,
            oracle_teacher,
            run_settings,
            hyper.rounds,
            identity=identity(config),
            resume=resume,
            workers=hyper.workers,
            on_round=lambda record, student: scores.score(record, student, wall()),
            progress=say,
        )
        done_rounds = run.rounds
    if not done_rounds:
        raise RunError(f"{out}: no DAgger round finished")
    newest = dagger.student_file(run_dir, int(done_rounds[-1]["round"]))
    write_bytes(out / "model.zip", newest.read_bytes())
    summary = dagger.DaggerRun(run_dir, None, done_rounds).summary()
    labels = int(done_rounds[-1]["labels_total"])
    meta = training_meta(
        config,
        # the zip's algorithm (the student is a PPO policy: it loads, and fine-tunes, as PPO)
        algo="ppo",
        env_steps=labels,
        wall_time_s=wall(),
        stopped_at=scores.stopped_at,
        tuned_from=tuned_from,
        trainer=DAGGER_ALGO,
        teacher_labels=labels,
        dagger={
            **summary,
            "best_round": scores.best_round(),
            "validation_cpu_s": float(sum(scores.eval_cpu)),
        },
    )
    write_json_file(out / "meta.json", meta)
    return meta
