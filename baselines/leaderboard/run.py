"""``run_leaderboard``: plan the jobs, run them, record each episode as it arrives, then
write the tables, the ranking and the figures from the record."""

from __future__ import annotations

import math
import os
import sys
from collections import defaultdict
from collections.abc import Callable, Iterable, Mapping
from contextlib import closing
from typing import Any

from tqdm import tqdm

from shipgym.limits import worker_count
from shipgym.notices import notice
from shipgym_baselines import evaluation
from shipgym_baselines.errors import RunError, check_seeds
from shipgym_baselines.evaluation import ACT_TIMEOUT_S, EVAL_SEED_OFFSET
from shipgym_baselines.executor import check_backend
from shipgym_baselines.leaderboard.costs import eta_line
from shipgym_baselines.leaderboard.jobs import (
    Job,
    announce_references,
    check_controllers,
    iter_results,
    longest_first,
    missing,
    plan_run,
    result_key,
    run_scenarios,
    suite_record,
    suite_scenarios,
)
from shipgym_baselines.leaderboard.outputs import load_results, write_results
from shipgym_baselines.plots.scenarios import median_ace_episode
from shipgym_baselines.plugins import ControllerSpec
from shipgym_baselines.records.episodes import STATS_ERROR, EpisodeResult, controller_failed
from shipgym_baselines.records.folders import check_out_dir, check_out_usable
from shipgym_baselines.records.runlog import RunLog
from shipgym_baselines.records.runrecord import read_run
from shipgym_baselines.registry import controller_label, training_seeds
from shipgym_baselines.scoring.comparison import (
    RECORD_KEY,
    references_record,
    suite_folder,
    with_references,
)
from shipgym_baselines.suite import load_suite


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
    references (:data:`shipgym_baselines.scoring.comparison.REFERENCES`) too, those not among
    the controllers already (``run.json`` records which; a resumed run that did not add them
    does not).  ``out_dir``: default
    ``results/<suite>`` (:func:`~shipgym_baselines.scoring.comparison.suite_folder`).
    ``show_progress``: a progress bar on stderr, after one line before the first episode: the
    episodes, workers and the time estimated from the recorded costs
    (:func:`shipgym_baselines.leaderboard.costs.eta_line`).  Ctrl-C raises
    :class:`~shipgym_baselines.records.runlog.RunInterrupted`.

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
    check_backend(backend)
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
    references = "recompute" if recompute_references else "table"
    jobs = plan_run(names, record, seeds_of, references)
    scenarios = run_scenarios(record, scenarios)
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
        act_timeout=act_timeout,
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
                        if result_key(result) in log.done:
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
    """A :class:`RunError` for a limit that is not a positive finite time [s] (``run.json``
    records it) and for ``--retry-failed`` without ``--resume``."""
    evaluation.ActGuard(act_timeout)
    if not math.isfinite(act_timeout):
        raise RunError(f"--act-timeout must be a finite time in s, got {act_timeout}")
    if retry_failed and not resume:
        raise RunError("--retry-failed runs the failed episodes of a resumed run: add --resume")


def announce_failure(result: EpisodeResult, announced: set[str]) -> None:
    """One line on stderr at the first episode of a controller ended by its failure (its
    error; the run goes on), and one at the first whose figures were left out (their
    ``stats_error``); ``announced``: the controllers (and ``<name> figures``) already
    named, updated.  Said here, in the run's own process, whichever process played it."""
    why = result.metrics.get(STATS_ERROR)
    if why and f"{result.controller} figures" not in announced:
        announced.add(f"{result.controller} figures")
        notice(f"shipgym: {result.controller}'s {why}: its figures are left out, the episode kept")
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
        for seed, training_seed in job.runs():
            rows[(job.scenario, label)].add((job.scenario, label, seed, training_seed))
    return rows


def keep_drawn(log: RunLog, rows: Mapping[tuple[str, str], set[tuple]], row: tuple) -> None:
    """Once every episode of ``row`` is recorded: keep the trajectory of the episode its
    figure draws (:func:`shipgym_baselines.plots.scenarios.median_ace_episode`), remove
    the others' (all of them on a twin that is no scenario of the run: no figure draws it)."""
    keys = rows[row]
    if not keys <= log.done:
        return
    scenario, controller = row
    if scenario not in log.record["suite"]["scenarios"]:
        log.drop_trajectories(keys)
        return
    seed, training_seed = median_ace_episode([log.episodes[k] for k in keys], *row)
    log.drop_trajectories(keys - {(scenario, controller, seed, training_seed)})
