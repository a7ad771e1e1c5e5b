"""The ``shipgym`` console script: leaderboards, training, evaluation, single runs, reports,
manoeuvres, the scenario catalogue, benchmarks and the papers' experiments (documentation:
the docs site, page "Packages and commands").

``--json`` prints exactly one JSON document on stdout; progress and tables go to stderr.
"""

from __future__ import annotations

import argparse
import signal
import sys
from collections.abc import Callable

from shipgym.errors import ShipgymError
from shipgym_baselines.cli import (
    bench,
    leaderboard,
    manoeuvre,
    references,
    report,
    reproduce,
    run,
    scenarios,
    summary,
    train,
    tune,
)
from shipgym_baselines.errors import RunFailed
from shipgym_baselines.signals import Terminated, signal_number, terminate_as_interrupt

#: the subcommands' parser builders, in the order ``shipgym --help`` lists them
SUBCOMMANDS: tuple[Callable[[argparse._SubParsersAction], None], ...] = (
    leaderboard.add_leaderboard_parser,
    reproduce.add_parser,
    train.add_parser,
    tune.add_parser,
    leaderboard.add_evaluate_parser,
    run.add_parser,
    report.add_parser,
    summary.add_parser,
    manoeuvre.add_parser,
    scenarios.add_parser,
    bench.add_parser,
    references.add_parser,
)

#: exit code of a bad input (a :class:`ShipgymError`), as argparse's own usage errors
EXIT_USAGE = 2
#: exit code of a run stopped from outside (a worker killed, a full disk)
EXIT_FAILED = 1
#: exit code after a signal: 128 + its number (Ctrl-C: 130, SIGTERM: 143)
EXIT_SIGNAL = 128
#: exit code after Ctrl-C (128 + SIGINT)
EXIT_INTERRUPTED = EXIT_SIGNAL + 2


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="shipgym", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    for add_parser in SUBCOMMANDS:
        add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run one subcommand; a :class:`ShipgymError` (bad input) prints one line and exits 2,
    a :class:`~shipgym_baselines.errors.RunFailed` one line and exit 1, Ctrl-C or SIGTERM one line
    and 128 + the signal's number; any other exception is a bug and keeps its
    traceback."""
    parser = build_parser()
    args = parser.parse_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)  # a run's record keeps it
    from shipgym_baselines.learned.trust import trusting_pickle

    try:
        # SIGTERM ends a run as Ctrl-C does
        with trusting_pickle(getattr(args, "trust_pickle", False)), terminate_as_interrupt():
            return int(args.func(args))
    except RunFailed as exc:  # a worker killed, a full disk: what was kept
        sys.stderr.write(f"shipgym {args.command}: failed: {exc}\n")
        return EXIT_FAILED
    except ShipgymError as exc:
        sys.stderr.write(f"shipgym {args.command}: error: {exc}\n")
        return EXIT_USAGE
    # a run says what it kept (shipgym_baselines.records.runlog.RunInterrupted)
    except KeyboardInterrupt as exc:
        signum = signal_number(exc)
        by = "" if signum == signal.SIGINT else f" by {signal.Signals(signum).name}"
        detail = f": {exc}" if str(exc) and not isinstance(exc, Terminated) else ""
        sys.stderr.write(f"shipgym {args.command}: interrupted{by}{detail}\n")
        return EXIT_SIGNAL + signum


__all__ = ["build_parser", "main"]
