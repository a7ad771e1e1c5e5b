"""``shipgym references``: fill the oracle's reference table for suites' trials.

The table (:mod:`shipgym_baselines.references`) ships with the package; the leaderboard reads it and
runs the oracle only for a trial it lacks.  This command runs the oracle on every trial of
the given suites (scenarios × the suite's seeds, drawn with its ``randomize`` ranges) and,
with ``--validation``, of the validation split that ``shipgym tune`` scores on
(:func:`~shipgym_baselines.tuning.validation.validation_trials`), that the table does not
hold yet.  It writes the table after every episode, so an interrupted fill resumes where
it stopped.  ``--table PATH`` writes another file (default: the shipped one, inside the
installed package).  Without ``--suite`` and ``--validation`` it fills the default suite's
trials.
"""

from __future__ import annotations

import argparse
import sys
import time
from contextlib import closing

from shipgym_baselines.cli.options import add_json_option, emit


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("references", help="fill the oracle's reference table for suites' trials")
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
    p.add_argument("--table", default=None, help="the table file (default: the shipped one)")
    add_json_option(p, "print {computed, held, wall_s, table} as JSON")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import os

    from shipgym_baselines.errors import check_seeds
    from shipgym_baselines.evaluation import EVAL_SEED_OFFSET
    from shipgym_baselines.leaderboard import Job, iter_results, suite_scenario, trials
    from shipgym_baselines.privileged import ORACLE
    from shipgym_baselines.references import ReferenceTable, announce
    from shipgym_baselines.suite import load_suite

    table = ReferenceTable.load(args.table)
    jobs, trial_of, held = [], {}, 0
    suites = args.suite if args.suite is not None else ([] if args.validation else ["default"])
    for name in suites:
        spec = load_suite(name)
        n = int(args.seeds if args.seeds is not None else spec.seeds)
        check_seeds(n, "--seeds")
        randomize = None if spec.randomize is None else spec.randomize.model_dump(mode="json")
        for scenario in spec.all_scenarios():
            suite_scenario(scenario)  # a bad name fails here, before any work
            for seed in (EVAL_SEED_OFFSET + i for i in range(n)):
                job = Job(ORACLE, scenario, (seed,), None, randomize, references="recompute")
                (trial,) = trials(job)
                if table.lookup(trial, seed) is not None:
                    held += 1
                elif (scenario, seed) not in trial_of:
                    trial_of[(scenario, seed)] = trial
                    jobs.append(job)
    if args.validation:
        from shipgym_baselines.tuning.validation import validation_trials

        for v in validation_trials():
            # the trial as resolved settings: the job runs exactly this scenario
            settings = v.scenario.config.model_dump(mode="json")
            job = Job(ORACLE, v.name, (v.seed,), None, None, settings, references="recompute")
            if table.lookup(v.scenario, v.seed) is not None:
                held += 1
            elif (v.name, v.seed) not in trial_of:
                trial_of[(v.name, v.seed)] = v.scenario
                jobs.append(job)
    announce(list(trial_of.values()), f"written to {table.path} after each")
    start = time.perf_counter()
    done = 0
    with closing(iter_results(jobs, "local", args.workers or os.cpu_count() or 1)) as results:
        for batch in results:
            for result in batch:
                table.add(trial_of[(result.scenario, result.seed)], result)
                table.save(args.table)
                done += 1
                sys.stderr.write(
                    f"references: {done}/{len(jobs)} {result.scenario} seed {result.seed}: "
                    f"cost {result.metrics.get('cost')}\n"
                )
    if not jobs:
        table.save(args.table)  # written once: a table of another env revision is replaced
    wall = time.perf_counter() - start
    summary = {"computed": done, "held": held, "wall_s": wall, "table": str(table.path)}
    emit(args, summary, f"references: {done} computed, {held} held, {wall:.0f} s: {table.path}")
    return 0
