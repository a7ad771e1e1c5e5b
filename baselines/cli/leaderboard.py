"""``shipgym leaderboard`` (the suite's controllers) and ``shipgym evaluate`` (one policy).

Both keep a run record in ``--out`` (``run.json``, ``episodes.jsonl``: see
:mod:`shipgym_baselines.records`); a folder that is not empty is refused before any work unless
``--resume`` or ``--force``.  The default ``--out``: ``results/<suite>`` for a suite's own
controllers, ``results/evaluate/<suite>/<controllers>`` for the controllers given
(``evaluate``'s policy, ``--controllers``: one folder per suite and set of controllers, outside
the suite's).  The controllers given, and a suite that does not list the ``oracle``, run
with the references they lack (:mod:`shipgym_baselines.scoring.comparison`), unless
``--no-references``; a suite that lists the oracle runs as it lists its controllers.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from shipgym_baselines.cli.options import add_run_options, command_line, emit
from shipgym_baselines.errors import RunError
from shipgym_baselines.plugins import ControllerEntry, ControllerSpec
from shipgym_baselines.scoring.comparison import REFERENCES, RESULTS_ROOT, suite_folder

#: ``evaluate`` writes to ``EVALUATE_ROOT/<suite>/<policy>`` unless given ``--out``
EVALUATE_ROOT = RESULTS_ROOT / "evaluate"


def add_references_option(parser: argparse.ArgumentParser) -> None:
    """``--no-references``: run only the controllers named, not the references too."""
    parser.add_argument(
        "--no-references",
        action="store_true",
        help=f"do not add the references ({', '.join(REFERENCES)}: the oracle read from its "
        "shipped table) that the run's controllers lack; without the oracle there is no "
        "ranking",
    )


def add_leaderboard_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "leaderboard",
        help="run every controller on a suite (docs: 'The leaderboard and its statistics')",
    )
    add_run_options(
        p,
        out=None,
        progress_help="no progress bar on stderr, nor its first line (the time estimated "
        "from the recorded costs)",
        out_help=f"output directory (default {RESULTS_ROOT}/<suite>: the suite's name or its "
        "file's stem; refused if not empty: see --resume, --force)",
    )
    p.add_argument(
        "--controllers",
        nargs="+",
        default=None,
        metavar="CONTROLLER",
        help="run these instead of the suite's: names, specs module:Attr / file.py:Attr, "
        "trained agents' folders or SB3 model zips",
    )
    p.add_argument(
        "--name",
        action="append",
        default=None,
        metavar="CONTROLLER=NAME",
        help="show CONTROLLER (as given to --controllers or in the suite) as NAME in the "
        "tables; repeat for several (e.g. --name work/ppo_ship.zip=ppo_ship)",
    )
    p.add_argument(
        "--recompute-references",
        action="store_true",
        help="run the oracle on every trial instead of reading its shipped reference table",
    )
    add_references_option(p)
    p.set_defaults(func=run)


def add_evaluate_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "evaluate", help="evaluate a controller or trained agent on a suite (leaderboard rows)"
    )
    p.add_argument(
        "policy",
        help="controller name, spec module:Attr or file.py:Attr, shipped policy name, trained "
        "agent folder or SB3 model zip",
    )
    p.add_argument(
        "--name",
        default=None,
        help="the policy's name in the tables (default: its own; an SB3 zip: the file's stem, "
        "a trained agent's folder: the folder's name)",
    )
    add_run_options(
        p,
        out=None,
        progress_help="no progress bar on stderr, nor its first line (the time estimated "
        "from the recorded costs)",
        out_help=f"output directory (default {EVALUATE_ROOT}/<suite>/<policy>; refused if not "
        "empty: see --resume, --force)",
    )
    add_references_option(p)
    p.set_defaults(func=run)


#: the longest folder name of :func:`evaluate_folder` before it is shortened with a hash
FOLDER_NAME_MAX = 80


def evaluate_folder(
    policy: ControllerSpec | list[ControllerSpec], suite: str | Path = "default"
) -> Path:
    """The default folder of a run of chosen controllers (``evaluate``'s ``policy``, or the
    list ``--controllers`` gives) on ``suite``: one per suite (its name or file stem) and set
    of table names (joined by ``+``; a long one cut and ended by a hash of the whole)."""
    import hashlib

    from shipgym_baselines.registry import controller_label

    labels = [controller_label(c) for c in (policy if isinstance(policy, list) else [policy])]
    name = "".join(c if c.isalnum() or c in "-_.+" else "_" for c in "+".join(labels))
    if len(name) > FOLDER_NAME_MAX:
        digest = hashlib.sha256(name.encode()).hexdigest()[:8]
        name = f"{name[: FOLDER_NAME_MAX - 9]}-{digest}"
    return EVALUATE_ROOT / suite_folder(suite).name / name


def lists_oracle(spec: Any) -> bool:
    """Whether a suite lists the ``oracle`` (the packaged suites do)."""
    from shipgym_baselines.registry import controller_label

    return any(controller_label(c) == REFERENCES[0] for c in spec.controllers)


def named(controller: ControllerSpec, name: str | None) -> ControllerSpec:
    """``controller`` shown as ``name`` (the long form), itself when ``name`` is None."""
    if name is None:
        return controller
    if not name.strip():
        raise RunError(f"--name for {controller!r} is empty")
    if isinstance(controller, ControllerEntry):
        return controller.model_copy(update={"name": name})
    return ControllerEntry(controller=controller, name=name)


def parse_names(pairs: list[str] | None) -> dict[str, str]:
    """``--name CONTROLLER=NAME`` options as controller → name (split at the last ``=``);
    a pair without ``=`` or a controller named twice is an error."""
    names: dict[str, str] = {}
    for pair in pairs or []:
        controller, sep, name = pair.rpartition("=")
        if not sep or not controller or not name:
            raise RunError(f"--name {pair!r}: give CONTROLLER=NAME (e.g. work/agent.zip=mine)")
        if controller in names:
            raise RunError(f"--name: controller {controller!r} is named twice")
        names[controller] = name
    return names


def named_controllers(
    controllers: list[ControllerSpec], pairs: list[str] | None
) -> list[ControllerSpec]:
    """``controllers`` with ``--name CONTROLLER=NAME`` applied; a CONTROLLER that is not
    among them is an error naming the valid ones."""
    names = parse_names(pairs)

    def key(c: ControllerSpec) -> str:
        return c if isinstance(c, str) else c.controller

    unknown = sorted(set(names) - {key(c) for c in controllers})
    if unknown:
        valid = ", ".join(key(c) for c in controllers)
        raise RunError(f"--name names {unknown}, not among the run's controllers: {valid}")
    return [named(c, names.get(key(c))) for c in controllers]


def run(args: argparse.Namespace) -> int:
    """Run the suite (with ``evaluate``: only ``args.policy``); print the ranking (--json:
    the rows)."""
    from shipgym_baselines.records.folders import check_out_dir, check_out_usable
    from shipgym_baselines.suite import load_suite

    policy = getattr(args, "policy", None)
    if policy is not None:
        policy = named(policy, args.name)
    controllers = [policy] if policy is not None else getattr(args, "controllers", None)
    out, note = args.out, ""
    if out is None and controllers is not None:
        out = evaluate_folder(controllers, args.suite)
        whose = f"evaluate's folder for {args.policy!r}" if policy else "--controllers' folder"
        note = f" ({whose} on --suite {args.suite}; give --out for another)"
    elif out is None:
        out = suite_folder(args.suite)
        note = f" (the leaderboard's folder for --suite {args.suite}; give --out for another)"
    from shipgym_baselines.leaderboard.run import check_failure_options

    # before any work: bad options, an unusable --out, a bad suite, --out in use or not empty
    check_failure_options(args.act_timeout, args.retry_failed, args.resume)
    check_out_usable(out, resume=args.resume, force=args.force)
    spec = load_suite(args.suite)
    explicit = controllers is not None
    if policy is None and args.name:
        controllers = named_controllers(controllers or list(spec.controllers), args.name)
    check_out_dir(out, resume=args.resume, force=args.force, note=note)
    from shipgym_baselines.leaderboard.outputs import terminal_summary
    from shipgym_baselines.leaderboard.run import run_leaderboard

    rows = run_leaderboard(
        suite=args.suite,
        seeds=args.seeds,
        out_dir=out,
        backend=args.backend,
        workers=args.workers,
        controllers=controllers,
        show_progress=not args.no_progress,
        resume=args.resume,
        force=args.force,
        command=command_line(args),
        recompute_references=getattr(args, "recompute_references", False),
        vector_figures=args.vector_figures,
        add_references=not args.no_references and (explicit or not lists_oracle(spec)),
        act_timeout=args.act_timeout,
        retry_failed=args.retry_failed,
    )
    if not args.json:
        from shipgym_baselines.records.runrecord import read_run

        record = read_run(out)
        sys.stderr.write(
            f"wrote {out}: leaderboard.md, .csv, .json, plots, run.json, episodes "
            f"({record['wall_s']:.0f} s wall, {record['cpu_s']:.0f} s CPU)\n"
        )
    emit(args, rows, terminal_summary(out))  # ends with the ranking and the page's path
    return 0
