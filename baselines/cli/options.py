"""Option blocks shared by several subcommands, and the one way a result is printed."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from baselines.jsonout import dumps

#: where leaderboard jobs and training runs execute (``--backend``)
BACKENDS = ("local", "ray")


def add_json_option(parser: argparse.ArgumentParser, help: str) -> None:
    """``--json``: print the result as one JSON document on stdout (see :func:`emit`)."""
    parser.add_argument("--json", action="store_true", help=help)


def add_progress_option(parser: argparse.ArgumentParser, help: str | None = None) -> None:
    """``--no-progress``: no progress bar on stderr."""
    parser.add_argument("--no-progress", action="store_true", help=help)


def add_backend_option(parser: argparse.ArgumentParser) -> None:
    """``--backend``: a local process pool or a Ray cluster."""
    parser.add_argument("--backend", choices=BACKENDS, default="local")


def add_run_options(
    parser: argparse.ArgumentParser, out: str, progress_help: str | None = None
) -> None:
    """The options of a suite run (``leaderboard``, ``evaluate``): --suite, --seeds, --out
    (default ``out``), --backend, --workers, --no-progress and --json."""
    parser.add_argument(
        "--suite", default="default", help="suite name in configs/suites or a YAML path"
    )
    parser.add_argument(
        "--seeds", type=int, default=None, help="seeds per scenario (default: suite's)"
    )
    parser.add_argument("--out", default=out, help="output directory")
    add_backend_option(parser)
    parser.add_argument(
        "--workers", type=int, default=None, help="local processes (default: cores)"
    )
    add_progress_option(parser, progress_help)
    add_json_option(parser, "print the rows as JSON on stdout")


def emit(args: argparse.Namespace, document: Any, text: str) -> None:
    """``document`` as one JSON document on stdout with ``--json``, else ``text``."""
    if args.json:
        sys.stdout.write(dumps(document) + "\n")
    else:
        sys.stdout.write(text + "\n")
