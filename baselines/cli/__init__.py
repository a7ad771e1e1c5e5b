"""The ``shipgym`` console script (SPEC §9b).

``--json`` prints exactly one JSON document on stdout; progress and tables go to stderr.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable

from baselines.cli import (
    bench,
    leaderboard,
    manoeuvre,
    references,
    report,
    reproduce,
    run,
    scenarios,
    train,
)
from shipgym.errors import ShipgymError

#: the subcommands' parser builders, in the order ``shipgym --help`` lists them
SUBCOMMANDS: tuple[Callable[[argparse._SubParsersAction], None], ...] = (
    leaderboard.add_leaderboard_parser,
    reproduce.add_parser,
    train.add_parser,
    leaderboard.add_evaluate_parser,
    run.add_parser,
    report.add_parser,
    manoeuvre.add_parser,
    scenarios.add_parser,
    bench.add_parser,
    references.add_parser,
)

#: exit code of a bad input (a :class:`ShipgymError`), as argparse's own usage errors
EXIT_USAGE = 2
#: exit code after Ctrl-C (128 + SIGINT)
EXIT_INTERRUPTED = 130


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="shipgym", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    for add_parser in SUBCOMMANDS:
        add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run one subcommand; a :class:`ShipgymError` (bad input) prints one line and exits 2,
    any other exception is a bug and keeps its traceback."""
    parser = build_parser()
    args = parser.parse_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)  # a run's record keeps it
    from baselines.learned.trust import trusting_pickle

    try:
        with trusting_pickle(getattr(args, "trust_pickle", False)):
            return int(args.func(args))
    except ShipgymError as exc:
        sys.stderr.write(f"shipgym {args.command}: error: {exc}\n")
        return EXIT_USAGE
    except KeyboardInterrupt as exc:  # a run says what it kept (baselines.runs.RunInterrupted)
        detail = f": {exc}" if str(exc) else ""
        sys.stderr.write(f"shipgym {args.command}: interrupted{detail}\n")
        return EXIT_INTERRUPTED


__all__ = ["build_parser", "main"]
