"""The ``shipgym`` console script (SPEC §9b).

``--json`` prints exactly one JSON document on stdout; progress and tables go to stderr.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from baselines.jsonout import dumps


def _emit(args: argparse.Namespace, document: Any, text: str) -> None:
    if args.json:
        sys.stdout.write(dumps(document) + "\n")
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
    """``leaderboard`` (the suite's controllers) and ``evaluate`` (one policy on a suite)."""
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
    _emit(args, rows, markdown_table(rows))
    if not args.json:
        sys.stderr.write(f"wrote {args.out}/leaderboard.md, .csv, .json and plots\n")
    return 0


def cmd_bench(args: argparse.Namespace) -> int:
    from baselines.benchmarks import bench_env, bench_identification, bench_nmpc, bench_training

    if args.target == "env":
        figures = bench_env(repeats=args.repeats)
    elif args.target == "nmpc":
        figures = bench_nmpc()
    elif args.target == "training":
        figures = bench_training(repeats=args.repeats)
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


def cmd_train(args: argparse.Namespace) -> int:
    from baselines.learned.agents import AGENT_DIR, load_agent_config
    from baselines.learned.train import train_sweep

    if args.agent == "all":
        if args.config:
            raise ValueError("train all: --config applies to one agent")
        names = sorted(p.stem for p in AGENT_DIR.glob("*.yaml"))
    else:
        names = [args.agent]
    seeds = args.seed or [None]
    if args.ship and len(seeds) > 1:
        raise ValueError("--ship exports one policy per agent: give at most one --seed")
    jobs = []
    for name in names:
        config = load_agent_config(args.config or name)
        for seed in seeds:
            out = args.out or "results/agents"
            if len(names) > 1 or args.out is None:
                out = f"{out}/{config.name}"
            if len(seeds) > 1:
                out = f"{out}/seed_{seed}"
            jobs.append(
                {
                    "config": config,
                    "out_dir": out,
                    "seed": seed,
                    "n_timesteps": args.timesteps,
                    "resume": args.resume,
                    "progress": not args.no_progress and len(names) * len(seeds) == 1,
                    "ship": args.ship,
                }
            )
    metas = train_sweep(jobs, backend=args.backend, workers=args.workers)
    text = "\n".join(
        f"{m['name']} (seed {m['seed']}): {m['env_steps']} env steps in "
        f"{m['wall_time_s']:.0f} s -> {m['out_dir']}"
        for m in metas
    )
    _emit(args, metas if len(metas) > 1 else metas[0], text)
    return 0


def cmd_manoeuvre(args: argparse.Namespace) -> int:
    import math
    from pathlib import Path

    from shipgym.manoeuvres import plot_manoeuvre, turning_circle, zigzag
    from shipgym.models import MODELS

    if args.ship not in MODELS:
        raise ValueError(f"unknown ship {args.ship!r}; valid: {', '.join(sorted(MODELS))}")
    model = MODELS[args.ship](variant=args.variant)
    if args.kind == "turning":
        default = min(35.0, math.degrees(model.rudder_limit))
        log, figures = turning_circle(model, args.rudder if args.rudder is not None else default)
    else:
        rudder = args.rudder if args.rudder is not None else 20.0
        log, figures = zigzag(model, rudder, args.switch if args.switch is not None else rudder)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    plot = out / f"{args.ship}_{args.kind}.png"
    plot_manoeuvre(model, args.kind, log, figures, str(plot))
    lines = [f"{k:22s} {v:.4g}" for k, v in figures.items()] + [f"plot: {plot}"]
    _emit(args, figures, "\n".join(lines))
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
    p.add_argument(
        "paper",
        choices=["liu2019", "morenosalinas2013", "borkowski2018", "xu2020", "xu2021"],
        help="which paper",
    )
    p.add_argument("--out", default=None, help="output directory (default results/reproduce/PAPER)")
    p.add_argument("--seeds", type=int, default=1, help="seeds per case and controller")
    p.add_argument("--no-progress", action="store_true")
    p.add_argument("--json", action="store_true", help="print the rows as JSON on stdout")
    p.set_defaults(func=cmd_reproduce)

    p = sub.add_parser(
        "train",
        help="train an SB3 agent (configs/agents) with evaluation, checkpoints, TensorBoard",
    )
    p.add_argument("agent", help="agent config name in configs/agents (ppo, sac, …) or 'all'")
    p.add_argument("--config", default=None, help="agent YAML (default configs/agents/AGENT.yaml)")
    p.add_argument("--out", default=None, help="output directory (default results/agents/NAME)")
    p.add_argument(
        "--seed",
        type=int,
        nargs="+",
        default=None,
        help="override the config's seed; several: a sweep",
    )
    p.add_argument("--workers", type=int, default=1, help="parallel training runs (local pool)")
    p.add_argument("--backend", choices=["local", "ray"], default="local")
    p.add_argument("--timesteps", type=int, default=None, help="override n_timesteps")
    p.add_argument("--resume", action="store_true", help="continue from the newest checkpoint")
    p.add_argument(
        "--ship", action="store_true", help="export the best model to baselines/learned/policies"
    )
    p.add_argument("--no-progress", action="store_true")
    p.add_argument("--json", action="store_true", help="print the training meta as JSON")
    p.set_defaults(func=cmd_train)

    p = sub.add_parser(
        "evaluate", help="evaluate a controller or trained agent on a suite (leaderboard rows)"
    )
    p.add_argument("policy", help="controller name, shipped policy name or trained agent folder")
    p.add_argument("--suite", default="default", help="suite name in configs/suites or a YAML path")
    p.add_argument("--seeds", type=int, default=None, help="seeds per scenario (default: suite's)")
    p.add_argument("--out", default="results/evaluate", help="output directory")
    p.add_argument("--backend", choices=["local", "ray"], default="local")
    p.add_argument("--workers", type=int, default=None, help="local processes (default: cores)")
    p.add_argument("--no-progress", action="store_true")
    p.add_argument("--json", action="store_true", help="print the rows as JSON on stdout")
    p.set_defaults(func=cmd_leaderboard)

    p = sub.add_parser(
        "manoeuvre", help="turning circle or zig-zag of a ship model, with figures and a plot"
    )
    p.add_argument("ship", help="ship model id (nomoto2, esso_osaka, mariner, blanke)")
    p.add_argument("kind", choices=["turning", "zigzag"])
    p.add_argument("--rudder", type=float, default=None, help="rudder angle [deg] (35 / 20)")
    p.add_argument("--switch", type=float, default=None, help="zig-zag heading switch [deg]")
    p.add_argument("--variant", default=None, help="model variant (e.g. esso_osaka literal)")
    p.add_argument("--out", default="results/manoeuvres", help="directory of the plot")
    p.add_argument("--json", action="store_true", help="print the figures as a JSON object")
    p.set_defaults(func=cmd_manoeuvre)

    p = sub.add_parser("scenarios", help="list the scenario catalogue")
    p.add_argument("--json", action="store_true", help="print the names as a JSON list")
    p.set_defaults(func=cmd_scenarios)

    p = sub.add_parser("bench", help="benchmarks of SPEC §10")
    p.add_argument(
        "target",
        choices=["env", "nmpc", "identification", "training"],
        help="what to benchmark (training: PPO with the batched env vs SubprocVecEnv)",
    )
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--json", action="store_true", help="print the figures as a JSON object")
    p.set_defaults(func=cmd_bench)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except (ValueError, KeyError, RuntimeError, OSError) as exc:
        sys.stderr.write(f"shipgym {args.command}: error: {exc}\n")
        return 2


if __name__ == "__main__":
    sys.exit(main())
