"""``shipgym bench TARGET``: the benchmarks (docs page "Benchmarks")."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Any

from shipgym_baselines.cli.options import add_json_option, emit
from shipgym_baselines.errors import check_count
from shipgym_baselines.studies import benchmarks

#: bench target -> the benchmark run with the parsed options (``--repeats``)
BENCHES: dict[str, Callable[[argparse.Namespace], dict[str, Any]]] = {
    "env": lambda args: benchmarks.bench_env(repeats=args.repeats),
    "nmpc": lambda args: benchmarks.bench_nmpc(),
    "identification": lambda args: benchmarks.bench_identification(),
    "training": lambda args: benchmarks.bench_training(repeats=args.repeats),
    "leaderboard": lambda args: _profile(args),
}


def _profile(args: argparse.Namespace) -> dict[str, Any]:
    from shipgym_baselines.studies.run_costs import profile_suite

    return profile_suite(
        args.suite,
        seeds=args.seeds,
        controllers=args.controllers,
        scenarios=args.scenarios,
        show_progress=True,
    )


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("bench", help="benchmarks of speed and throughput (docs: 'Benchmarks')")
    p.add_argument(
        "target",
        choices=list(BENCHES),
        help="what to benchmark (training: the shipped PPO config through the per-ship batched "
        "envs, DummyVecEnv and SubprocVecEnv; leaderboard: CPU seconds of a suite per "
        "controller, ship and step)",
    )
    p.add_argument("--repeats", type=int, default=5, help="timed repetitions (≥ 1)")
    p.add_argument(
        "--suite", default="default", help="leaderboard: the suite whose CPU time is profiled"
    )
    p.add_argument(
        "--seeds", type=int, default=1, help="leaderboard: evaluation seeds measured (≥ 1)"
    )
    p.add_argument(
        "--controllers", nargs="+", default=None, help="leaderboard: only these controllers"
    )
    p.add_argument(
        "--scenarios", nargs="+", default=None, help="leaderboard: only these suite scenarios"
    )
    add_json_option(p, "print the figures as a JSON object")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the benchmark, print its figures (nested keys joined by dots)."""
    check_count(args.repeats, "--repeats")
    figures = BENCHES[args.target](args)
    emit(args, figures, "\n".join(flatten_lines(figures)))
    return 0


def flatten_lines(figures: dict[str, Any], prefix: str = "") -> list[str]:
    """``name value`` lines of nested figures, names joined by dots."""
    lines = []
    for key, value in figures.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            lines.extend(flatten_lines(value, name + "."))
        elif isinstance(value, float):
            lines.append(f"{name:60s} {value:,.4g}")
        else:
            lines.append(f"{name:60s} {value}")
    return lines
