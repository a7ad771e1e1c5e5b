"""The leaderboard's work: a :class:`Job` per controller and scenario, the plan of a run's
jobs, and the functions a worker runs (locally in a process pool or on a Ray cluster)."""

from __future__ import annotations

import functools
import json
import math
from collections import defaultdict
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any, NamedTuple

from shipgym.config import is_path
from shipgym.scenarios.loader import Scenario, load_scenario
from shipgym.scenarios.trials import seed_trials
from shipgym_baselines import evaluation
from shipgym_baselines.errors import RunError
from shipgym_baselines.evaluation import ACT_TIMEOUT_S
from shipgym_baselines.executor import map_jobs
from shipgym_baselines.isolation import isolated, run_isolated
from shipgym_baselines.leaderboard.twins import plan_twins, twin_record
from shipgym_baselines.plugins import ControllerSpec
from shipgym_baselines.privileged import ORACLE, grants_truth
from shipgym_baselines.records.episodes import EpisodeLabel, EpisodeResult, controller_failed
from shipgym_baselines.records.trials import (
    LEARNED_TRIALS,
    SHARED,
    TWIN_PLAYERS,
    TWIN_SCENARIOS,
    deal_names,
    dealt_owners,
    shares_trials,
    twin_scenarios,
)
from shipgym_baselines.references import ReferenceCache, announce, lookup, result_from_entry
from shipgym_baselines.registry import (
    ControllerRef,
    applies_to,
    controller_label,
    resolve_controller,
)
from shipgym_baselines.signals import worker_init
from shipgym_baselines.suite import scenario_names


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


class Job(NamedTuple):
    """One unit of work: a controller (trained with ``training_seed``; None: not trained;
    its record as :func:`plan_jobs` resolved it, or a name resolved where it runs)
    on the trials of scenario ``scenario`` (its table name, :func:`suite_scenarios`; or a
    catalogue name, held-out name or YAML path loaded as such) that ``seeds``
    draw with ``randomize`` (a :class:`~shipgym.scenarios.trials.TrialRandomization` as a dict;
    None: no trials).
    ``settings``: the scenario as the run resolved it at its start (``run.json``'s), run
    as recorded whatever its file says now; None: resolved from ``scenario`` here.  The
    evaluation loop labels the job's episodes with :attr:`label`."""

    controller: ControllerRef
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
    #: a learned agent whose training seeds share the trials: the training seed that plays
    #: each of ``seeds`` (``training_seed`` is then None); the job runs them all in lockstep
    dealt: tuple[int | None, ...] | None = None

    @property
    def label(self) -> EpisodeLabel:
        """What the job's episodes are labelled with: the scenario's table name (not its
        trials'), the controller's table name and the job's training seed (None: the
        policy's own; a dealt job's episodes each carry their own, :meth:`runs`)."""
        return EpisodeLabel(self.scenario, controller_label(self.controller), self.training_seed)

    def runs(self) -> list[tuple[int, int | None]]:
        """(evaluation seed, training seed) of each of the job's episodes."""
        owners = self.dealt if self.dealt is not None else [self.training_seed] * len(self.seeds)
        return list(zip(self.seeds, owners, strict=True))


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
    """A suite's scenarios (as :func:`~shipgym_baselines.suite.load_suite` gives them)
    by table name: a catalogue or held-out name as given, a YAML file's under its ``name:``
    (:func:`~shipgym_baselines.suite.scenario_names`: a name that clashes is refused,
    naming both files)."""
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
    return seed_trials(job_scenario(job), job.randomize, job.seeds)


def run_job(job: tuple) -> EpisodeResult:
    """One episode ``(controller, scenario, seed[, training_seed[, randomize]])`` (see
    :class:`Job`); top-level so process pools can pickle it."""
    one = Job(job[0], job[1], (int(job[2]),), *job[3:])
    (trial,) = trials(one)
    (result,) = evaluation.evaluate(
        one.controller,
        trial,
        list(one.seeds),
        training_seed=one.training_seed,
        guard=_guard(one),
        label=one.label,
    )
    return result


def _guard(job: Job) -> evaluation.ActGuard:
    """How the job's episodes end when their controller fails: a privileged reference is
    never judged as an entrant (no time limit; a failed episode of it is recorded, and
    never a denominator: :func:`~shipgym_baselines.scoring.scores.scored_episodes`)."""
    if grants_truth(job.controller):
        return evaluation.ActGuard(math.inf)
    return evaluation.ActGuard(job.act_timeout)


def run_batch(job: Job) -> list[EpisodeResult]:
    """The job's episodes, all seeds at once (:func:`shipgym_baselines.evaluation.evaluate_batch`),
    in the order of ``job.seeds``; a dealt job's each by its own training seed."""
    return evaluation.evaluate_batch(
        job.controller,
        trials(job),
        list(job.seeds),
        training_seed=job.training_seed,
        guard=_guard(job),
        label=job.label,
        training_seeds=job.dealt,
    )


