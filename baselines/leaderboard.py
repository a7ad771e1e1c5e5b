"""The leaderboard: every controller on every suite scenario × seeds, one table (SPEC §9).

Each evaluation seed runs its own trial of a scenario: the suite's ``randomize`` ranges
(:mod:`shipgym.scenarios.trials`) draw the start, the jump time and the current from the
seed, and the sensor noise varies with it too.  A learned agent runs once per training seed
(:func:`shipgym_baselines.registry.training_seeds`), so its row aggregates training seeds ×
evaluation seeds.

The work is cut into jobs (:class:`Job`, names and seeds only: the worker builds each
seed's trial): a classical controller's job is one scenario for all the evaluation seeds,
a learned agent's one training seed on one scenario for all of them, the oracle's one
(scenario, seed) trial; a job's seeds run in lockstep
(:func:`shipgym_baselines.evaluation.evaluate_batch`: the rows of one evaluation trials env, one
network forward per step for a learned agent's, equal to the episodes one by one).
``local`` runs the jobs in a process pool; ``ray`` submits the same job function to a Ray
cluster (``pip install shipgym[ray]``).
The parent records each episode as it arrives (:mod:`shipgym_baselines.records.runs`: ``run.json``,
``episodes.jsonl``), and every table is aggregated from that record: the rows with
``*_ci95`` intervals, ``aggregate.json`` (the ranking of :mod:`shipgym_baselines.ranking`: cost over
the oracle's), ``scenario_scores.json``, the figures.
"""

from __future__ import annotations

import contextlib
import csv
import functools
import io
import json
import math
import os
import sys
from collections import defaultdict
from collections.abc import Callable, Collection, Iterable, Iterator, Mapping, Sequence
from concurrent.futures import Executor, Future, ProcessPoolExecutor, as_completed
from contextlib import closing
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
from tqdm import tqdm

from shipgym.config import is_path
from shipgym.limits import worker_count
from shipgym.metrics import aggregate
from shipgym.notices import notice
from shipgym.scenarios import Scenario, load_scenario
from shipgym.scenarios.trials import TrialRandomization, trial_scenario
from shipgym_baselines import evaluation
from shipgym_baselines.comparison import (
    RECORD_KEY,
    comparison_note,
    references_record,
    suite_folder,
    with_references,
)
from shipgym_baselines.errors import BackendError, RunError, check_seeds
from shipgym_baselines.escaping import csv_cell, md_cell, plain_text
from shipgym_baselines.evaluation import ACT_TIMEOUT_S, EVAL_SEED_OFFSET
from shipgym_baselines.figures import median_ace_episode
from shipgym_baselines.jsonout import dumps, dumps_rows
from shipgym_baselines.plugins import ControllerSpec
from shipgym_baselines.privileged import grants_truth
from shipgym_baselines.ranking import (
    BASELINE,
    GAIN,
    HEADROOM_EXPLAINED,
    ORACLE,
    PARTIAL,
    SCORE_EXPLAINED,
    aggregate_ranking,
    controller_failed,
    headroom_grid,
    headroom_table,
    is_partial,
    no_ranking,
    resolution_lines,
    row_intervals,
    scenario_ships,
)
from shipgym_baselines.ranking import scenario_scores as score_table
from shipgym_baselines.records.episodes import EpisodeResult
from shipgym_baselines.records.outfiles import carried, write_bytes, write_text
from shipgym_baselines.records.runs import (
    BACKENDS,
    RUN_FILE,
    RunLog,
    check_out_dir,
    check_out_usable,
    episode_result,
    read_episodes,
    read_run,
)
from shipgym_baselines.references import ReferenceCache, announce, lookup, result_from_entry
from shipgym_baselines.registry import applies_to, controller_kind, controller_label, training_seeds
from shipgym_baselines.signals import worker_init
from shipgym_baselines.studies.run_costs import eta_line, tables_line
from shipgym_baselines.style import FIGURE_DPI, controller_style
from shipgym_baselines.suite import load_suite, scenario_names
from shipgym_baselines.verdict import folder_verdict, plain_name, verdict

#: metric columns aggregated over a row's episodes (mean, ``*_std`` and ``*_ci95``)
COLUMNS = (
    "ace",
    "ace_L",
    "t_c",
    "return",
    "cost",
    "rudder_travel",
    "J",
    "success",
    "compute_ms",
    "mean_abs_cross_track",
    "max_abs_cross_track",
)

#: training-cost columns, present for learned agents only (mean and std over training seeds)
TRAINING_COLUMNS = ("train_env_steps", "train_wall_s")

AGGREGATE_FILE = "aggregate.json"
PROB = f"prob_improvement_over_{BASELINE}"
SCENARIO_SCORES_FILE = "scenario_scores.json"


def check_controllers(names: list[str]) -> list[str]:
    """The table labels of ``names``; a clear error, before any job runs, for a name that
    is neither a controller nor a trained agent, and for two names with the same label."""
    labels = [controller_label(name) for name in names]  # resolves each: a clear error
    duplicates = sorted({label for label in labels if labels.count(label) > 1})
    if duplicates:
        raise RunError(
            f"controllers {names} give the same table name(s) {duplicates}: give each its "
            "own name (a suite's long form {controller: ..., name: ...})"
        )
    return labels


#: the split of the scenarios a suite gives as YAML files (run.json's ``scenario_files``)
YOURS = "yours"
#: the ranking tables' headings, by split
SPLIT_TITLES = {
    "catalogue": "Catalogue scenarios",
    "heldout": "Held-out scenarios",
    "inrange": "In-range scenarios, drawn from the training ranges",
    YOURS: "Your scenarios",
}
#: the splits of the named test scenarios (``<split>:<index>``): jumps outside the learned
#: agents' training ranges (extrapolation), and inside them (interpolation)
TEST_SPLITS = ("heldout", "inrange")
#: the splits of :func:`generalisation`, in its order
GENERALISATION_SPLITS = ("catalogue", *TEST_SPLITS)


def scenario_split(scenario: str, own: Collection[str] = ()) -> str:
    """``heldout`` / ``inrange`` for named held-out / in-range test scenarios
    (``heldout:3``, ``inrange:3``), :data:`YOURS` for the suite's own scenarios (``own``:
    their table names; a YAML path, as older records name them), else ``catalogue``."""
    for split in TEST_SPLITS:
        if scenario.startswith(f"{split}:"):
            return split
    return YOURS if scenario in own or is_path(scenario) else "catalogue"


# --- jobs ------------------------------------------------------------------------------------


class Job(NamedTuple):
    """One unit of work: a controller (trained with ``training_seed``; None: not trained)
    on the trials of scenario ``scenario`` (its table name, :func:`suite_scenarios`; or a
    catalogue name, held-out name or YAML path loaded as such) that ``seeds``
    draw with ``randomize`` (a :class:`TrialRandomization` as a dict; None: no trials).
    ``settings``: the scenario as the run resolved it at its start (``run.json``'s), run
    as recorded whatever its file says now; None: resolved from ``scenario`` here."""

    controller: ControllerSpec
    scenario: str
    seeds: tuple[int, ...]
    training_seed: int | None = None
    randomize: dict[str, Any] | None = None
    settings: dict[str, Any] | None = None
    #: the oracle's episodes: "table" (the shipped reference table, running only a trial it
    #: lacks) or "recompute" (run every trial)
    references: str = "table"
    #: the limit [s] on one ``act`` call: a slower call, or a controller that fails, ends
    #: its episode (:class:`~shipgym_baselines.evaluation.ActGuard`)
    act_timeout: float = ACT_TIMEOUT_S


