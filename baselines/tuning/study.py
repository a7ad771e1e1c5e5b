"""Run a study: Optuna (TPE sampler seeded, median pruner), SQLite storage, resumable.

A study is one (tuning config, ship) pair — ``<name>:<ship>`` for a per-ship config, else
``<name>`` — in the folder ``<out>/<ship>`` (or ``<out>``), its storage
``sqlite:///<folder>/study.db`` unless ``--storage`` names another.  An existing study is
continued only with ``resume=True`` (else refused: nothing is overwritten silently), and a
resumed study runs until it holds ``n_trials`` finished trials (complete, pruned or failed;
a trial left running by a killed process is marked failed).  A study keeps what determines
its scores (:func:`study_record`: the resolved config but its name, words, budget and final
training; its ship and validation trials; the env and oracle revisions) and its SHA-256 in
its user attributes; resuming it under a record that differs is refused, naming the keys
that changed, and so is resuming a study that has no record.  The sampler's seed is the
config's ``sampler_seed`` plus the number of trials already finished, so a resumed study
draws new points and the same history gives the same suggestions.

Before its first trial a study scores the *default* settings (the config's ``default``:
the registry's construction before tuning — for a classical controller its paper-literal
design, ``preset: paper``; for a learned agent its agent config unchanged) and keeps the
ratios in the study, so the report can compare best and default on the same trials.  When the study
ends, its ``tuning_report.json`` is (re)written and the chosen settings — the best trial's
as it was scored (its ``settings`` user attribute: the fixed ones and its parameters), or none
(the default kept) when the best is not below the default — go into
``<out>/chosen/<controller>.yaml`` (:mod:`~shipgym_baselines.tuning.chosen`): the packaged
``configs/tuning/chosen`` only with ``promote`` (or another folder with ``chosen_dir``).
Settings already in the target section are replaced only when the winner is not worse on
the same validation trials, or with ``force`` (:mod:`~shipgym_baselines.tuning.promotion`).

``backend="ray"`` runs the trials as Ray tasks, ``workers`` at a time, each loading the
study from the shared storage.

A study's folder is locked while the study runs, as a run folder is
(:func:`~shipgym_baselines.records.locking.out_lock`), and so is a SQLite ``--storage``
outside it (:func:`storage_lock`): a second process on the same study is refused in one
line naming the holder, so two processes never draw the same trials.
The folder holds no link (refused in one line), and the report is written through none,
listed in the folder's manifest (:mod:`~shipgym_baselines.records.manifest`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import hashlib
import json
import os
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from shipgym_baselines.errors import RunError
from shipgym_baselines.executor import RaySetup, check_backend, map_jobs
from shipgym_baselines.records import chosen as chosen_records
from shipgym_baselines.records.locking import file_lock, out_lock
from shipgym_baselines.records.manifest import Manifest
from shipgym_baselines.records.outfiles import check_no_links, refuse_special, write_text
from shipgym_baselines.records.runrecord import now
from shipgym_baselines.scoring.intervals import geometric_mean
from shipgym_baselines.tuning import chosen as chosen_settings
from shipgym_baselines.tuning import promotion
from shipgym_baselines.tuning.estimate import cpu_duration, recorded_cpu_s
from shipgym_baselines.tuning.objective import chunked_ratios, controller_ratios
from shipgym_baselines.tuning.report import REPORT_FILE, best_vs_default, trial_rows
from shipgym_baselines.tuning.space import TuningConfig, load_tuning
from shipgym_baselines.tuning.validation import ValidationTrial, oracle_costs, validation_trials

STORAGE_FILE = "study.db"
#: the folder under ``--out`` that a study's chosen settings go to unless promoted
CHOSEN_FOLDER = "chosen"
#: Optuna's states of a finished trial
FINISHED = ("COMPLETE", "PRUNED", "FAIL")
#: a tuning config's keys that do not change a study's scores: its name and words, its budget
#: (``--trials`` with ``--resume`` extends a study) and a learned study's final training
UNSCORED = frozenset({"name", "description", "budget", "final"})
#: the study's user attributes that keep :func:`study_record` and its SHA-256
RECORD_ATTR, DIGEST_ATTR = "record", "record_sha256"

Progress = Callable[[str], object]


@dataclasses.dataclass
class StudyPlan:
    """What one study runs: config, ship (None: every ship), folder, storage, name, and
    the folder its chosen settings go to (None: not written, as in a Ray task)."""

    tuning: str  # the config's name or path (what a Ray worker reloads)
    config: TuningConfig
    ship: str | None
    folder: Path
    storage: str
    study_name: str
    chosen_dir: Path | None = None

    @property
    def section(self) -> str:
        return self.ship or chosen_records.ALL_SHIPS


def plan_studies(
    tuning: str,
    ship: str | None = None,
    out: str | os.PathLike | None = None,
    storage: str | None = None,
    chosen_dir: str | os.PathLike | None = None,
    promote: bool = False,
) -> list[StudyPlan]:
    """The studies ``shipgym tune`` runs: one per ship for a per-ship config (only ``ship``
    when given), else one.  Their chosen settings go to ``<out>/chosen``, the packaged
    folder with ``promote``, or ``chosen_dir``."""
    config = load_tuning(tuning)
    base = Path(out) if out is not None else Path("results") / "tuning" / config.name
    if promote and chosen_dir is not None:
        raise RunError(
            "--promote writes the packaged chosen settings and --chosen-dir another folder: "
            "give one of them"
        )
    if promote:
        chosen = chosen_records.chosen_dir()
    else:
        chosen = Path(chosen_dir) if chosen_dir is not None else base / CHOSEN_FOLDER
    if not config.per_ship:
        if ship is not None:
            raise RunError(f"--ship: {config.name} is one setting for every ship (per_ship false)")
        return [_plan(tuning, config, None, base, storage, chosen)]
    ships = _ships(config)
    if ship is not None:
        if ship not in ships:
            raise RunError(f"--ship {ship!r}: {config.name} is tuned on {', '.join(ships)}")
        ships = [ship]
    if storage is not None and len(ships) > 1:
        raise RunError("--storage names one study's storage: give --ship too")
    return [_plan(tuning, config, s, base / s, storage, chosen) for s in ships]


def _ships(config: TuningConfig) -> list[str]:
    """The ships a per-ship config is tuned on: its ``ships`` or every ship of the
    validation split the controller applies to."""
    from shipgym.scenarios.sampling import load_distribution
    from shipgym_baselines.registry import resolve_controller

    models = [s.model for s in load_distribution(config.validation.distribution).config.ships]
    applies = resolve_controller(config.controller).applies_to
    wanted = config.ships or models
    return [m for m in models if m in wanted and (applies is None or m in applies)]


def _plan(
    tuning: str,
    config: TuningConfig,
    ship: str | None,
    folder: Path,
    storage: str | None,
    chosen: Path,
) -> StudyPlan:
    url = storage or default_storage(folder)
    name = f"{config.name}:{ship}" if ship else config.name
    return StudyPlan(tuning, config, ship, folder, url, name, chosen)


def study_exists(plan: StudyPlan) -> bool:
    import optuna

    db = sqlite_file(plan.storage)
    if db is not None and not db.is_file():
        return False
    return plan.study_name in optuna.study.get_all_study_names(plan.storage)


def plan_trials(plan: StudyPlan) -> list[ValidationTrial]:
    v = plan.config.validation
    return validation_trials(v.distribution, plan.ship, v.per_ship, plan.config.ships)


def study_record(plan: StudyPlan) -> dict[str, Any]:
    """What determines a study's scores: its config resolved (but :data:`UNSCORED`), its
    ship, its validation trials (name, env seed and scenario content hash each) and the env
    and oracle revisions."""
    from shipgym_baselines.references import scenario_key

    trials = [f"{t.name}:{t.seed}:{scenario_key(t.scenario)}" for t in plan_trials(plan)]
    return {
        **plan.config.model_dump(mode="json", exclude=set(UNSCORED)),
        "ship": plan.ship,
        "validation_trials": trials,
        **promotion.revisions(),
    }


def record_digest(record: dict[str, Any]) -> str:
    """The SHA-256 of a :func:`study_record` as canonical JSON."""
    text = json.dumps(record, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()


def changed_keys(old: dict[str, Any], new: dict[str, Any]) -> list[str]:
    """The keys whose values differ between two records, a mapping's keys named inside it
    (``params.los_radius_L``, ``fixed.tuning``)."""
    changed = []
    for key in sorted(set(old) | set(new)):
        a, b = old.get(key), new.get(key)
        if a == b:
            continue
        if isinstance(a, dict) and isinstance(b, dict):
            changed += [f"{key}.{k}" for k in sorted(set(a) | set(b)) if a.get(k) != b.get(k)]
        else:
            changed.append(key)
    return changed


def check_record(plan: StudyPlan, study: Any) -> None:
    """Refuse to continue ``study`` unless it was started with the plan's
    :func:`study_record` (:class:`RunError` naming the keys that changed)."""
    held = study.user_attrs.get(DIGEST_ATTR)
    advice = "start a new study with another --out or --storage"
    if held is None:
        raise RunError(
            f"--resume: study {plan.study_name!r} in {plan.storage} has no record of the config "
            f"it started with (it began before studies kept one): {advice}"
        )
    record = study_record(plan)
    if held != record_digest(record):
        changed = changed_keys(dict(study.user_attrs.get(RECORD_ATTR) or {}), record)
        raise RunError(
            f"--resume: the config differs from the one study {plan.study_name!r} started "
            f"with: {', '.join(changed) or 'its record'} (restore it, or {advice})"
        )


class Scorer:
    """Scores settings on a study's validation trials: ``score(overrides, report)`` ->
    per-trial cost ratios (classical: evaluated a chunk at a time; learned: trained, then
    evaluated, :mod:`~shipgym_baselines.tuning.learned`)."""

    def __init__(self, plan: StudyPlan, progress: Progress | None = None) -> None:
        self.plan = plan
        self.run_name: str | None = None  # a learned trial's run folder name
        self.trials = plan_trials(plan)
        plan.folder.mkdir(parents=True, exist_ok=True)
        self.oracle = oracle_costs(self.trials, progress=progress)  # the per-user cache

    def score(
        self, settings: dict[str, Any], report: Callable[[float, int], None] | None = None
    ) -> list[float]:
        """Per-trial ratios of the controller made with ``settings`` (all of them: the
        study's ``fixed`` are not added here)."""
        config = self.plan.config
        if config.kind == "learned":
            from shipgym_baselines.tuning.learned import train_and_score

            run = self.plan.folder / "runs" / (self.run_name or "default")
            return train_and_score(config, settings, self.trials, self.oracle, run, report)
        return chunked_ratios(
            lambda trials, oracle: controller_ratios(config.controller, settings, trials, oracle),
            self.trials,
            self.oracle,
            config.chunk,
            report,
        )

    def objective(self, trial: Any) -> float:
        """The Optuna objective: sample, score with pruning reports, return the gmean."""
        import optuna

        params = {k: spec.suggest(trial, k) for k, spec in self.plan.config.params.items()}
        start = time.process_time()
        self.run_name = f"trial_{trial.number}"

        def report(value: float, step: int) -> None:
            trial.report(value, step)
            if trial.should_prune():
                trial.set_user_attr("cpu_s", time.process_time() - start)
                raise optuna.TrialPruned()

        settings = {**self.plan.config.fixed, **params}
        trial.set_user_attr("settings", settings)  # what its value is the objective of
        ratios = self.score(settings, report)
        trial.set_user_attr("ratios", ratios)
        trial.set_user_attr("cpu_s", time.process_time() - start)
        return geometric_mean(ratios)


def open_study(plan: StudyPlan, resume: bool, create: bool = True, driver: bool = True) -> Any:
    """The plan's Optuna study: created with its :func:`study_record` (refused if it exists
    and not ``resume``) or loaded (``resume``: refused if there is none, or if it started
    with another record: :func:`check_record`).  ``driver``: the process that runs the
    study marks the trials a killed process left running as failed; a Ray task (False) must
    not, or it would fail another task's trial that is running now."""
    import optuna

    exists = study_exists(plan)
    if exists and not resume:
        raise RunError(
            f"study {plan.study_name!r} exists in {plan.storage}: pass --resume to continue "
            "it, or another --out / --storage for a new one (nothing is overwritten)"
        )
    if resume and not exists:
        raise RunError(f"--resume: no study {plan.study_name!r} in {plan.storage}")
    plan.folder.mkdir(parents=True, exist_ok=True)
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    finished = 0
    if exists:
        study = optuna.load_study(study_name=plan.study_name, storage=plan.storage)
        check_record(plan, study)
        if driver:
            _fail_stale(study)
        finished = sum(t.state.name in FINISHED for t in study.trials)
    sampler = optuna.samplers.TPESampler(
        seed=plan.config.sampler_seed + finished,
        n_startup_trials=plan.config.startup_trials,
    )
    pruner = optuna.pruners.MedianPruner(n_startup_trials=plan.config.startup_trials)
    if not exists and create:
        record = study_record(plan)
        try:
            study = optuna.create_study(
                study_name=plan.study_name,
                storage=plan.storage,
                sampler=sampler,
                pruner=pruner,
                direction="minimize",
            )
        except optuna.exceptions.DuplicatedStudyError:
            raise RunError(
                f"study {plan.study_name!r} was just created in {plan.storage} by another "
                "process: wait for it, or choose another --out / --storage"
            ) from None
        study.set_user_attr(RECORD_ATTR, record)
        study.set_user_attr(DIGEST_ATTR, record_digest(record))
        return study
    return optuna.load_study(
        study_name=plan.study_name, storage=plan.storage, sampler=sampler, pruner=pruner
    )


def _fail_stale(study: Any) -> None:
    """Mark trials a killed process left running as failed (a resumed study re-runs them)."""
    from optuna.trial import TrialState

    for t in study.trials:
        if t.state == TrialState.RUNNING:
            study._storage.set_trial_state_values(t._trial_id, state=TrialState.FAIL)


def run_study(
    plan: StudyPlan,
    n_trials: int | None = None,
    resume: bool = False,
    backend: str = "local",
    workers: int = 1,
    progress: Progress | None = None,
    force: bool = False,
) -> dict[str, Any]:
    """Run (or continue) one study to ``n_trials`` finished trials (default: the config's
    budget), then write its report and chosen settings (``force``: even over better
    settings; module doc); returns the report."""
    check_backend(backend)
    total = int(n_trials if n_trials is not None else plan.config.budget)
    if total < 1:
        raise RunError(f"--trials {total}: at least 1")
    check_chosen(plan)  # before any trial, not after the last
    with out_lock(plan.folder, now()), storage_lock(plan):
        check_no_links(plan.folder)
        manifest = Manifest(plan.folder)
        if plan.storage == default_storage(plan.folder):
            manifest.claim(STORAGE_FILE)
        with manifest.recording():
            report = _run_locked(plan, total, resume, backend, workers, progress, force)
        manifest.compact(keep=(REPORT_FILE,))
        return report


def check_chosen(plan: StudyPlan) -> None:
    """A :class:`RunError` in one line, before the study's first trial, when the chosen
    settings it will write cannot be: a link or no regular file in the file's place, or a
    file that is no chosen-settings document."""
    if plan.chosen_dir is None:
        return
    file = chosen_settings.chosen_file(plan.config.controller, plan.chosen_dir)
    refuse_special(file, "--chosen-dir")
    chosen_settings.read_chosen(plan.config.controller, plan.chosen_dir)


@contextlib.contextmanager
def storage_lock(plan: StudyPlan) -> Iterator[None]:
    """Hold the lock of a SQLite ``--storage`` outside the study's folder (``<db>.lock``):
    two processes on one study through one storage, each with its own ``--out``, would
    draw the same trials; the second is refused in one line naming the first.  The
    default storage lies in the folder, which :func:`run_study` locks already; a server
    storage (``postgresql://…``) is not locked here: run one ``tune`` per study on it."""
    db = sqlite_file(plan.storage)
    if db is None or plan.storage == default_storage(plan.folder):
        yield
        return
    with file_lock(db, now(), "--storage"):
        yield


def sqlite_file(storage: str) -> Path | None:
    """The database file of a SQLite storage URL (None: another storage)."""
    prefix = "sqlite:///"
    return Path(storage[len(prefix) :]) if storage.startswith(prefix) else None


def default_storage(folder: Path) -> str:
    """The SQLite storage URL of a study in ``folder`` (:data:`STORAGE_FILE`)."""
    return f"sqlite:///{(folder / STORAGE_FILE).absolute()}"


def _run_locked(
    plan: StudyPlan,
    total: int,
    resume: bool,
    backend: str,
    workers: int,
    progress: Progress | None,
    force: bool,
) -> dict[str, Any]:
    """:func:`run_study` once the study's folder is locked; its start-up line
    (:func:`~shipgym_baselines.tuning.study.start_line`) once the study opened."""
    study = open_study(plan, resume)
    say(progress, start_line(plan, total))
    scorer = Scorer(plan, progress)
    if "default_ratios" not in study.user_attrs:
        say(progress, f"{plan.study_name}: scoring the default settings")
        start = time.process_time()
        study.set_user_attr("default_ratios", scorer.score(dict(plan.config.default)))
        study.set_user_attr("default_cpu_s", time.process_time() - start)
    remaining = total - sum(t.state.name in FINISHED for t in study.trials)
    if remaining > 0:
        say(progress, f"{plan.study_name}: {remaining} trial(s) to run ({backend})")
        if backend == "ray":
            _run_on_ray(plan, total, workers)
        else:
            study.optimize(
                scorer.objective,
                n_trials=remaining,
                callbacks=[_progress_callback(plan, progress)],
            )
    study = open_study(plan, resume=True, create=False)
    return write_report(plan, study, scorer, force, progress)


def start_line(plan: StudyPlan, trials: int) -> str:
    """The line a study starts with, after its checks: the study, its ``trials``, the
    validation trials each scores, and an estimate from the shipped study's CPU per trial
    (:func:`~shipgym_baselines.tuning.estimate.recorded_cpu_s`; a resumed study runs only
    the trials it lacks: the estimate is then an upper bound)."""
    config = plan.config
    validation = len(plan_trials(plan))
    where = plan.ship or "every ship"
    each = "a training run scored on" if config.kind == "learned" else "scored on"
    recorded = recorded_cpu_s(config.name, plan.ship)
    if recorded is None:
        estimate = "no shipped study of this name and ship to estimate from"
    else:
        per_trial, default = recorded
        estimate = (
            f"at most about {cpu_duration(per_trial * trials + default)} (the shipped study: "
            f"{per_trial:.1f} CPU s a trial)"
        )
    return (
        f"{plan.study_name}: {trials} trials of {config.controller} ({where}), each "
        f"{each} {validation} validation trials, after the default settings; {estimate}"
    )


def _progress_callback(plan: StudyPlan, progress: Progress | None) -> Callable[..., None]:
    def callback(study: Any, trial: Any) -> None:
        best = study.best_value if any(t.value is not None for t in study.trials) else None
        say(
            progress,
            f"{plan.study_name}: trial {trial.number} {trial.state.name} value {trial.value} "
            f"params {trial.params} (best {best})",
        )

    return callback


def say(progress: Progress | None, text: str) -> None:
    if progress is not None:
        progress(text)


def write_report(
    plan: StudyPlan,
    study: Any,
    scorer: Scorer,
    force: bool = False,
    progress: Progress | None = None,
) -> dict[str, Any]:
    """Write ``tuning_report.json`` and the chosen settings (module doc); returns the
    report."""
    config = plan.config
    trials, oracle = scorer.trials, scorer.oracle
    default = list(study.user_attrs["default_ratios"])
    complete = [t for t in study.trials if t.state.name == "COMPLETE"]
    best = min(complete, key=lambda t: t.value) if complete else None
    names = [t.name for t in trials]
    report: dict[str, Any] = {
        "name": config.name,
        "controller": config.controller,
        "kind": config.kind,
        "ship": plan.ship,
        "study": plan.study_name,
        "storage": plan.storage,
        "objective": config.objective,
        "sampler": {
            "type": "TPESampler",
            "seed": config.sampler_seed,
            "n_startup_trials": config.startup_trials,
        },
        "pruner": {
            "type": "MedianPruner",
            "n_startup_trials": config.startup_trials,
            "report_every_trials": config.chunk,
        },
        "budget": config.budget,
        "validation": {
            "distribution": config.validation.distribution,
            "trials": names,
            "seeds": [t.seed for t in trials],
            "oracle_costs": oracle,
        },
        "fixed": dict(config.fixed),
        "default_settings": dict(config.default),
        "search_space": {k: v.model_dump(exclude_none=True) for k, v in config.params.items()},
        "trials": trial_rows(study),
        "best_params": dict(best.params) if best else None,
        "best_value": best.value if best else None,
        "default_value": geometric_mean(default),
        "cpu_s": {
            "default": study.user_attrs.get("default_cpu_s"),
            "trials": sum(t.user_attrs.get("cpu_s") or 0.0 for t in study.trials),
        },
    }
    if best is not None:
        report["best_vs_default"] = best_vs_default(best.user_attrs["ratios"], default, names)
        improved = best.value < report["default_value"]
        # the settings the winner was scored with: the best trial's as stored with it (the
        # fixed ones and its parameters), or the default's (a learned study's default names
        # its env and rollout settings, the same as every trial's; a classical default, the
        # paper's preset, is the controller's construction without chosen settings)
        winner = dict(best.user_attrs["settings"]) if improved else dict(config.default)
        settings = {k: v for k, v in winner.items() if k != "preset"}
        ratios = list(best.user_attrs["ratios"]) if improved else default
        values = f"{best.value:.4g}, default {report['default_value']:.4g}"
        choice = (
            f"the best trial's settings (best {values})"
            if improved
            else f"the default settings (no trial beat them: best trial {values})"
        )
        summary = {
            "study": plan.study_name,
            "report": str(plan.folder / REPORT_FILE),
            "best_value": best.value,
            "default_value": report["default_value"],
            "trials": len(study.trials),
            "value": geometric_mean(ratios),
            "validation": promotion.validation_record(trials, ratios),
        }
        report["chosen"] = {
            "section": plan.section,
            "settings": settings,
            "kept_default": not improved,
            **write_chosen(plan, scorer, settings, ratios, summary, choice, force, progress),
        }
    plan.folder.mkdir(parents=True, exist_ok=True)
    write_text(plan.folder / REPORT_FILE, json.dumps(report, indent=2, default=_jsonable) + "\n")
    return report


def write_chosen(
    plan: StudyPlan,
    scorer: Scorer,
    settings: dict[str, Any],
    ratios: list[float],
    summary: dict[str, Any],
    choice: str,
    force: bool,
    progress: Progress | None,
) -> dict[str, Any]:
    """Write the winner's ``settings`` (``choice``: which they are, in words) into the plan's
    chosen folder unless the section there holds settings that are better on the same
    trials (``force``: write anyway); returns the report's ``chosen`` block: ``file``,
    ``written``, ``replaced``, ``incumbent`` (the paired comparison, None for a new section)
    and ``refused``."""
    block: dict[str, Any] = {
        "file": None,
        "written": False,
        "replaced": None,
        "incumbent": None,
        "refused": None,
    }
    if plan.chosen_dir is None:
        return block
    controller = plan.config.controller
    file = chosen_settings.chosen_file(controller, plan.chosen_dir)
    where = f"{file} [{plan.section}]"
    block["file"] = str(file)
    held = chosen_records.section_record(controller, plan.section, plan.chosen_dir)
    if held is not None:
        incumbent = block["incumbent"] = _incumbent(plan, scorer, held, progress)
        c = incumbent["comparison"] = promotion.compare(ratios, incumbent.pop("ratios"))
        if not promotion.not_worse(c) and not force:
            block["refused"] = (
                f"{plan.study_name}: kept {where}: its settings score {c['incumbent_value']:.4g} "
                f"on the same {c['trials']} validation trials, this study's choice "
                f"({choice}) {c['new_value']:.4g} (lower is better); --force replaces them"
            )
            return block
    written, block["replaced"] = chosen_settings.write_chosen(
        controller, plan.section, settings, summary, plan.chosen_dir
    )
    block.update(file=str(written), written=True)
    if held is None:
        said = f", objective {summary['value']:.4g}: written to {where} (a new section)"
    else:
        said = (
            f": replaced {where}: {block['replaced']} (objective {c['incumbent_value']:.4g}) by "
            f"{settings} ({c['new_value']:.4g}, the same {c['trials']} validation trials)"
        )
    say(progress, f"{plan.study_name}: chose {choice}{said}")
    return block


def _incumbent(
    plan: StudyPlan,
    scorer: Scorer,
    held: tuple[dict[str, Any], dict[str, Any]],
    progress: Progress | None,
) -> dict[str, Any]:
    """The settings a chosen section holds, with their ratios on the study's trials:
    recorded, or scored now (:mod:`~shipgym_baselines.tuning.promotion`)."""
    settings, summary = held
    ratios = promotion.recorded_ratios(summary, scorer.trials)
    source = "recorded"
    if ratios is None:
        say(
            progress,
            f"{plan.study_name}: scoring the settings already chosen for {plan.section} on the "
            f"same {len(scorer.trials)} validation trials (no record on these trials)",
        )
        scorer.run_name = "incumbent"
        ratios = scorer.score(promotion.incumbent_settings(plan.config, settings))
        source = "scored"
    return {"settings": settings, "source": source, "study": summary.get("study"), "ratios": ratios}


def _jsonable(value: Any) -> Any:
    if hasattr(value, "item"):
        return value.item()
    raise TypeError(f"not JSON: {value!r}")


def _run_on_ray(plan: StudyPlan, total: int, workers: int) -> None:
    """The remaining trials as Ray tasks, ``workers`` at once, sharing the storage (a Ray
    started here has ``workers`` CPUs and is shut down after)."""
    n = max(1, workers)
    setup = RaySetup(
        init={"num_cpus": n, "include_dashboard": False, "log_to_driver": False},
        task={"num_cpus": 1},
        shutdown=True,
    )
    task = functools.partial(_ray_worker, plan.tuning, plan.ship, str(plan.folder), plan.storage)
    list(map_jobs(task, [total] * n, "ray", ray_setup=setup))  # until every task ends


def _ray_worker(tuning: str, ship: str | None, folder: str, storage: str, total: int) -> int:
    """One Ray task: load the study and run trials until it holds ``total`` finished."""
    from optuna.study import MaxTrialsCallback
    from optuna.trial import TrialState

    config = load_tuning(tuning)
    name = f"{config.name}:{ship}" if ship else config.name
    plan = StudyPlan(tuning, config, ship, Path(folder), storage, name)
    study = open_study(plan, resume=True, create=False, driver=False)
    scorer = Scorer(plan)
    states = (TrialState.COMPLETE, TrialState.PRUNED, TrialState.FAIL)
    if sum(t.state in states for t in study.trials) >= total:
        return 0
    study.optimize(scorer.objective, callbacks=[MaxTrialsCallback(total, states=states)])
    return len(study.trials)
