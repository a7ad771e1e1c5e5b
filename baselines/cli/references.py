"""``shipgym references``: fill the privileged references' tables for suites' trials.

The tables (:mod:`shipgym_baselines.references`, one per reference: ``oracle`` and
``oracle_frozen``) ship with the package; the leaderboard reads them, then the per-user
cache, and runs a reference only for a trial neither holds.  This command runs each
reference of ``--reference`` (default: both) on every trial of the given suites (scenarios ×
the suite's seeds, the held-out and in-range ones × its ``heldout_seeds`` and
``inrange_seeds``, drawn with its ``randomize``
ranges), the ``oracle`` on the twins of the suite's changing scenarios that are no
scenario of the suite (:mod:`shipgym_baselines.leaderboard.twins`) and, with
``--validation``, the ``oracle`` on the validation split that ``shipgym
tune`` scores on (:func:`~shipgym_baselines.tuning.validation.validation_trials`; tuning
needs no other reference), that its target does not hold yet.  It writes after every
episode, so an interrupted fill resumes where it stopped.  Without ``--suite`` and
``--validation`` it fills the default suite's trials.

Where the episodes go:

- by default, the per-user cache (:func:`~shipgym_baselines.references.user_cache_path`),
  which every later leaderboard and study reads; a trial the shipped table holds is not
  computed again;
- ``--packaged``: the shipped tables inside the installed package (what every leaderboard
  then reads first);
- ``--table FILE``: that file (one reference, the ``oracle`` unless ``--reference`` names
  another).

A ``--packaged`` or ``--table`` file is locked while it is filled
(:func:`~shipgym_baselines.records.locking.file_lock`, ``<file>.lock`` beside it): a second
fill of the same file is refused in one line naming the first.  It is written through no
link (:func:`~shipgym_baselines.records.outfiles.write_bytes`): a link in its place is
refused in one line.

A ``--packaged`` or ``--table`` file of another env revision, reference, oracle revision or
oracle settings is refused in one line unless ``--replace``, which keeps the old file as
``FILE.bak`` (never overwriting another one) and starts it afresh
(:func:`~shipgym_baselines.references.fill_tables`).
"""

from __future__ import annotations

import argparse
import sys
import time
from contextlib import closing
from typing import Any

from shipgym_baselines.cli.options import add_json_option, emit
from shipgym_baselines.privileged import ORACLE, ORACLE_FROZEN