@functools.lru_cache(maxsize=128)
def _cached_scenario(name: str, _stamp: tuple[int, int] | None) -> Scenario:
    return load_scenario(name)


def suite_scenario(name: str) -> Scenario:
    """A suite's scenario, loaded once per process (a YAML file again when it changed)."""
    stamp = None
    if is_path(name):
        stat = Path(name).stat()
        stamp = (stat.st_mtime_ns, stat.st_size)
    return _cached_scenario(name, stamp)


def suite_scenarios(entries: Iterable[str]) -> dict[str, Scenario]:
    """A suite's scenarios (as :func:`~shipgym_baselines.suite.load_suite` gives them) by
    table name: a catalogue or held-out name as given, a YAML file's under its ``name:``
    (:func:`~shipgym_baselines.suite.scenario_names`: a name that clashes is refused, naming
    both files)."""
    entries = list(entries)
    names = scenario_names(entries, suite_scenario).names
    return {names[entry]: suite_scenario(entry) for entry in entries}


@functools.lru_cache(maxsize=128)
def _recorded_scenario(settings: str) -> Scenario:
    return load_scenario(json.loads(settings))


def job_scenario(job: Job) -> Scenario:
    """The job's scenario: built from its recorded ``settings`` (once per process), else
    resolved from its name."""
    if job.settings is None:
        return suite_scenario(job.scenario)
    return _recorded_scenario(json.dumps(job.settings, sort_keys=True))


def trials(job: Job) -> list[Scenario]:
    """The job's scenario as each of its seeds draws it (the scenario itself without
    randomisation)."""
    base = job_scenario(job)
    randomization = None if job.randomize is None else TrialRandomization(**job.randomize)
    return [trial_scenario(base, randomization, seed) for seed in job.seeds]


def _named(results: list[EpisodeResult], job: Job) -> list[EpisodeResult]:
    """``results`` under the table name and the job's scenario name, with the job's
    training seed."""
    label = controller_label(job.controller)
    for result in results:
        result.controller = label
        result.scenario = job.scenario
        if job.training_seed is not None:
            result.training_seed = job.training_seed
    return results


def run_job(job: tuple) -> EpisodeResult:
    """One episode ``(controller, scenario, seed[, training_seed[, randomize]])`` (see
    :class:`Job`); top-level so process pools can pickle it."""
    one = Job(job[0], job[1], (int(job[2]),), *job[3:])
    (trial,) = trials(one)
    seeds = list(one.seeds)
    result = evaluation.evaluate(
        one.controller, trial, seeds, training_seed=one.training_seed, guard=_guard(one)
    )
    return _named(result, one)[0]


def _guard(job: Job) -> evaluation.ActGuard:
    """How the job's episodes end when their controller fails."""
    return evaluation.ActGuard(job.act_timeout)


def run_batch(job: Job) -> list[EpisodeResult]:
    """The job's episodes, all seeds at once (:func:`shipgym_baselines.evaluation.evaluate_batch`),
    in the order of ``job.seeds``."""
    results = evaluation.evaluate_batch(
        job.controller,
        trials(job),
        list(job.seeds),
        training_seed=job.training_seed,
        guard=_guard(job),
    )
    return _named(list(results), job)


def reference_work(job: Job) -> list[EpisodeResult]:
    """A privileged reference's episodes of ``job`` (``oracle`` or ``oracle_frozen``): each
    trial's entry of the reference's shipped table or of its per-user cache
    (:mod:`shipgym_baselines.references`), the reference run for a trial both lack (and
    stored in the cache)."""
    reference = controller_label(job.controller)
    cache, out = ReferenceCache(reference=reference), []
    for seed, trial in zip(job.seeds, trials(job), strict=True):
        entry = lookup(trial, seed, cache, reference)
        if entry is not None:
            out.append(result_from_entry(entry, job.scenario, seed, reference))
        else:
            (result,) = _named(
                evaluation.evaluate(job.controller, trial, [seed], guard=_guard(job)), job
            )
            if not controller_failed(result.metrics):  # a reference that failed: not kept
                cache.store(trial, result)
            out.append(result)
    return out


def announce_references(jobs: Iterable[Job]) -> None:
    """One line on stderr per privileged reference before its episodes of ``jobs`` that are
    computed, not read (a trial neither table holds; every trial with
    ``--recompute-references``): how many, the estimated CPU time."""
    pending: dict[str, list[Scenario]] = defaultdict(list)
    where: dict[str, str] = {}
    for job in jobs:
        if not grants_truth(job.controller):
            continue
        reference = controller_label(job.controller)
        cache = ReferenceCache(reference=reference)
        where.setdefault(reference, f"once: cached in {cache.path}")
        for seed, trial in zip(job.seeds, trials(job), strict=True):
            if job.references == "recompute":
                pending[reference].append(trial)
                where[reference] = (
                    "--recompute-references: every trial, the cache neither read nor written"
                )
            elif lookup(trial, seed, cache, reference) is None:
                pending[reference].append(trial)
    for reference, todo in pending.items():
        announce(todo, where[reference], reference)


def work(job: Job) -> list[EpisodeResult]:
    """A job's episodes: a privileged reference's from its table (:func:`reference_work`), a
    single seed through :func:`run_job`, several through :func:`run_batch`."""
    if job.references == "table" and grants_truth(job.controller):
        return reference_work(job)
    if len(job.seeds) == 1:
        return [run_job((job.controller, job.scenario, job.seeds[0], *job[3:]))]
    return run_batch(job)


def _iter_local(jobs: list[Job], workers: int) -> Iterator[list[EpisodeResult]]:
    """The jobs' results as they finish (in turn, or in a pool of ``workers`` processes,
    :func:`shipgym_baselines.signals.worker_init`)."""
    if workers <= 1:
        for job in jobs:
            yield work(job)
        return
    pool = ProcessPoolExecutor(max_workers=workers, initializer=worker_init)
    try:
        for fut in as_completed([pool.submit(work, j) for j in jobs]):
            yield fut.result()
    except BaseException:  # Ctrl-C, a failed job, or the consumer stopped: stop the workers
        workers_running = list((pool._processes or {}).values())  # shutdown forgets them
        pool.shutdown(wait=False, cancel_futures=True)
        for process in workers_running:
            process.kill()  # workers ignore SIGTERM (shipgym_baselines.signals)
        raise
    pool.shutdown()


def _iter_ray(jobs: list[Job]) -> Iterator[list[EpisodeResult]]:
    try:
        import ray
    except ImportError as exc:
        raise BackendError("--backend ray needs Ray: pip install 'shipgym[ray]'") from exc
    if not ray.is_initialized():
        ray.init(address=os.environ.get("RAY_ADDRESS"), ignore_reinit_error=True)
    remote = ray.remote(work)
    pending = [remote.remote(j) for j in jobs]
    try:
        while pending:
            done, pending = ray.wait(pending)
            yield from ray.get(done)
    except BaseException:
        for ref in pending:
            ray.cancel(ref, force=True)
        raise