def reference_work(job: Job) -> list[EpisodeResult]:
    """A privileged reference's episodes of ``job`` (``oracle`` or ``oracle_frozen``): each
    trial's entry of the reference's shipped table or of its per-user cache
    (:mod:`shipgym_baselines.references`), the reference run for a trial both lack (and
    stored in the cache)."""
    label = job.label
    reference = label.controller
    cache, out = ReferenceCache(reference=reference), []
    for seed, trial in zip(job.seeds, trials(job), strict=True):
        entry = lookup(trial, seed, cache, reference)
        if entry is not None:
            out.append(result_from_entry(entry, job.scenario, seed, reference))
        else:
            (result,) = evaluation.evaluate(
                job.controller, trial, [seed], guard=_guard(job), label=label
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
    single seed through :func:`run_job`, several through :func:`run_batch`; a controller
    whose code is not the benchmark's own plays them in a process of its own
    (:mod:`shipgym_baselines.isolation`: a call that never ends, or a process that ends,
    fails the job's episodes, not the run)."""
    if job.references == "table" and grants_truth(job.controller):
        return reference_work(job)
    if isolated(job.controller):
        failed = functools.partial(failed_episodes, job)
        return run_isolated(play, job, failed, _guard(job).setup_timeout)
    return play(job)


def play(job: Job) -> list[EpisodeResult]:
    """:func:`work`'s episodes of a controller: a single seed through :func:`run_job`,
    several through :func:`run_batch` (top-level: a child process runs it)."""
    if len(job.seeds) == 1 and job.dealt is None:
        return [run_job((job.controller, job.scenario, job.seeds[0], *job[3:]))]
    return run_batch(job)


def failed_episodes(job: Job, reason: str, error: str) -> list[EpisodeResult]:
    """Every episode of ``job`` failed with ``reason`` and ``error`` at its reset (its
    process ended without its results: :func:`~shipgym_baselines.evaluation.failed_episode`),
    in the order :func:`play` gives them."""
    guard, name = _guard(job), job.label.controller
    return [
        evaluation.failed_episode(
            job.controller,
            trial,
            seed,
            reason,
            error,
            guard,
            EpisodeLabel(job.scenario, name, training_seed),
        )
        for (seed, training_seed), trial in zip(job.runs(), trials(job), strict=True)
    ]


def iter_results(jobs: list[Job], backend: str, workers: int) -> Iterator[list[EpisodeResult]]:
    """The results of ``jobs`` on ``backend`` (:data:`~shipgym_baselines.executor.BACKENDS`), job
    by job in completion
    order (in turn, or in a pool of ``workers`` processes started with
    :func:`shipgym_baselines.signals.worker_init`; :mod:`shipgym_baselines.executor`)."""
    return map_jobs(work, jobs, backend, workers, initializer=worker_init)


def result_key(result: EpisodeResult) -> tuple[str, str, int, int | None]:
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
    the scenarios run on fewer,
    :meth:`~shipgym_baselines.suite.SuiteConfig.scenario_seeds`),
    the trial randomisation, controllers (table name, how the suite names it, kind, training seeds),
    each scenario's settings (by table name), the pairs that do not apply, when the
    suite has its own scenarios ``scenario_files`` (table name → the YAML file read) and,
    unless the suite turns them off, the no-change twins (``twins``, ``twin_scenarios``,
    ``twin_players``: :mod:`shipgym_baselines.leaderboard.twins`)."""
    ships = {s: sc.model.name for s, sc in scenarios.items()}
    controllers = []
    for c in names:
        record = resolve_controller(c)
        controllers.append(
            {
                "name": record.name,
                "controller": c if isinstance(c, str) else c.model_dump(),  # the long form
                "kind": record.kind,
                "training_seeds": list(seeds_of[record.name]),
            }
        )
    files = scenario_names(spec.all_scenarios(), suite_scenario).files
    own = {"scenario_files": {n: f for n, f in files.items() if n in scenarios}}
    fewer = {s: v for s, v in spec.scenario_seeds(seed_list).items() if s in scenarios}
    shared = {LEARNED_TRIALS: SHARED} if spec.learned_trials == SHARED else {}
    twins: dict[str, Any] = {}
    if spec.twins:
        of, new = plan_twins(scenarios, {s: fewer.get(s, seed_list) for s in scenarios})
        players = [c["name"] for c in controllers if is_twin_player(c["name"], c["kind"])]
        twins = {**twin_record(of, new), TWIN_PLAYERS: players} if of else {}
        for name, twin in new.items():
            first = next(s for s, t in of.items() if t == name)
            if first in fewer:
                fewer[name] = fewer[first]
            ships[name] = twin.model.name
    skip = [
        [s, c["name"]]
        for s in [*scenarios, *twins.get(TWIN_SCENARIOS, {})]
        for c in controllers
        if not applies_to(c["name"], ships[s])
    ]
    return {
        "name": spec.name,
        "seeds": seed_list,
        **({"scenario_seeds": fewer} if fewer else {}),  # absent without: older records resume
        **shared,  # absent: every training seed plays every seed (and older records resume)
        "randomize": None if spec.randomize is None else spec.randomize.model_dump(mode="json"),
        "controllers": controllers,
        "scenarios": {s: sc.config.model_dump(mode="json") for s, sc in scenarios.items()},
        "does_not_apply": skip,
        **(own if own["scenario_files"] else {}),  # absent without: older records resume
        **twins,  # absent: a run without twins (and older records resume)
    }


def is_twin_player(name: str, kind: str) -> bool:
    """Whether a controller of a run plays the twins: every competitor, and the ``oracle``
    (the other references never: the optimum that never adapts costs what the oracle does on
    a trial without a change)."""
    return kind != "reference" or name == ORACLE


def plan_jobs(
    names: list[ControllerSpec],
    scenarios: Iterable[str] | Mapping[str, dict[str, Any]],
    seed_list: list[int],
    seeds_of: Mapping[str, list[int | None]],
    randomize: dict[str, Any] | None,
    skip: set[tuple[str, str]],
    references: str = "table",
    scenario_seeds: Mapping[str, list[int]] | None = None,
    shared: bool = False,
    deal: Mapping[str, str] | None = None,
) -> list[Job]:
    """Every job of a run: per scenario and controller that applies, one job of all seeds
    per training seed (a learned agent's; with ``shared`` one job of all seeds, each played
    by the training seed :func:`~shipgym_baselines.records.trials.dealt_owners` deals it,
    :attr:`Job.dealt`) or of all seeds (a classical controller's: they run in lockstep,
    :func:`run_batch`), one job per seed for the
    privileged oracle (its reference table is looked up trial by trial).  ``scenarios``:
    names, or name → recorded settings (the jobs run those); ``scenario_seeds``: the
    scenarios run on other seeds than ``seed_list``, with theirs; ``deal``: the name each
    scenario's trials are dealt by (default: its own;
    :func:`~shipgym_baselines.records.trials.deal_names`)."""
    records = [resolve_controller(c) for c in names]  # once: each job carries its record
    jobs = []
    for scenario in scenarios:
        settings = scenarios[scenario] if isinstance(scenarios, Mapping) else None
        seeds = list((scenario_seeds or {}).get(scenario, seed_list))
        for c in records:
            label = c.name
            if (scenario, label) in skip:
                continue
            learned = c.kind == "learned"
            if learned and shared:  # one job: each seed played by the training seed dealt it
                by = (deal or {}).get(scenario, scenario)
                dealt = tuple(dealt_owners(by, seeds, seeds_of[label]))
                jobs.append(Job(c, scenario, tuple(seeds), None, randomize, settings, dealt=dealt))
                continue
            for k in seeds_of[label]:
                if learned:
                    jobs.append(Job(c, scenario, tuple(seeds), k, randomize, settings))
                elif not c.privileged:
                    jobs.append(Job(c, scenario, tuple(seeds), k, randomize, settings, references))
                else:
                    jobs += [
                        Job(c, scenario, (seed,), k, randomize, settings, references)
                        for seed in seeds
                    ]
    return jobs


def plan_run(
    names: list[ControllerSpec],
    record: Mapping[str, Any],
    seeds_of: Mapping[str, list[int | None]],
    references: str = "table",
) -> list[Job]:
    """The jobs of a run whose resolved suite is ``record`` (:func:`suite_record`, as
    ``run.json`` keeps it): :func:`plan_jobs` on its scenarios' recorded settings, seeds,
    randomisation, the pairs that do not apply and its deal of learned trials, then on the
    twins that are no scenario of the run, by the controllers that play them."""
    args = (
        list(record["seeds"]),
        seeds_of,
        record["randomize"],
        {tuple(pair) for pair in record["does_not_apply"]},
        references,
        record.get("scenario_seeds"),
        shares_trials(record),
        deal_names(record),
    )
    jobs = plan_jobs(names, record["scenarios"], *args)
    twins = twin_scenarios(record)
    if twins:
        players = set(record.get(TWIN_PLAYERS, []))
        jobs += plan_jobs([c for c in names if controller_label(c) in players], twins, *args)
    return jobs


def run_scenarios(
    record: Mapping[str, Any], scenarios: Mapping[str, Scenario]
) -> dict[str, Scenario]:
    """``scenarios`` (the run's, by table name) and the twins of ``record`` that are no
    scenario of the run, built from their recorded settings."""
    twins = {t: _recorded_scenario(json.dumps(s, sort_keys=True)) for t, s in
             twin_scenarios(record).items()}  # fmt: skip
    return {**scenarios, **twins}


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
        runs = [(s, k) for s, k in job.runs() if (job.scenario, label, s, k) not in done]
        if runs:
            seeds = tuple(s for s, _ in runs)
            dealt = None if job.dealt is None else tuple(k for _, k in runs)
            todo.append(job._replace(seeds=seeds, dealt=dealt))
    return todo
