"""``shipgym train AGENT``: train SB3 agents (configs/agents), one run or a sweep.

``shipgym train all --seeds 0 1 2 --ship`` trains every agent with three seeds (runs in
``results/agents/<name>/seed_<k>``) and ships each into
``baselines/learned/policies/<name>/seed_<k>``; with ``--resume`` a finished run is not
trained again, so the same command on finished runs only exports them.

``--settings tuned`` trains with the study's chosen settings and the tuning config's
``final`` block (:mod:`shipgym_baselines.tuning.tuned`; without ``--seeds``, the final
block's seeds); with ``--resume`` a re-run after a kill exports finished seeds, resumes
unfinished ones from their checkpoint and starts the ones that reached none afresh.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from shipgym_baselines.cli.options import (
    add_backend_option,
    add_json_option,
    add_out_options,
    add_progress_option,
    add_trust_pickle_option,
    emit,
)
from shipgym_baselines.errors import RunError, check_count


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "train",
        help="train an SB3 agent (configs/agents) with evaluation, checkpoints, TensorBoard",
    )
    p.add_argument("agent", help="agent config name in configs/agents (ppo, sac, …) or 'all'")
    p.add_argument("--config", default=None, help="agent YAML (default configs/agents/AGENT.yaml)")
    add_out_options(
        p,
        None,
        help="output directory (default results/agents/NAME; refused if not empty: see "
        "--resume, --force)",
        resume_help="continue from the newest checkpoint",
    )
    p.add_argument(
        "--seeds",
        "--seed",
        dest="seeds",
        type=int,
        nargs="+",
        default=None,
        metavar="SEED",
        help="training seed(s), overriding the config's; several: a sweep, each run in OUT/seed_K",
    )
    p.add_argument("--workers", type=int, default=1, help="parallel training runs (local pool)")
    add_backend_option(p)
    p.add_argument("--timesteps", type=int, default=None, help="override n_timesteps")
    p.add_argument(
        "--settings",
        choices=("config", "tuned"),
        default="config",
        help="config: the agent config as written; tuned: with the chosen settings of its "
        "study (configs/tuning/chosen/AGENT.yaml) and the final block of "
        "configs/tuning/AGENT.yaml (budget, plateau, selection, seeds)",
    )
    p.add_argument(
        "--chosen-dir",
        default=None,
        help="folder of the chosen settings read by --settings tuned "
        "(default configs/tuning/chosen)",
    )
    p.add_argument(
        "--ship",
        action="store_true",
        help="export each run's best model to baselines/learned/policies/NAME/seed_K "
        "(with --resume, finished runs are not trained again: only exported)",
    )
    add_progress_option(p)
    add_trust_pickle_option(p)  # --resume: checkpoints this user's shipgym did not write
    add_json_option(p, "print the training meta as JSON")
    p.set_defaults(func=run)


def training_jobs(args: argparse.Namespace) -> list[dict[str, Any]]:
    """One job per (agent, seed) with its output directory (``train_sweep``'s input)."""
    from shipgym_baselines.learned.agent_folder import check_agent_folder
    from shipgym_baselines.training.agents import list_agent_configs, load_agent_config

    if args.timesteps is not None:
        check_count(args.timesteps, "--timesteps")
    if args.agent == "all":
        if args.config:
            raise RunError("train all: --config applies to one agent")
        names = list_agent_configs()
    else:
        names = [args.agent]
    settings = getattr(args, "settings", "config")
    jobs = []
    for name in names:
        config = load_agent_config(args.config or name)
        tuned_from = None
        seeds = args.seeds or [None]
        if settings == "tuned":
            from shipgym_baselines.tuning.tuned import tuned_agent

            config, tuned_from = tuned_agent(config, getattr(args, "chosen_dir", None))
            seeds = args.seeds or tuned_from["final"]["seeds"]
        for seed in seeds:
            out = args.out or "results/agents"
            if len(names) > 1 or args.out is None:
                out = f"{out}/{config.name}"
            if len(seeds) > 1:
                out = f"{out}/seed_{seed}"
            if not args.resume:  # before any run of the sweep starts
                check_agent_folder(out, config.name, args.force)
            jobs.append(
                {
                    "config": config,
                    "out_dir": out,
                    "seed": seed,
                    "n_timesteps": args.timesteps,
                    "resume": args.resume,
                    "force": args.force,
                    "progress": not args.no_progress and len(names) * len(seeds) == 1,
                    "ship": args.ship,
                    "tuned_from": tuned_from,
                    "fresh_if_unstarted": True,
                }
            )
    return jobs


def run(args: argparse.Namespace) -> int:
    """Train every job, print one line per run (or the meta(s) with ``--json``)."""
    from shipgym_baselines.extras import require

    require("stable_baselines3", "rl", "shipgym train")
    from shipgym_baselines.training.announce import start_line, too_short_line
    from shipgym_baselines.training.train import train_sweep

    jobs = training_jobs(args)
    for job in jobs:
        config = job["config"]
        steps = job["n_timesteps"] or config.n_timesteps
        sys.stderr.write(start_line(config, steps, job["seed"], job["out_dir"]) + "\n")
    metas = train_sweep(jobs, backend=args.backend, workers=args.workers)
    for job, meta in zip(jobs, metas, strict=True):
        line = too_short_line(job["config"], meta)
        if line is not None:
            sys.stderr.write(line + "\n")
    text = "\n".join(
        f"{m['name']} (seed {m['seed']}): {m['env_steps']} env steps in "
        f"{m['wall_time_s']:.0f} s -> {m['out_dir']}"
        + (f", shipped to {m['shipped_to']}" if "shipped_to" in m else "")
        for m in metas
    )
    emit(args, metas if len(metas) > 1 else metas[0], text)
    return 0