def iter_results(jobs: list[Job], backend: str, workers: int) -> Iterator[list[EpisodeResult]]:
    """The results of ``jobs`` on ``backend`` (:data:`BACKENDS`), job by job in completion
    order."""
    if backend == "local":
        return _iter_local(jobs, workers)
    if backend == "ray":
        return _iter_ray(jobs)
    raise RunError(f"unknown backend {backend!r}; valid: {', '.join(BACKENDS)}")


def _result_key(result: EpisodeResult) -> tuple[str, str, int, int | None]:
    """(scenario, table name, seed, training seed): the episode's key in ``episodes.jsonl``."""
    return (result.scenario, result.controller, int(result.seed), result.training_seed)


def suite_record(
    spec: Any,
    names: list[ControllerSpec],
    scenarios: Mapping[str, Scenario],
    seed_list: list[int],
    seeds_of: Mapping[str, list[int | None]],
) -> dict[str, Any]:
    """The resolved suite as ``run.json`` keeps it: evaluation seeds (``scenario_seeds``:
    the scenarios run on fewer, :meth:`~shipgym_baselines.suite.SuiteConfig.scenario_seeds`),
    the trial randomisation, controllers (table name, how the suite names it, kind, training seeds),
    each scenario's settings (by table name), the pairs that do not apply and, when the
    suite has its own scenarios, ``scenario_files`` (table name → the YAML file read)."""
    ships = {s: sc.model.name for s, sc in scenarios.items()}
    controllers = []
    for c in names:
        label = controller_label(c)
        controllers.append(
            {
                "name": label,
                "controller": c if isinstance(c, str) else c.model_dump(),  # the long form
                "kind": controller_kind(label),
                "training_seeds": list(seeds_of[label]),
            }
        )
    files = scenario_names(spec.all_scenarios(), suite_scenario).files
    own = {"scenario_files": {n: f for n, f in files.items() if n in scenarios}}
    fewer = {s: v for s, v in spec.scenario_seeds(seed_list).items() if s in scenarios}
    return {
        "name": spec.name,
        "seeds": seed_list,
        **({"scenario_seeds": fewer} if fewer else {}),  # absent without: older records resume
        "randomize": None if spec.randomize is None else spec.randomize.model_dump(mode="json"),
        "controllers": controllers,
        "scenarios": {s: sc.config.model_dump(mode="json") for s, sc in scenarios.items()},
        "does_not_apply": [
            [s, c["name"]]
            for s in scenarios
            for c in controllers
            if not applies_to(c["name"], ships[s])
        ],
        **(own if own["scenario_files"] else {}),  # absent without: older records resume
    }


def plan_jobs(
    names: list[ControllerSpec],
    scenarios: Iterable[str] | Mapping[str, dict[str, Any]],
    seed_list: list[int],
    seeds_of: Mapping[str, list[int | None]],
    randomize: dict[str, Any] | None,
    skip: set[tuple[str, str]],
    references: str = "table",
    scenario_seeds: Mapping[str, list[int]] | None = None,
) -> list[Job]:
    """Every job of a run: per scenario and controller that applies, one job of all seeds
    per training seed (a learned agent's) or of all seeds (a classical controller's: they
    run in lockstep, :func:`run_batch`), one job per seed for the privileged oracle (its
    reference table is looked up trial by trial).  ``scenarios``: names, or name →
    recorded settings (the jobs run those); ``scenario_seeds``: the scenarios run on other
    seeds than ``seed_list``, with theirs."""
    jobs = []
    for scenario in scenarios:
        settings = scenarios[scenario] if isinstance(scenarios, Mapping) else None
        seeds = list((scenario_seeds or {}).get(scenario, seed_list))
        for c in names:
            label = controller_label(c)
            if (scenario, label) in skip:
                continue
            for k in seeds_of[label]:
                if controller_kind(label) == "learned":
                    jobs.append(Job(c, scenario, tuple(seeds), k, randomize, settings))
                elif not grants_truth(c):
                    jobs.append(Job(c, scenario, tuple(seeds), k, randomize, settings, references))
                else:
                    jobs += [
                        Job(c, scenario, (seed,), k, randomize, settings, references)
                        for seed in seeds
                    ]
    return jobs


def longest_first(jobs: list[Job], scenarios: Mapping[str, Scenario]) -> list[Job]:
    """``jobs`` ordered by their most control steps (the scenario's time limit over its
    control period, × the job's seeds), longest first: the pool's workers then end
    together instead of one finishing a long job alone (what a run computes is the same)."""

    def steps(job: Job) -> float:
        sc = scenarios[job.scenario]
        return sc.config.time_limit / sc.control_period * len(job.seeds)

    return sorted(jobs, key=steps, reverse=True)  # stable: ties keep the plan's order


def missing(jobs: list[Job], done: set[Any]) -> list[Job]:
    """The jobs with the seeds whose episodes ``done`` (episode keys) does not hold."""
    todo = []
    for job in jobs:
        label = controller_label(job.controller)
        seeds = [s for s in job.seeds if (job.scenario, label, s, job.training_seed) not in done]
        if seeds:
            todo.append(job._replace(seeds=tuple(seeds)))
    return todo


