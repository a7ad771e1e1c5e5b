"""``shipgym reproduce PAPER``: re-run a source paper's experiment (docs: "Reproducing the
papers")."""

from __future__ import annotations

import argparse
import sys

from shipgym_baselines.cli.options import add_json_option, add_progress_option, emit
from shipgym_baselines.errors import check_seeds
from shipgym_baselines.reproduce import PAPERS


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "reproduce", help="re-run a source paper's experiment (docs: 'Reproducing the papers')"
    )
    p.add_argument("paper", choices=list(PAPERS), help="which paper")
    p.add_argument("--out", default=None, help="output directory (default results/reproduce/PAPER)")
    p.add_argument("--seeds", type=int, default=1, help="seeds per case and controller")
    add_progress_option(p)
    add_json_option(p, "print the rows as JSON on stdout")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Check the options (before any work), run the paper's cases, print its markdown table
    (or the rows with ``--json``).  The report's files in ``--out`` are replaced."""
    from tqdm import tqdm

    from shipgym_baselines.records.folders import check_out_dir

    check_seeds(args.seeds, "--seeds")
    out = args.out or f"results/reproduce/{args.paper}"
    check_out_dir(out, force=True)  # usable (a writable folder); its earlier report replaced
    paper = PAPERS[args.paper]
    bar = tqdm(desc=f"reproduce {args.paper}", file=sys.stderr, disable=args.no_progress)
    rows = paper.run(
        out_dir=out,
        seeds=args.seeds,
        progress=lambda: bar.update(1),
    )
    bar.close()
    if args.json:
        emit(args, rows, "")
    else:
        sys.stdout.write(paper.markdown(rows))
    return 0
