"""``shipgym report DIR [DIR …]``: tables and plots rebuilt from run folders (merged)."""

from __future__ import annotations

import argparse
import sys

from shipgym_baselines.cli.options import (
    add_json_option,
    add_out_options,
    add_vector_option,
    command_line,
    emit,
)

#: where ``report`` writes unless given ``--out``
REPORT_OUT = "results/report"


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "report",
        help="rebuild the tables and plots from run folders (several: one merged table)",
    )
    p.add_argument("runs", nargs="+", metavar="DIR", help="leaderboard / evaluate output folders")
    add_out_options(
        p,
        REPORT_OUT,
        help=f"output directory (default {REPORT_OUT}; refused if not empty: see --force)",
        resume_help=None,
    )
    add_vector_option(p)
    add_json_option(p, "print the rows as JSON on stdout")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Merge the runs, write the report, print the table (or rows); say which runs were
    incomplete."""
    from shipgym_baselines.leaderboard.report import write_report

    rows, sources = write_report(
        args.runs,
        args.out,
        force=args.force,
        command=command_line(args),
        vector_figures=args.vector_figures,
    )
    from shipgym_baselines.leaderboard.outputs import terminal_summary

    for source in sources:
        if source["status"] != "complete":
            sys.stderr.write(
                f"note: {source['folder']} is {source['status']}: {source['episodes']} of "
                f"{source['jobs']} episodes\n"
            )
    if not args.json:
        sys.stderr.write(f"wrote {args.out}: leaderboard.md, .csv, .json, plots, report.json\n")
    emit(args, rows, terminal_summary(args.out))  # ends with the ranking and the page's path
    return 0
