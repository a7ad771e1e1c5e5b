"""``shipgym leaderboard`` (the suite's controllers) and ``shipgym evaluate`` (one policy)."""

from __future__ import annotations

import argparse
import sys

from baselines.cli.options import add_run_options, emit


def add_leaderboard_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("leaderboard", help="run every controller on a suite (SPEC §9)")
    add_run_options(p, out="results/leaderboard", progress_help="no progress bar on stderr")
    p.set_defaults(func=run)


def add_evaluate_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "evaluate", help="evaluate a controller or trained agent on a suite (leaderboard rows)"
    )
    p.add_argument("policy", help="controller name, shipped policy name or trained agent folder")
    add_run_options(p, out="results/evaluate")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the suite (with ``evaluate``: only ``args.policy``), print the table or rows."""
    from baselines.leaderboard import markdown_table, run_leaderboard

    policy = getattr(args, "policy", None)
    rows = run_leaderboard(
        suite=args.suite,
        seeds=args.seeds,
        out_dir=args.out,
        backend=args.backend,
        workers=args.workers,
        controllers=[policy] if policy else None,
        show_progress=not args.no_progress,
    )
    emit(args, rows, markdown_table(rows))
    if not args.json:
        sys.stderr.write(f"wrote {args.out}/leaderboard.md, .csv, .json and plots\n")
    return 0
