"""The ``shipgym`` console script (SPEC §9b).

``--json`` prints exactly one JSON document on stdout; progress and tables go to stderr.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any


def _emit(args: argparse.Namespace, document: Any, text: str) -> None:
    if args.json:
        sys.stdout.write(json.dumps(document) + "\n")
    else:
        sys.stdout.write(text + "\n")


def cmd_scenarios(args: argparse.Namespace) -> int:
    from shipgym.scenarios import list_scenarios, load_scenario

    names = list_scenarios()
    lines = []
    for name in names:
        sc = load_scenario(name)
        lines.append(f"{name:28s} {sc.model.name:10s} {sc.config.description.strip()}")
    _emit(args, names, "\n".join(lines))
    return 0


def cmd_leaderboard(args: argparse.Namespace) -> int:
    from baselines.leaderboard import markdown_table, run_leaderboard

    rows = run_leaderboard(
        suite=args.suite,
        seeds=args.seeds,
        out_dir=args.out,
        backend=args.backend,
        workers=args.workers,
        show_progress=not args.no_progress,
    )
    if args.json:
        _emit(args, rows, "")
    else:
        sys.stdout.write(markdown_table(rows))
        sys.stderr.write(f"wrote {args.out}/leaderboard.md, .csv, .json and plots\n")
    return 0


def cmd_bench(args: argparse.Namespace) -> int:
    from baselines.benchmarks import bench_env, bench_identification, bench_nmpc

    if args.target == "env":
        figures = bench_env(repeats=args.repeats)
    elif args.target == "nmpc":
        figures = bench_nmpc()
    else:
        figures = bench_identification()
    _emit(args, figures, "\n".join(_flatten_lines(figures)))
    return 0


def _flatten_lines(figures: dict[str, Any], prefix: str = "") -> list[str]:
    lines = []
    for key, value in figures.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            lines.extend(_flatten_lines(value, name + "."))
        elif isinstance(value, float):
            lines.append(f"{name:60s} {value:,.4g}")
        else:
            lines.append(f"{name:60s} {value}")
    return lines


def cmd_reproduce(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from baselines.reproduce import PAPERS

    module = PAPERS[args.paper]
    bar = tqdm(desc=f"reproduce {args.paper}", file=sys.stderr, disable=args.no_progress)
    rows = module.run(
        out_dir=args.out or f"results/reproduce/{args.paper}",
        seeds=args.seeds,
        progress=lambda: bar.update(1),
    )
    bar.close()
    if args.json:
        _emit(args, rows, "")
    else:
        sys.stdout.write(module.markdown(rows))
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="shipgym", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("leaderboard", help="run every controller on a suite (SPEC §9)")
    p.add_argument("--suite", default="default", help="suite name in configs/suites or a YAML path")
    p.add_argument("--seeds", type=int, default=None, help="seeds per scenario (default: suite's)")
    p.add_argument("--out", default="results/leaderboard", help="output directory")
    p.add_argument("--backend", choices=["local", "ray"], default="local")
    p.add_argument("--workers", type=int, default=None, help="local processes (default: cores)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    p.add_argument("--json", action="store_true", help="print the rows as JSON on stdout")
    p.set_defaults(func=cmd_leaderboard)

    p = sub.add_parser("reproduce", help="re-run a source paper's experiment (SPEC §11)")
    p.add_argument("paper", choices=["liu2019"], help="which paper")
    p.add_argument("--out", default=None, help="output directory (default results/reproduce/PAPER)")
    p.add_argument("--seeds", type=int, default=1, help="seeds per case and controller")
    p.add_argument("--no-progress", action="store_true")
    p.add_argument("--json", action="store_true", help="print the rows as JSON on stdout")
    p.set_defaults(func=cmd_reproduce)

    p = sub.add_parser("scenarios", help="list the scenario catalogue")
    p.add_argument("--json", action="store_true", help="print the names as a JSON list")
    p.set_defaults(func=cmd_scenarios)

    p = sub.add_parser("bench", help="benchmarks of SPEC §10")
    p.add_argument("target", choices=["env", "nmpc", "identification"], help="what to benchmark")
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--json", action="store_true", help="print the figures as a JSON object")
    p.set_defaults(func=cmd_bench)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except (ValueError, KeyError, RuntimeError) as exc:
        sys.stderr.write(f"shipgym {args.command}: error: {exc}\n")
        return 2


if __name__ == "__main__":
    sys.exit(main())