def run_leaderboard(
    suite: str = "default",
    seeds: int | None = None,
    out_dir: str | os.PathLike | None = None,
    backend: str = "local",
    workers: int | None = None,
    controllers: Iterable[ControllerSpec] | None = None,
    show_progress: bool = True,
    resume: bool = False,
    force: bool = False,
    command: list[str] | None = None,
    on_episode: Callable[[EpisodeResult], None] | None = None,
    recompute_references: bool = False,
    vector_figures: bool = False,
    add_references: bool = False,
    act_timeout: float = ACT_TIMEOUT_S,
    retry_failed: bool = False,
) -> list[dict[str, Any]]:
    """Run the suite, write its tables, ranking and figures (:func:`write_results`); return
    the rows.

    ``out_dir`` must be empty unless ``resume`` (run only the episodes missing from its
    ``episodes.jsonl``: a job whose episodes are partly there runs the missing seeds) or
    ``force`` (clear its earlier outputs); ``command``: the argv recorded in ``run.json``
    (default ``sys.argv``); ``on_episode``: called in this process after each episode is
    recorded; ``recompute_references``: run the ``oracle`` on every trial instead of reading
    its shipped reference table (:mod:`shipgym_baselines.references`); ``vector_figures``:
    the figures' vector copies too (SVG / SVGZ).  ``workers``: local processes
    (default: the cores), clamped to the jobs; below 1 refused.  ``add_references``: run the
    references (:data:`shipgym_baselines.comparison.REFERENCES`) too, those not among the
    controllers already (``run.json`` records which; a resumed run that did not add them
    does not).  ``out_dir``: default
    ``results/<suite>`` (:func:`~shipgym_baselines.comparison.suite_folder`).
    ``show_progress``: a progress bar on stderr, after one line before the first episode: the
    episodes, workers and the time estimated from the recorded costs
    (:func:`shipgym_baselines.studies.run_costs.eta_line`).  Ctrl-C raises
    :class:`~shipgym_baselines.records.runs.RunInterrupted`.

    A controller that fails (raises, gives a malformed or non-finite action, or takes
    longer than ``act_timeout`` [s] for one ``act`` call) ends that episode, recorded with
    ``termination_reason`` ``controller_error`` / ``controller_timeout`` and its
    ``error``, and the run goes on (:class:`~shipgym_baselines.evaluation.ActGuard`);
    ``resume`` keeps such episodes unless ``retry_failed``, which runs them again.
    """
    if out_dir is None:
        out_dir = suite_folder(suite)
    check_failure_options(act_timeout, retry_failed, resume)  # before any work
    check_out_usable(out_dir, resume=resume, force=force)
    if backend not in BACKENDS:
        raise RunError(f"unknown backend {backend!r}; valid: {', '.join(BACKENDS)}")
    spec = load_suite(suite)  # a bad suite is named before the state of out_dir
    check_out_dir(out_dir, resume=resume, force=force)
    n_seeds = int(seeds if seeds is not None else spec.seeds)
    check_seeds(n_seeds, "--seeds")
    names = list(controllers) if controllers else list(spec.controllers)
    added: list[str] = []
    if resume and RECORD_KEY not in read_run(out_dir)["suite"]:
        add_references = False  # resumed as it was started: without the references
    if add_references:
        names, added = with_references(names)
    labels = check_controllers(names)
    seeds_of = {label: training_seeds(c) for label, c in zip(labels, names, strict=True)}
    seed_list = [EVAL_SEED_OFFSET + i for i in range(n_seeds)]
    scenarios = suite_scenarios(spec.all_scenarios())
    record = suite_record(spec, names, scenarios, seed_list, seeds_of)
    if add_references:
        given = list(controllers) if controllers else None
        record[RECORD_KEY] = references_record(suite, spec.controllers, given, added)
    skip = {tuple(pair) for pair in record["does_not_apply"]}
    references = "recompute" if recompute_references else "table"
    jobs = plan_jobs(
        names,
        record["scenarios"],
        seed_list,
        seeds_of,
        record["randomize"],
        skip,
        references,
        record.get("scenario_seeds"),
    )
    jobs = [job._replace(act_timeout=act_timeout) for job in jobs]
    workers = worker_count(workers if workers is not None else os.cpu_count() or 1, len(jobs))
    n_episodes = sum(len(job.seeds) for job in jobs)
    log = RunLog.open(
        out_dir,
        command=sys.argv if command is None else command,
        suite=record,
        jobs=n_episodes,
        resume=resume,
        force=force,
    )
    with log.recording():  # holds out_dir's lock to the end
        if retry_failed:
            log.retry([key for key, ep in log.episodes.items() if controller_failed(ep)])
        todo = longest_first(missing(jobs, log.done), scenarios)
        announce_references(todo)
        rows = row_keys(jobs)
        if show_progress:  # the bar's first line, before any job ends
            sys.stderr.write(eta_line(todo, scenarios, workers, n_episodes) + "\n")
        failed: set[str] = set()  # the controllers whose failure was announced
        bar = tqdm(
            total=n_episodes,
            initial=n_episodes - sum(len(job.seeds) for job in todo),
            desc="leaderboard",
            file=sys.stderr,
            disable=not show_progress,
        )
        try:
            with closing(iter_results(todo, backend, workers)) as results:
                for batch in results:
                    for result in batch:
                        if _result_key(result) in log.done:
                            continue  # recorded before (a resumed job)
                        log.append(result, keep_trajectory=True)
                        keep_drawn(log, rows, (result.scenario, result.controller))
                        announce_failure(result, failed)
                        bar.update(1)
                        if on_episode is not None:
                            on_episode(result)
        finally:
            bar.close()
        for row in rows:  # rows completed by a run that stopped before pruning them
            keep_drawn(log, rows, row)
        with log.manifest.recording():  # the tables and figures: listed as written
            results = load_results(log.folder)
            return write_results(
                log.folder, log.record["suite"], results, workers, vector_figures, show_progress
            )


def check_failure_options(act_timeout: float, retry_failed: bool, resume: bool) -> None:
    """A :class:`RunError` for a limit that is not a positive time [s] and for
    ``--retry-failed`` without ``--resume``."""
    evaluation.ActGuard(act_timeout)
    if retry_failed and not resume:
        raise RunError("--retry-failed runs the failed episodes of a resumed run: add --resume")


def announce_failure(result: EpisodeResult, announced: set[str]) -> None:
    """One line on stderr at the first episode of a controller ended by its failure (its
    error; the run goes on); ``announced``: the controllers already named, updated."""
    if not controller_failed(result.metrics) or result.controller in announced:
        return
    announced.add(result.controller)
    notice(
        f"shipgym: {result.controller} failed on {result.scenario} seed {result.seed} "
        f"({result.metrics['termination_reason']}: {result.metrics.get('error')}); its "
        "episode counts as failed and the run goes on (episodes.jsonl has each failure)"
    )


def row_keys(jobs: Iterable[Job]) -> dict[tuple[str, str], set[tuple]]:
    """(scenario, table name) → the keys of the row's episodes (every training seed ×
    evaluation seed)."""
    rows: dict[tuple[str, str], set[tuple]] = defaultdict(set)
    for job in jobs:
        label = controller_label(job.controller)
        for seed in job.seeds:
            rows[(job.scenario, label)].add((job.scenario, label, seed, job.training_seed))
    return rows


def keep_drawn(log: RunLog, rows: Mapping[tuple[str, str], set[tuple]], row: tuple) -> None:
    """Once every episode of ``row`` is recorded: keep the trajectory of the episode its
    figure draws (:func:`shipgym_baselines.figures.median_ace_episode`), remove the others'."""
    keys = rows[row]
    if not keys <= log.done:
        return
    scenario, controller = row
    seed, training_seed = median_ace_episode([log.episodes[k] for k in keys], *row)
    log.drop_trajectories(keys - {(scenario, controller, seed, training_seed)})


def load_results(folder: str | os.PathLike) -> list[EpisodeResult]:
    """The episodes recorded in a run folder's ``episodes.jsonl`` (trajectories if kept)."""
    return [episode_result(r, folder) for r in read_episodes(folder)]


# --- tables ----------------------------------------------------------------------------------


def _order(result: EpisodeResult) -> tuple:
    ts = result.training_seed
    return (result.scenario, result.controller, ts is not None, ts or 0, result.seed)


def episode_rows(results: Iterable[EpisodeResult]) -> list[dict[str, Any]]:
    """The episodes as the ranking reads them: every metric, ``training_seed`` and keys."""
    return [{**r.row(), "training_seed": r.training_seed} for r in results]


