"""``shipgym references``: fill the privileged references' tables for suites' trials.

The tables (:mod:`shipgym_baselines.references`, one per reference: ``oracle`` and
``oracle_frozen``) ship with the package; the leaderboard reads them and runs a reference
only for a trial its table lacks.  This command runs each reference of ``--reference``
(default: both) on every trial of the given suites (scenarios × the suite's seeds, the
in-range ones × its ``inrange_seeds``, drawn with its ``randomize`` ranges) and, with
``--validation``, the ``oracle`` on the validation split
that ``shipgym tune`` scores on (:func:`~shipgym_baselines.tuning.validation.validation_trials`;
tuning needs no other reference), that its table does not hold yet.  It writes a table after
every episode, so an interrupted fill resumes where it stopped.  ``--table PATH`` writes
another file (one reference, the ``oracle`` unless ``--reference`` names another; default: the
shipped tables, inside the installed package).
Without ``--suite`` and ``--validation`` it fills the default suite's trials.
"""

from __future__ import annotations

import argparse
import sys
import time
from contextlib import closing

from shipgym_baselines.cli.options import add_json_option, emit
from shipgym_baselines.ranking import ORACLE, ORACLE_FROZEN

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
    p.add_argument(
        "--table", default=None, help="the table file, one --reference only (default: shipped)"
    )
    add_json_option(
        p, "print {computed, held, wall_s, table, tables} as JSON (table: the first reference's)"
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import os

    from shipgym_baselines.errors import RunError, check_seeds
    from shipgym_baselines.evaluation import EVAL_SEED_OFFSET
    from shipgym_baselines.leaderboard import Job, iter_results, suite_scenario, trials
    from shipgym_baselines.references import ReferenceTable, announce
    from shipgym_baselines.suite import load_suite

    if args.reference is None:
        chosen = [ORACLE] if args.table is not None else list(REFERENCES)
    else:
        chosen = list(dict.fromkeys(args.reference))
    if args.table is not None and len(chosen) != 1:
        raise RunError(f"--table names one file: give one --reference, not {chosen}")
    tables = {ref: ReferenceTable.load(args.table, ref) for ref in chosen}
    jobs, trial_of, held = [], {}, 0
    todo: dict[str, list] = {ref: [] for ref in chosen}

    def add(reference: str, job: Job, name: str, seed: int, trial) -> None:
        nonlocal held
        if tables[reference].lookup(trial, seed) is not None:
            held += 1
        elif (reference, name, seed) not in trial_of:
            trial_of[(reference, name, seed)] = trial
            todo[reference].append(trial)
            jobs.append(job)

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
                    add(ref, job, scenario, seed, trial)
    if args.validation and ORACLE in chosen:
        from shipgym_baselines.tuning.validation import validation_trials

        for v in validation_trials():
            # the trial as resolved settings: the job runs exactly this scenario
            settings = v.scenario.config.model_dump(mode="json")
            job = Job(ORACLE, v.name, (v.seed,), None, None, settings, references="recompute")
            add(ORACLE, job, v.name, v.seed, v.scenario)
    if args.validation and ORACLE not in chosen:
        sys.stderr.write("references: --validation fills the oracle's table only: ignored\n")
    for ref in chosen:
        announce(todo[ref], f"written to {tables[ref].path} after each", ref)
    start = time.perf_counter()
    done = 0
    with closing(iter_results(jobs, "local", args.workers or os.cpu_count() or 1)) as results:
        for batch in results:
            for result in batch:
                ref = result.controller
                tables[ref].add(trial_of[(ref, result.scenario, result.seed)], result)
                tables[ref].save(args.table)
                done += 1
                sys.stderr.write(
                    f"references: {done}/{len(jobs)} {ref} {result.scenario} seed "
                    f"{result.seed}: cost {result.metrics.get('cost')}\n"
                )
    for ref in chosen:
        if not todo[ref]:
            tables[ref].save(args.table)  # written once: a table of another revision is replaced
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
