"""``shipgym tune NAME``: an Optuna study of a controller's settings on the validation split.

The search space, budget and validation trials are ``configs/tuning/NAME.yaml``; the
protocol is ``docs/tuning.md`` (:mod:`shipgym_baselines.tuning`).  One study per ship for a
per-ship config (``--ship`` picks one), in ``--out`` (default ``results/tuning/NAME``, a
folder per ship) with its SQLite storage there unless ``--storage URL``; an existing study
is continued only with ``--resume``, and only under the config it started with.  Each study
writes ``tuning_report.json`` into its folder and its chosen settings into
``<out>/chosen/<controller>.yaml``.  ``--promote`` writes them
into the packaged ``configs/tuning/chosen`` instead (``--chosen-dir``: another folder),
saying what they replace; settings that score better on the same validation trials are
kept unless ``--force`` (the command then exits 1).
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from shipgym_baselines.cli.options import add_json_option, emit
from shipgym_baselines.executor import BACKENDS


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("tune", help="tune a controller's settings on the validation split (Optuna)")
    p.add_argument("name", help="tuning config in configs/tuning (pid_los, ppo, …) or a YAML path")
    p.add_argument("--trials", type=int, default=None, help="trials per study (default: budget)")
    p.add_argument(
        "--resume",
        action="store_true",
        help="continue the existing study (refused if its config changed since it started)",
    )
    p.add_argument("--storage", default=None, help="Optuna storage URL (default: SQLite in --out)")
    p.add_argument("--backend", choices=BACKENDS, default="local")
    p.add_argument("--workers", type=int, default=1, help="Ray tasks at once (--backend ray)")
    p.add_argument("--ship", default=None, help="only this ship's study (per-ship configs)")
    p.add_argument("--out", default=None, help="study folder (default results/tuning/NAME)")
    where = p.add_mutually_exclusive_group()
    where.add_argument(
        "--promote",
        action="store_true",
        help="write the chosen settings into the packaged configs/tuning/chosen (what every "
        "run of the controller then uses); default: OUT/chosen",
    )
    where.add_argument(
        "--chosen-dir",
        default=None,
        help="write the chosen settings into this folder (default: OUT/chosen)",
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="replace chosen settings even when they score better on the same trials",
    )
    add_json_option(p, "print the studies' reports as one JSON list")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the studies; exit 1 when a study's chosen settings were kept out of their file
    because the settings there score better (``--force`` replaces them)."""
    from shipgym_baselines.extras import require

    require("optuna", "tune", "shipgym tune")
    from shipgym_baselines.tuning.study import plan_studies, run_study

    plans = plan_studies(
        args.name, args.ship, args.out, args.storage, args.chosen_dir, promote=args.promote
    )
    reports: list[dict[str, Any]] = []
    for plan in plans:
        report = run_study(
            plan,
            n_trials=args.trials,
            resume=args.resume,
            backend=args.backend,
            workers=args.workers,
            progress=lambda text: sys.stderr.write(f"tune: {text}\n"),
            force=args.force,
        )
        reports.append(report)
    lines = [
        f"{r['study']}: best {r['best_value']} (default {r['default_value']:.4g}) "
        f"params {r['best_params']} -> {plan.folder}"
        for r, plan in zip(reports, plans, strict=True)
    ]
    emit(args, reports, "\n".join(lines))
    refused = [r["chosen"]["refused"] for r in reports if (r.get("chosen") or {}).get("refused")]
    for text in refused:
        sys.stderr.write(f"shipgym tune: not written: {text}\n")
    return 1 if refused else 0