def write_results(
    out: str | os.PathLike,
    suite: Mapping[str, Any],
    results: list[EpisodeResult],
    workers: int | None = None,
    vector_figures: bool = False,
    announce: bool = True,
) -> list[dict[str, Any]]:
    """Tables, ranking and figures into ``out`` from episode results and a suite as
    ``run.json`` keeps it (:func:`suite_record`); returns the rows.  ``announce``: say so
    first in one line on stderr, with the time it takes (:func:`tables_line`).

    ``leaderboard.{json,csv}`` (the rows), ``leaderboard.md`` (the ranking, the
    controller × scenario cost ratios, then the rows), ``generalisation.json``,
    ``aggregate.json`` (:func:`shipgym_baselines.ranking.aggregate_ranking`),
    ``scenario_scores.json`` and the figures
    (:mod:`shipgym_baselines.figures`: per scenario the small multiples of each controller's
    median-ACE episode, per split the ranking's interval estimates and performance
    profiles) and ``leaderboard.html`` (:mod:`shipgym_baselines.pages`: all of it on one page).  The
    ranking of each split and each figure are independent tasks, run in a
    pool of ``workers`` processes (default: the cores) when there are
    :data:`POOLED_FIGURES` scenario figures or more.  ``vector_figures``: each figure's
    vector copy too (the page shows the PNGs; issue 20).
    """
    from shipgym_baselines import figures, pages

    # completion order varies between runs: aggregate in a fixed order (bit-stable means)
    results = sorted(results, key=_order)
    out = Path(out)
    kinds = {c["name"]: c["kind"] for c in suite["controllers"]}
    episodes = episode_rows(results)
    splits = {s: scenario_split(s, suite.get("scenario_files", {})) for s in suite["scenarios"]}
    ranked = rankable(episodes, suite.get("scenario_seeds"))
    if announce:
        notice(tables_line(len(splits), workers or os.cpu_count() or 1))
    drawn = figures.episodes_to_draw(results)
    shown = sorted({scenario for scenario, _ in drawn})
    with _pool(workers or os.cpu_count() or 1, len(shown)) as pool:
        boards = [
            pool.submit(
                aggregate_ranking, ranked, {s: sp for s, sp in splits.items() if sp == split}, kinds
            )
            for split in sorted(set(splits.values()))
        ]
        plots = {
            scenario: pool.submit(
                carried(figures.plot_scenarios),
                out,
                {key: ep for key, ep in drawn.items() if key[0] == scenario},
                suite["scenarios"],
                kinds,
                vector=vector_figures,
            )
            for scenario in shown
        }
        board = sorted(
            (row for future in boards for row in future.result()),
            key=lambda r: (r["split"], r["cost_ratio_iqm"], r["controller"]),
        )
        ranking_plots = [
            pool.submit(
                carried(figures.plot_ranking),
                out,
                [r for r in board if r["split"].removesuffix(PARTIAL) == split],
                ranked,
                splits,
                kinds,
                vector_figures,
            )
            for split in dict.fromkeys(r["split"].removesuffix(PARTIAL) for r in board)
        ]
        rows = aggregate_results(
            results,
            list(suite["scenarios"]),
            list(kinds),
            kinds=kinds,
            not_applicable={tuple(pair) for pair in suite["does_not_apply"]},
            splits=splits,
        )
        scores = score_table(ranked, splits, kinds)
        write_text(out / AGGREGATE_FILE, dumps(board, indent=2) + "\n")
        write_text(out / SCENARIO_SCORES_FILE, dumps_rows(scores))  # one scenario a line
        left_out = sorted({e["scenario"] for e in episodes} - {e["scenario"] for e in ranked})
        note = comparison_note(suite, out)
        headroom = headroom_table(ranked, scenario_ships(suite["scenarios"]), splits)
        head = ranking_markdown(
            board, scores, list(suite["scenarios"]), left_out, ranked, note, headroom
        )
        write_tables(rows, out, head=head)
        files = [f for future in ranking_plots for f in future.result()]
        files += [f for s in suite["scenarios"] if s in plots for f in plots[s].result()]
        files += figures.plot_learning_curves(out, learned_curves(kinds), vector_figures)
    lead = verdict(board, ranked, plain_name)
    pages.write_html(
        out,
        rows,
        board,
        scores,
        files,
        subtitle=subtitle(suite, results),
        verdict=lead,
        note=note if board else "",
        headroom=headroom,
    )
    return rows


def learned_curves(kinds: Mapping[str, str]) -> dict[str, list[dict[str, Any]]]:
    """The shipped learning curves of the suite's learned controllers (by name)."""
    from shipgym_baselines.learned.curves import agent_curves

    return {name: agent_curves(name) for name, kind in kinds.items() if kind == "learned"}


def subtitle(suite: Mapping[str, Any], results: list[EpisodeResult]) -> str:
    """The page's line under its title: suite, seeds, trials, training seeds."""
    trained = {r.training_seed for r in results if r.training_seed is not None}
    parts = [
        f"suite {suite.get('name') or '(merged)'}",
        f"{len(suite['scenarios'])} scenarios",
        f"{len(suite['controllers'])} controllers",
        f"{len(suite['seeds'])} evaluation seeds"
        + (" (randomised trials)" if suite.get("randomize") else ""),
    ]
    if trained:
        parts.append(f"learned agents × {len(trained)} training seeds")
    return " · ".join(parts)


#: scenario figures from which :func:`write_results` draws in a process pool
POOLED_FIGURES = 4


