"""Option blocks shared by several subcommands, and the one way a result is printed."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from shipgym_baselines.evaluation import ACT_TIMEOUT_S
from shipgym_baselines.executor import BACKENDS
from shipgym_baselines.jsonout import dumps


def add_json_option(parser: argparse.ArgumentParser, help: str) -> None:
    """``--json``: print the result as one JSON document on stdout (see :func:`emit`)."""
    parser.add_argument("--json", action="store_true", help=help)


def add_vector_option(parser: argparse.ArgumentParser) -> None:
    """``--vector-figures``: write each figure's vector copy (SVG, a scenario's as SVGZ)
    beside its PNG (the page shows the PNGs; without the copies a run folder is lighter)."""
    parser.add_argument(
        "--vector-figures",
        action="store_true",
        help="also write each figure as SVG (scenario figures as SVGZ) beside its PNG",
    )


def add_progress_option(parser: argparse.ArgumentParser, help: str | None = None) -> None:
    """``--no-progress``: no progress bar on stderr."""
    parser.add_argument(
        "--no-progress", action="store_true", help=help or "no progress bar on stderr"
    )


def add_trust_pickle_option(parser: argparse.ArgumentParser) -> None:
    """``--trust-pickle``: read model files that only unpickling can read (it runs any code
    they hold; :mod:`shipgym_baselines.learned.trust`)."""
    parser.add_argument(
        "--trust-pickle",
        action="store_true",
        help="read agent files that need unpickling (a pickled VecNormalize, an SB3 zip's "
        "pickled policy class or kwargs): unpickling runs any code in them",
    )


def add_backend_option(parser: argparse.ArgumentParser) -> None:
    """``--backend``: a local process pool or a Ray cluster."""
    parser.add_argument(
        "--backend",
        choices=BACKENDS,
        default="local",
        help="where the jobs run: local processes or a Ray cluster",
    )


def add_act_timeout_option(parser: argparse.ArgumentParser) -> None:
    """``--act-timeout``: the limit on one ``act`` call of a controller; a slower call, or
    one that fails, ends its episode as failed and the run goes on
    (:class:`~shipgym_baselines.evaluation.ActGuard`)."""
    parser.add_argument(
        "--act-timeout",
        type=float,
        default=ACT_TIMEOUT_S,
        metavar="SECONDS",
        help=f"CPU time one act call of a controller may take (default {ACT_TIMEOUT_S:g} s; "
        "ten times it in wall time; construction and reset 30 times it, at least 60 s); a "
        "slower call ends its episode as controller_timeout, as a call that raises or gives "
        "a malformed or non-finite action ends it as controller_error; the run goes on",
    )


def add_out_options(
    parser: argparse.ArgumentParser,
    out: str | None,
    help: str = "output directory",
    resume_help: str | None = "finish the run in --out: only the episodes missing from its "
    "episodes.jsonl",
) -> None:
    """``--out`` (default ``out``) and, for a folder that is not empty, ``--resume`` (none
    when ``resume_help`` is None) or ``--force`` (clear its earlier outputs)."""
    parser.add_argument("--out", default=out, help=help)
    group = parser.add_mutually_exclusive_group()
    if resume_help is not None:
        group.add_argument("--resume", action="store_true", help=resume_help)
    group.add_argument(
        "--force", action="store_true", help="clear the earlier outputs in --out, start afresh"
    )


def add_run_options(
    parser: argparse.ArgumentParser,
    out: str | None,
    progress_help: str | None = None,
    out_help: str = "output directory (refused if not empty: see --resume, --force)",
) -> None:
    """The options of a suite run (``leaderboard``, ``evaluate``): --suite, --seeds, --out
    (default ``out``) with --resume / --force, --retry-failed, --act-timeout, --backend,
    --workers, --trust-pickle, --no-progress, --vector-figures, --json."""
    parser.add_argument(
        "--suite", default="default", help="suite name in configs/suites or a YAML path"
    )
    parser.add_argument(
        "--seeds", type=int, default=None, help="seeds per scenario (default: suite's)"
    )
    add_out_options(parser, out, out_help)
    parser.add_argument(
        "--retry-failed",
        action="store_true",
        help="with --resume: run again the episodes its controller ended (controller_error, "
        "controller_timeout), which --resume alone keeps",
    )
    add_act_timeout_option(parser)
    add_backend_option(parser)
    parser.add_argument(
        "--workers", type=int, default=None, help="local processes (default: cores)"
    )
    add_trust_pickle_option(parser)
    add_progress_option(parser, progress_help)
    add_vector_option(parser)
    add_json_option(parser, "print the rows as JSON on stdout")


def command_line(args: argparse.Namespace) -> list[str]:
    """The command as typed (``shipgym …``), for a run's record."""
    return ["shipgym", *getattr(args, "argv", sys.argv[1:])]


def emit(args: argparse.Namespace, document: Any, text: str) -> None:
    """``document`` as one JSON document on stdout with ``--json``, else ``text``."""
    if args.json:
        sys.stdout.write(dumps(document) + "\n")
    else:
        sys.stdout.write(text + "\n")
