"""``shipgym summary DIR``: a finished leaderboard run's summary (ranking rows, headroom,
change shares, wall and CPU time, commit), the file the README's numbers come from."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from shipgym_baselines.cli.options import add_json_option, emit


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "summary",
        help="a finished leaderboard run's summary: the numbers the README quotes",
    )
    p.add_argument(
        "run", metavar="DIR", help="a finished leaderboard run's folder (not a report's)"
    )
    p.add_argument(
        "--out",
        metavar="FILE",
        help="also write the summary as JSON to FILE (the repository ships the default "
        "run's as docs/run_summary.json); refused if FILE exists, see --force",
    )
    p.add_argument("--force", action="store_true", help="replace an existing --out FILE")
    add_json_option(p, "print the summary as JSON on stdout")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Summarise the run; write ``--out``; print the README's table (or the JSON)."""
    from shipgym_baselines.errors import RunError
    from shipgym_baselines.jsonout import dumps
    from shipgym_baselines.leaderboard.summary import readme_table, run_summary
    from shipgym_baselines.records.outfiles import write_text

    try:
        summary = run_summary(args.run)
    except FileNotFoundError as exc:
        raise RunError(str(exc)) from None
    if args.out is not None:
        out = Path(args.out)
        if out.exists() and not args.force:
            raise RunError(f"--out {out}: exists; --force replaces it")
        try:
            write_text(out, dumps(summary, indent=2) + "\n")
        except OSError as exc:
            raise RunError(f"--out {out}: cannot write it ({exc.strerror})") from None
        if not args.json:
            sys.stderr.write(f"wrote {out}\n")
    has_catalogue = "catalogue" in summary["splits"]
    text = readme_table(summary) if has_catalogue else "(no catalogue split: no README table)"
    emit(args, summary, text)
    return 0