class _Inline:
    """An executor that runs each task as it is submitted (a small run needs no pool)."""

    def submit(self, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Future:
        future: Future = Future()
        future.set_result(fn(*args, **kwargs))
        return future


@contextlib.contextmanager
def _pool(workers: int, figures: int) -> Iterator[Executor | _Inline]:
    """A process pool of ``workers`` for ``figures`` scenario figures and the ranking, or
    :class:`_Inline` for a few or one worker."""
    if workers <= 1 or figures < POOLED_FIGURES:
        yield _Inline()
        return
    with ProcessPoolExecutor(max_workers=workers, initializer=worker_init) as pool:
        yield pool


def aggregate_results(
    results: list[EpisodeResult],
    scenarios: list[str],
    controllers: list[str],
    kinds: Mapping[str, str] | None = None,
    not_applicable: set[tuple[str, str]] | None = None,
    splits: Mapping[str, str] | None = None,
) -> list[dict[str, Any]]:
    """One row per (scenario, controller) over its episodes (training seeds × evaluation
    seeds): means, ``*_std`` and 95 % ``*_ci95`` intervals ``[low, high]`` (bootstrap,
    stratified over training seeds: :func:`shipgym_baselines.ranking.row_intervals`; None where a
    metric is not finite in every episode, e.g. t_c when a seed never converged), or "does
    not apply".  ``seeds``: the evaluation seeds; ``training_seeds``: how many training
    seeds (0 for a controller that is not trained), ``training_seed_list`` which;
    ``episodes``: their product.  ``kinds``: controller kinds (default: the registry's);
    ``not_applicable``: the (scenario, controller) pairs that do not apply (None: every pair
    without episodes); a pair without episodes that is not listed has no row (a partial or
    merged record); ``splits``: scenario → split (default: :func:`scenario_split`)."""
    groups: dict[tuple[str, str], list[EpisodeResult]] = defaultdict(list)
    for r in results:
        groups[(r.scenario, r.controller)].append(r)
    rows = []
    for scenario in scenarios:
        for controller in controllers:
            group = groups.get((scenario, controller), [])
            listed = not_applicable is None or (scenario, controller) in not_applicable
            if not group and not listed:
                continue  # not run (yet): no row
            head = {
                "scenario": scenario,
                "split": (splits or {}).get(scenario) or scenario_split(scenario),
                "controller": controller,
                "kind": group[0].kind
                if group
                else (kinds or {}).get(controller) or controller_kind(controller),
                "applies": bool(group),
            }
            if not group:  # the controller does not apply to this scenario's ship: shown
                rows.append({**head, **_counts([]), **_metric_cells(COLUMNS, None, None)})
                continue
            keys = COLUMNS + tuple(k for k in TRAINING_COLUMNS if k in group[0].metrics)
            agg = aggregate([r.metrics for r in group], keys)
            cis = row_intervals(episode_rows(group), COLUMNS)
            rows.append({**head, **_counts(group), **_metric_cells(keys, agg, cis)})
    return rows


def _counts(group: list[EpisodeResult]) -> dict[str, Any]:
    trained = sorted({r.training_seed for r in group if r.training_seed is not None})
    return {
        "seeds": len({r.seed for r in group}),
        "training_seeds": len(trained),
        "training_seed_list": trained,
        "episodes": len(group),
    }


def _metric_cells(
    keys: Sequence[str], agg: Mapping[str, float] | None, cis: Mapping[str, Any] | None
) -> dict[str, Any]:
    """``key``, ``key_std`` and (for :data:`COLUMNS`) ``key_ci95`` of each metric."""
    cells: dict[str, Any] = {}
    for key in keys:
        cells[key] = None if agg is None else agg[key]
        cells[f"{key}_std"] = None if agg is None else agg[f"{key}_std"]
        if key in COLUMNS:
            cells[f"{key}_ci95"] = None if cis is None else cis[f"{key}_ci95"]
    return cells


# --- the ranking -----------------------------------------------------------------------------


def rankable(
    episodes: list[dict[str, Any]], scenario_seeds: Mapping[str, Collection[int]] | None = None
) -> list[dict[str, Any]]:
    """The episodes the ranking is computed from: those of the scenarios on which every
    controller that ran there has all its runs (each of its training seeds × every
    evaluation seed of the record; ``scenario_seeds``: the scenarios run on fewer, with
    theirs).  A complete run keeps them all; an interrupted or merged record leaves out the
    scenarios it holds only in part."""
    every = {int(e["seed"]) for e in episodes}
    fewer = scenario_seeds or {}
    trained: dict[str, set[Any]] = defaultdict(set)
    cells: dict[tuple[str, str], set[tuple[Any, int]]] = defaultdict(set)
    for e in episodes:
        trained[e["controller"]].add(e["training_seed"])
        cells[(e["scenario"], e["controller"])].add((e["training_seed"], int(e["seed"])))
    partial = {
        scenario
        for (scenario, controller), runs in cells.items()
        if len(runs) != len(trained[controller]) * len(fewer.get(scenario, every))
    }
    return [e for e in episodes if e["scenario"] not in partial]


def _interval(value: Any, ci: Any, digits: int = 2) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "–"
    text = f"{value:.{digits}f}"
    if ci:
        text += f" [{ci[0]:.{digits}f}, {ci[1]:.{digits}f}]"
    return text


def _table_title(split: str, rows: Sequence[Mapping[str, Any]]) -> str:
    """A ranking table's heading: the split, and its scenarios (every controller's in a
    main table; a partial table's controllers have their own)."""
    base = split.removesuffix(PARTIAL)
    name = SPLIT_TITLES.get(base, base)
    if is_partial(split):
        return (
            f"{name}: controllers that do not apply to every scenario (each ranked on the "
            "scenarios it applies to; not comparable with the table above)"
        )
    return f"{name} ({len(rows[0]['scenarios'])}, the same for every controller)"


def ranking_tables(board: Sequence[Mapping[str, Any]]) -> list[str]:
    """The ranking as markdown: one table per split, each followed by its partial table; the
    column of the probability of improvement over ``pid_los`` only where a row has one (the
    run has ``pid_los`` and another controller), the columns against the frozen optimum
    (adaptation gain, P(beats it), gap closed) only where a row has them (the run has
    ``oracle_frozen``)."""
    lines: list[str] = []
    for split in dict.fromkeys(r["split"] for r in board):
        mine = [r for r in board if r["split"] == split]
        with_prob = any(r[PROB] is not None for r in mine)
        prob = [f"P(improvement over {BASELINE}) [95 % CI]"] if with_prob else []
        with_gap = any(r.get(GAIN) is not None for r in mine)
        gap = list(GAP_HEADERS) if with_gap else []
        header = [
            "rank",
            "controller",
            "kind",
            "training seeds",
            "scenarios",
            "cost ratio IQM [95 % CI]",
            "geometric mean [95 % CI]",
            *prob,
            "failure rate [95 % CI]",
            *gap,
        ]
        lines += [
            f"### {_table_title(split, mine)}",
            "",
            "| " + " | ".join(header) + " |",
            "|" + "---|" * len(header),
        ]
        for rank, r in enumerate(mine, start=1):
            cells = [
                str(rank),
                md_cell(r["controller"]),
                md_cell(r["kind"]),
                str(r["training_seeds"] or "–"),
                str(len(r["scenarios"])),
                _interval(r["cost_ratio_iqm"], r["cost_ratio_iqm_ci95"], 3),
                _interval(r["cost_ratio_gmean"], r["cost_ratio_gmean_ci95"], 3),
                *([_interval(r[PROB], r[f"{PROB}_ci95"])] if with_prob else []),
                _interval(r["failure_rate"], r["failure_rate_ci95"]),
                *(_gap_cells(r) if with_gap else []),
            ]
            lines.append("| " + " | ".join(cells) + " |")
        lines.append("")
    return lines


#: the ranking tables' columns against the frozen optimum
GAP_HEADERS = (
    "adaptation gain [95 % CI]",
    "P(C < C_frozen) [95 % CI]",
    "gap closed IQM [95 % CI] (trials)",
)


def _gap_cells(row: Mapping[str, Any]) -> list[str]:
    """A ranking row's cells against the frozen optimum (:data:`GAP_HEADERS`)."""
    trials = row.get("gap_trials")
    gap = _interval(row.get("gap_closed_iqm"), row.get("gap_closed_iqm_ci95"))
    return [
        _interval(row.get(GAIN), row.get(f"{GAIN}_ci95")),
        _interval(row.get("prob_beats_frozen"), row.get("prob_beats_frozen_ci95")),
        gap + (f" ({trials})" if gap != "–" and trials else ""),
    ]


def ranking_markdown(
    board: list[dict[str, Any]],
    scores: list[dict[str, Any]],
    scenarios: list[str],
    left_out: Sequence[str] = (),
    episodes: Sequence[Mapping[str, Any]] = (),
    note: str = "",
    headroom: Sequence[Mapping[str, Any]] = (),
) -> str:
    """The head of ``leaderboard.md``: the score in two sentences, the ranking per split
    (and its partial tables), the resolution, the headroom per ship × change family and the
    controller × scenario table of cost ratios; ``episodes``: the ranked ones (to name the
    scenarios without the oracle's); ``note``: what the run is ranked against
    (:func:`~shipgym_baselines.comparison.comparison_note`), under the score's sentences;
    ``headroom``: :func:`~shipgym_baselines.ranking.headroom_table`'s rows."""
    lead = verdict(board, episodes)
    lines = ["# Leaderboard", "", *([lead, ""] if lead else []), "## Ranking", ""]
    if not board:
        return "\n".join([*lines, no_ranking(scores), ""])
    lines += [SCORE_EXPLAINED, ""]
    if note:
        lines += [note, ""]
    if left_out:
        lines += [f"Left out (episodes missing): {', '.join(left_out)}.", ""]
    with_oracle = {e["scenario"] for e in episodes if e["controller"] == ORACLE}
    unranked = sorted({e["scenario"] for e in episodes} - with_oracle)
    if unranked:
        lines += [
            f"Not ranked (no episodes of {ORACLE}; a run with the references has them): "
            f"{', '.join(unranked)}.",
            "",
        ]
    lines += ranking_tables(board) + resolution_lines(board) + headroom_markdown(headroom)
    lines += scores_markdown(board, scores, scenarios)
    return "\n".join(lines)


def headroom_markdown(headroom: Sequence[Mapping[str, Any]]) -> list[str]:
    """The headroom table (:func:`~shipgym_baselines.ranking.headroom_table` rows): a row per
    ship, a column per change family, each cell the geometric mean of C_frozen / C_oracle
    and its trials; no lines without rows."""
    if not headroom:
        return []
    ships, families, cells = headroom_grid(headroom)
    lines = [
        "### Headroom per ship and change family",
        "",
        HEADROOM_EXPLAINED,
        "",
        "| ship | " + " | ".join(f.replace("_", " ") for f in families) + " |",
        "|---|" + "---|" * len(families),
    ]
    for ship in ships:
        row = [md_cell(ship)]
        for family in families:
            found = cells.get((ship, family))
            row.append(f"{found['headroom_gmean']:.2f} ({found['trials']})" if found else "–")
        lines.append("| " + " | ".join(row) + " |")
    return [*lines, ""]


def scores_markdown(
    board: list[dict[str, Any]], scores: list[dict[str, Any]], scenarios: list[str]
) -> list[str]:
    """The controller × scenario table: the oracle's mean cost, then each controller's
    geometric-mean cost ratio [95 % CI] (– where it does not apply)."""
    by_scenario = {s["scenario"]: s for s in scores}
    shown = [s for s in scenarios if s in by_scenario]
    cell = {(c["controller"], s["scenario"]): c for s in scores for c in s["controllers"]}
    controllers = list(dict.fromkeys(r["controller"] for r in board))
    controllers += sorted({c for c, _ in cell} - set(controllers))  # the references
    lines = [
        "## Cost ratio per scenario",
        "",
        f"First row: the mean cost of {ORACLE} on each scenario [95 % interval]. Then each "
        "controller's geometric mean of C / C_oracle over the row's episodes [95 % interval, "
        "stratified over training seeds]; – where the controller does not apply.",
        "",
        "| controller | " + " | ".join(map(md_cell, shown)) + " |",
        "|---|" + "---|" * len(shown),
        f"| {ORACLE} (cost) | "
        + " | ".join(
            _interval(by_scenario[s]["oracle_cost"], by_scenario[s]["oracle_cost_ci95"], 1)
            for s in shown
        )
        + " |",
    ]
    for controller in controllers:
        row = [md_cell(controller)]
        for s in shown:
            found = cell.get((controller, s))
            row.append(
                _interval(found["cost_ratio_gmean"], found["cost_ratio_gmean_ci95"], 3)
                if found
                else "–"
            )
        lines.append("| " + " | ".join(row) + " |")
    return [*lines, ""]


def terminal_summary(folder: str | os.PathLike) -> str:
    """What ``leaderboard``, ``evaluate`` and ``report`` print: the ranking of the run
    folder's ``aggregate.json`` (or why there is none), its resolution, and the path of
    ``leaderboard.html``."""
    from shipgym_baselines.pages import PAGE_FILE

    lead = folder_verdict(folder)
    board = json.loads((Path(folder) / AGGREGATE_FILE).read_text())
    lines = [
        *([lead, ""] if lead else []),
        "## Ranking (cost over the oracle's; lower is better)",
        "",
    ]
    lines += ranking_tables(board) + resolution_lines(board) if board else [_why_none(folder), ""]
    lines += _note_lines(folder) if board else []
    return "\n".join([*lines, f"leaderboard: {Path(folder) / PAGE_FILE}"])


def _why_none(folder: str | os.PathLike) -> str:
    """Why the run folder has no ranking (:func:`~shipgym_baselines.ranking.no_ranking`)."""
    file = Path(folder) / SCENARIO_SCORES_FILE
    return no_ranking(json.loads(file.read_text()) if file.is_file() else [])


def _note_lines(folder: str | os.PathLike) -> list[str]:
    """What a run folder's ranking is against (its ``run.json``), as lines; none for a
    report's folder or a run that added no reference."""
    if not (Path(folder) / RUN_FILE).is_file():
        return []
    note = comparison_note(read_run(folder).get("suite", {}), folder)
    return [note, ""] if note else []


def _fmt(value: Any, std: Any = None) -> str:
    if isinstance(value, float):
        if math.isinf(value):
            return "never" if value > 0 else "-inf"
        if math.isnan(value):
            return "–"
        text = f"{value:.3f}"
        if isinstance(std, float) and math.isfinite(std):
            text += f" ± {std:.3f}"
        return text
    return str(value)


def write_tables(rows: list[dict[str, Any]], out: Path, head: str = "") -> None:
    """``leaderboard.{json,csv,md}`` and ``generalisation.json``; ``head``: the markdown
    before the rows (the ranking)."""
    write_text(out / "leaderboard.json", dumps_rows(rows))  # one row a line
    keys = list(dict.fromkeys(k for r in rows for k in r))  # learned rows add training cost
    table = io.StringIO(newline="")
    writer = csv.DictWriter(table, fieldnames=keys, restval="")
    writer.writeheader()
    writer.writerows([{k: csv_cell(v) for k, v in r.items()} for r in rows])
    write_text(out / "leaderboard.csv", table.getvalue())
    rows_part = "## All rows\n\n" + markdown_table(rows) if head else markdown_table(rows)
    write_text(
        out / "leaderboard.md",
        (head + "\n" if head else "") + rows_part + generalisation_table(rows),
    )
    write_text(out / "generalisation.json", dumps(generalisation(rows), indent=2))


def _generalisation_splits(rows: Sequence[Mapping[str, Any]]) -> tuple[str, ...]:
    """The splits of :func:`generalisation`: catalogue and held-out always, in-range when
    the run has in-range rows."""
    present = {r["split"] for r in rows}
    return tuple(s for s in GENERALISATION_SPLITS if s != "inrange" or s in present)


def generalisation(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per controller: mean ACE/L, return and success on catalogue vs held-out scenarios
    (and in-range ones, ``inrange_*`` keys, when the run has them).

    Means are over the scenarios of each split on which *every* controller of the table
    ran (so that all controllers are compared on the same set; ``*_scenarios`` counts them).
    """
    controllers = list(dict.fromkeys(r["controller"] for r in rows))
    ran = {(r["scenario"], r["controller"]) for r in rows if r.get("applies", True)}
    splits = _generalisation_splits(rows)
    common = {}
    for split in splits:
        scenarios = dict.fromkeys(r["scenario"] for r in rows if r["split"] == split)
        common[split] = [s for s in scenarios if all((s, c) in ran for c in controllers)]
    out = []
    for controller in controllers:
        mine = [r for r in rows if r["controller"] == controller]
        entry: dict[str, Any] = {"controller": controller, "kind": mine[0]["kind"]}
        for split in splits:
            group = [r for r in mine if r["scenario"] in common[split]]
            entry[f"{split}_scenarios"] = len(group)
            for key in ("ace_L", "return", "success"):
                values = [r[key] for r in group if isinstance(r[key], float)]
                entry[f"{split}_{key}"] = float(np.mean(values)) if values else math.nan
        out.append(entry)
    return out


def generalisation_table(rows: list[dict[str, Any]]) -> str:
    """Markdown of :func:`generalisation` (empty when the suite has no held-out or in-range
    scenarios)."""
    if not any(r["split"] in TEST_SPLITS for r in rows):
        return ""
    gen = generalisation(rows)
    splits = _generalisation_splits(rows)
    label = {"catalogue": "catalogue", "heldout": "held-out", "inrange": "in-range"}
    counts = ", ".join(f"{gen[0][f'{s}_scenarios']} {label[s]}" for s in splits)
    header = ["controller", "kind"] + [
        f"{what} {label[s]}" for what in ("ACE/L", "return", "success") for s in splits
    ]
    title = " vs ".join(label[s] for s in splits)
    lines = [
        f"\n## Generalisation: {title} scenarios\n\nMeans over the scenarios "
        f"of each split on which every controller ran ({counts}).\n",
        "| " + " | ".join(header) + " |",
        "|" + "---|" * len(header),
    ]
    for g in gen:
        cells = [md_cell(g["controller"]), md_cell(g["kind"])]
        cells += [
            _fmt(g[f"{split}_{key}"]) for key in ("ace_L", "return", "success") for split in splits
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def markdown_table(rows: list[dict[str, Any]]) -> str:
    """The per-row table: mean ± std over each row's episodes, ACE and return with their
    95 % intervals."""
    head = [
        "scenario",
        "controller",
        "kind",
        "seeds",
        "ACE [m]",
        "ACE 95 % CI",
        "ACE/L",
        "t_c [s]",
        "return",
        "return 95 % CI",
        "rudder travel [rad]",
        "J",
        "success",
        "compute [ms]",
        "training",
    ]
    keys = ["ace_L", "t_c", "return", "rudder_travel", "J", "success", "compute_ms"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        cells = [md_cell(r["scenario"]), md_cell(r["controller"]), md_cell(r["kind"])]
        if not r.get("applies", True):
            lines.append("| " + " | ".join(cells + ["does not apply"] + [""] * 11) + " |")
            continue
        seeds = str(r["seeds"])
        if r.get("training_seeds"):
            seeds += f" × {r['training_seeds']} trained"
        values = {k: _fmt(r[k], r.get(f"{k}_std")) for k in ("ace", *keys)}
        cells += [seeds, values["ace"], _ci(r.get("ace_ci95")), values["ace_L"], values["t_c"]]
        cells += [values["return"], _ci(r.get("return_ci95"))]
        cells += [values[k] for k in ("rudder_travel", "J", "success", "compute_ms")]
        cost = ""
        if "train_env_steps" in r:
            cost = f"{r['train_env_steps'] / 1e3:.0f} k steps, {r['train_wall_s'] / 60:.1f} min"
        cells.append(cost)
        lines.append("| " + " | ".join(cells) + " |")
    note = (
        "\nMean ± std over each row's episodes (evaluation seeds; × training seeds for a "
        "learned agent), with the 95 % bootstrap interval of the mean (stratified over "
        "training seeds; every metric's is in leaderboard.json as *_ci95). t_c: moment (s of "
        "simulation time) from which |e| stays below the threshold after the first parameter "
        "change; 'never' when it does not. training: env steps and wall time of a learned "
        "agent's training run (mean over its training seeds).\n"
    )
    return "\n".join(lines) + "\n" + note


def _ci(ci: Any) -> str:
    return f"[{ci[0]:.3f}, {ci[1]:.3f}]" if ci else "–"


# --- figures ---------------------------------------------------------------------------------


def plot_file(scenario: str) -> str:
    """The plot's file name for a scenario: inside the run's folder, whatever the scenario is
    (``heldout:0`` → ``heldout_0.png``, a YAML path → its stem)."""
    name = Path(scenario).stem if is_path(scenario) else scenario
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) + ".png"


def plot_results(
    results: list[EpisodeResult],
    out: Path,
    scenarios: Mapping[str, Any] | None = None,
    randomize: Mapping[str, Any] | None = None,
) -> list[Path]:
    """Per scenario: tracks over the path, e(t) and δ(t) of the first evaluation seed (of
    the first training seed) of each controller whose trajectory was kept; returns the
    files written (:func:`plot_file`).  ``scenarios``: name → settings (as ``run.json``
    records them; default: each scenario loaded by name); ``randomize``: the trial
    randomisation (the jump time drawn is that seed's)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    randomization = None if randomize is None else TrialRandomization(**randomize)
    written = []
    for scenario in sorted({r.scenario for r in results if r.trajectory}):
        first: dict[str, EpisodeResult] = {}
        for r in sorted(results, key=_order):
            if r.scenario == scenario and r.trajectory:
                first.setdefault(r.controller, r)
        seed = min(r.seed for r in first.values())
        sc = load_scenario(scenarios[scenario] if scenarios else scenario)
        sc = trial_scenario(sc, randomization, seed)
        fig, axes = plt.subplots(1, 3, figsize=(15, 4))
        pts = sc.path.point(np.linspace(0, sc.path.length, 300))
        axes[0].plot(pts[:, 0], pts[:, 1], "k--", lw=1, label="path")
        for name, r in first.items():
            tr, look, label = r.trajectory, controller_style(name).kwargs(), plain_text(name)
            axes[0].plot(tr["x"], tr["y"], lw=1, label=label, **look)
            axes[1].plot(tr["t"], tr["cross_track_error"], lw=1, label=label, **look)
            axes[2].plot(tr["t"], np.degrees(tr["rudder_angle"]), lw=1, label=label, **look)
        if sc.change_time is not None:
            for ax in axes[1:]:
                ax.axvline(sc.change_time, color="gray", ls=":", lw=1)
        title = f"{plain_text(scenario)}: tracks (seed {seed})"
        axes[0].set(xlabel="x [m]", ylabel="y [m]", title=title)
        axes[0].set_aspect("equal", adjustable="datalim")
        axes[1].set(xlabel="t [s]", ylabel="e [m]", title="cross-track error")
        axes[2].set(xlabel="t [s]", ylabel="δ [deg]", title="rudder angle")
        axes[0].legend(fontsize=7)
        fig.tight_layout()
        image = io.BytesIO()
        fig.savefig(image, format="png", dpi=FIGURE_DPI)
        plt.close(fig)
        written.append(out / plot_file(scenario))
        write_bytes(written[-1], image.getvalue())
    return written