#: the references with a table (:data:`shipgym_baselines.references.REFERENCES`)
REFERENCES = (ORACLE, ORACLE_FROZEN)


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "references", help="fill the privileged references' tables for suites' trials"
    )
    p.add_argument(
        "--suite", nargs="+", default=None, metavar="SUITE", help="suites (default: default)"
    )
    p.add_argument(
        "--validation",
        action="store_true",
        help="the validation split's trials too (those `shipgym tune` scores on)",
    )
    p.add_argument("--seeds", type=int, default=None, help="evaluation seeds (default: suite's)")
    p.add_argument("--workers", type=int, default=None, help="processes (default: the cores)")
    p.add_argument(
        "--reference",
        nargs="+",
        choices=REFERENCES,
        default=None,
        help="the references to fill (default: all; with --table: oracle)",
    )
    where = p.add_mutually_exclusive_group()
    where.add_argument(
        "--packaged",
        action="store_true",
        help="write the shipped tables inside the installed package (what every leaderboard "
        "then reads); default: the per-user cache",
    )
    where.add_argument(
        "--table",
        default=None,
        help="write this table file, one --reference only (default: the per-user cache)",
    )
    p.add_argument(
        "--replace",
        action="store_true",
        help="replace a --packaged or --table file of another revision or settings, keeping "
        "the old one as FILE.bak",
    )
    add_json_option(
        p, "print {computed, held, wall_s, table, tables} as JSON (table: the first reference's)"
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import contextlib
    import functools

    from shipgym_baselines.errors import RunError, check_seeds
    from shipgym_baselines.evaluation import EVAL_SEED_OFFSET
    from shipgym_baselines.leaderboard.jobs import Job, suite_scenario, suite_scenarios, trials
    from shipgym_baselines.leaderboard.twins import plan_twins
    from shipgym_baselines.records.locking import file_lock
    from shipgym_baselines.records.runrecord import now
    from shipgym_baselines.references import (
        ReferenceCache,
        fill_tables,
        lookup,
        table_path,
    )
    from shipgym_baselines.suite import load_suite

    if args.reference is None:
        chosen = [ORACLE] if args.table is not None else list(REFERENCES)
    else:
        chosen = list(dict.fromkeys(args.reference))
    if args.table is not None and len(chosen) != 1:
        raise RunError(f"--table names one file: give one --reference, not {chosen}")
    candidates: list[tuple[str, Job, str, int, Any]] = []  # reference, job, name, seed, trial
    suites = args.suite if args.suite is not None else ([] if args.validation else ["default"])
    for name in suites:
        spec = load_suite(name)
        n = int(args.seeds if args.seeds is not None else spec.seeds)
        check_seeds(n, "--seeds")
        randomize = None if spec.randomize is None else spec.randomize.model_dump(mode="json")
        seeds = [EVAL_SEED_OFFSET + i for i in range(n)]
        fewer = spec.scenario_seeds(seeds)
        for scenario in spec.all_scenarios():
            suite_scenario(scenario)  # a bad name fails here, before any work
            for seed in fewer.get(scenario, seeds):
                for ref in chosen:
                    job = Job(ref, scenario, (seed,), None, randomize, references="recompute")
                    (trial,) = trials(job)
                    candidates.append((ref, job, scenario, seed, trial))
        if spec.twins and ORACLE in chosen:  # the oracle plays the twins, no other reference
            scenarios = suite_scenarios(spec.all_scenarios())
            seeds_of = {s: fewer.get(s, seeds) for s in scenarios}
            of, new = plan_twins(scenarios, seeds_of)
            for twin, scenario in new.items():
                settings = scenario.config.model_dump(mode="json")
                first = next(s for s, t in of.items() if t == twin)
                for seed in seeds_of[first]:
                    job = Job(ORACLE, twin, (seed,), None, randomize, settings, "recompute")
                    (trial,) = trials(job)
                    candidates.append((ORACLE, job, twin, seed, trial))
    if args.validation and ORACLE in chosen:
        from shipgym_baselines.tuning.validation import validation_trials

        for v in validation_trials():
            # the trial as resolved settings: the job runs exactly this scenario
            settings = v.scenario.config.model_dump(mode="json")
            job = Job(ORACLE, v.name, (v.seed,), None, None, settings, references="recompute")
            candidates.append((ORACLE, job, v.name, v.seed, v.scenario))
    if args.validation and ORACLE not in chosen:
        sys.stderr.write("references: --validation fills the oracle's table only: ignored\n")
    with contextlib.ExitStack() as locks:
        if args.table is not None or args.packaged:
            files = {r: args.table if args.table is not None else table_path(r) for r in chosen}
            option = "--table" if args.table is not None else "--packaged"
            for file in files.values():  # one fill per file: a second is refused in one line
                locks.enter_context(file_lock(file, now(), option))
            filled = fill_tables(files, args.replace)
            tables: dict[str, Any] = dict(filled)
            holds = {ref: filled[ref].lookup for ref in chosen}
        else:
            caches = {ref: ReferenceCache(reference=ref) for ref in chosen}
            tables = dict(caches)
            holds = {
                ref: functools.partial(lookup, cache=caches[ref], reference=ref) for ref in chosen
            }
            if args.replace:
                sys.stderr.write(
                    "references: --replace: a per-user cache of another revision is replaced "
                    "anyway (it holds only computed references): ignored\n"
                )
        start = time.perf_counter()
        done, held = _fill(candidates, chosen, tables, holds, args.workers)
    wall = time.perf_counter() - start
    paths = {ref: str(tables[ref].path) for ref in chosen}
    summary = {
        "computed": done,
        "held": held,
        "wall_s": wall,
        "table": paths[chosen[0]],
        "tables": paths,
    }
    where = ", ".join(paths.values())
    emit(args, summary, f"references: {done} computed, {held} held, {wall:.0f} s: {where}")
    return 0


def _fill(
    candidates: list[tuple[str, Any, str, int, Any]],
    chosen: list[str],
    tables: dict[str, Any],
    holds: dict[str, Any],
    workers: int | None,
) -> tuple[int, int]:
    """Run each reference on the candidate trials its table does not hold, storing each
    episode as it ends; (episodes computed, trials held already)."""
    import os

    from shipgym_baselines.leaderboard.jobs import iter_results
    from shipgym_baselines.references import announce

    jobs, trial_of, held = [], {}, 0
    todo: dict[str, list] = {ref: [] for ref in chosen}
    for ref, job, name, seed, trial in candidates:
        if holds[ref](trial, seed) is not None:
            held += 1
        elif (ref, name, seed) not in trial_of:
            trial_of[(ref, name, seed)] = trial
            todo[ref].append(trial)
            jobs.append(job)
    for ref in chosen:
        announce(todo[ref], f"written to {tables[ref].path} after each", ref)
    done = 0
    with closing(iter_results(jobs, "local", workers or os.cpu_count() or 1)) as results:
        for batch in results:
            for result in batch:
                ref = result.controller
                tables[ref].store(trial_of[(ref, result.scenario, result.seed)], result)
                done += 1
                sys.stderr.write(
                    f"references: {done}/{len(jobs)} {ref} {result.scenario} seed "
                    f"{result.seed}: cost {result.metrics.get('cost')}\n"
                )
    return done, held
