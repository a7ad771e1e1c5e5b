"""``shipgym run SCENARIO CONTROLLER``: one episode, its metrics and a track plot.

Writes ``metrics.json`` (the episode's row: scenario, controller, kind, seed and every
metric, as ``--json`` prints it) and the leaderboard's figure of the episode (path and
track, cross-track error, rudder angle) into ``--out``, as a leaderboard writes its folder:
locked while written, each file listed in ``manifest.txt`` and written through no link
(``--force`` deletes only what the manifest lists).  The episode is the trial that
``--seed`` draws with ``--suite``'s randomisation (default suite ``default``), so it equals
that suite's leaderboard episode of the scenario and seed; the default seed is the
leaderboard's first evaluation seed.  A learned agent runs the policy of
``--training-seed`` (default: its first; the leaderboard runs each of
:func:`~shipgym_baselines.registry.training_seeds`), named with all its training seeds in
the output (``training_seed``, ``training_seeds``; None and [] for an untrained controller).
"""

from __future__ import annotations

import argparse
import functools
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from shipgym_baselines.cli.options import (
    add_act_timeout_option,
    add_json_option,
    add_out_options,
    add_trust_pickle_option,
    emit,
)
from shipgym_baselines.errors import RunError
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET

#: the default ``--out`` is ``RUN_ROOT/<scenario>_<controller>_<seed>``
RUN_ROOT = Path("results/run")
METRICS_FILE = "metrics.json"


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run", help="one episode of a controller on a scenario: its metrics and a track plot"
    )
    p.add_argument(
        "scenario",
        help="catalogue name, held-out test scenario (heldout:3), scenario YAML, or the name: "
        "of a scenario file that --suite lists",
    )
    p.add_argument(
        "controller", help="controller name, shipped policy name or trained agent folder / zip"
    )
    p.add_argument(
        "--seed",
        type=int,
        default=EVAL_SEED_OFFSET,
        help=f"evaluation seed (default {EVAL_SEED_OFFSET}, the leaderboard's first; its "
        f"i-th seed is {EVAL_SEED_OFFSET} + i)",
    )
    p.add_argument(
        "--training-seed",
        type=int,
        default=None,
        metavar="K",
        help="a learned agent's training seed to replay, one of those its leaderboard row "
        "aggregates (default: the first)",
    )
    p.add_argument(
        "--suite",
        default="default",
        help="replay this suite's trial of the scenario and seed (its randomize: block: start "
        "offset, heading, jump time, current), as its leaderboard ran it; a name in "
        "configs/suites or a YAML path (default: default)",
    )
    add_out_options(
        p,
        None,
        help=f"output directory (default {RUN_ROOT}/SCENARIO_CONTROLLER_SEED; refused if not "
        "empty: see --force)",
        resume_help=None,
    )
    p.add_argument(
        "--video",
        default=None,
        metavar="FILE",
        help="also write an animation of the episode: FILE.gif (Pillow) or FILE.mp4 (needs "
        "ffmpeg: pip install 'shipgym[video]')",
    )
    add_act_timeout_option(p)
    add_trust_pickle_option(p)
    add_json_option(p, "print the episode's metrics as one JSON object")
    p.set_defaults(func=run)


def default_out(scenario: str, controller: str, seed: int) -> Path:
    """``RUN_ROOT/<scenario>_<controller>_<seed>``, each part reduced to a file name."""
    parts = (scenario, controller, str(seed))
    return RUN_ROOT / "_".join(_file_name(part) for part in parts)


def _file_name(text: str) -> str:
    return "".join(c if c.isalnum() or c in "-." else "_" for c in text).strip("._") or "_"


def run(args: argparse.Namespace) -> int:
    """Check the scenario, the controller and ``--out`` (in that order, before any work),
    run the episode, write its files, print its metrics."""
    from shipgym.animation import check_video_file
    from shipgym.config import is_path
    from shipgym.scenarios.loader import load_scenario
    from shipgym.scenarios.trials import trial_scenario
    from shipgym_baselines.evaluation import ActGuard, evaluate
    from shipgym_baselines.isolation import call, isolated, run_isolated
    from shipgym_baselines.jsonout import dumps
    from shipgym_baselines.leaderboard.jobs import check_controllers
    from shipgym_baselines.leaderboard.outputs import plot_results
    from shipgym_baselines.records.episodes import EpisodeLabel
    from shipgym_baselines.records.folders import check_out_dir
    from shipgym_baselines.records.manifest import check_listed
    from shipgym_baselines.registry import applies_to, training_seeds
    from shipgym_baselines.suite import load_suite

    guard = ActGuard(args.act_timeout)
    suite = load_suite(args.suite)
    scenario = load_scenario(_suite_file(args.scenario, suite))
    video = None if args.video is None else check_video_file(args.video)
    (label,) = check_controllers([args.controller])
    ship = scenario.model.name
    if not applies_to(label, ship):
        raise RunError(
            f"controller {label!r} does not apply to the {ship} ship of scenario {scenario.name!r}"
        )
    trained = [k for k in training_seeds(args.controller) if k is not None]
    training_seed = _training_seed(label, trained, args.training_seed)
    name = Path(args.scenario).stem if is_path(args.scenario) else args.scenario
    out = check_out_dir(args.out or default_out(name, label, args.seed), force=args.force)
    if args.force:
        check_listed(out)  # a user's file refused before the episode, not after
    # the suite's trial of this seed, as the leaderboard draws it (leaderboard.trials)
    trial = trial_scenario(scenario, suite.randomize, args.seed)
    settings = {} if training_seed is None else {"training_seed": training_seed}
    # as the leaderboard names them: a scenario file under its name:
    table_name = scenario.name if is_path(args.scenario) else args.scenario
    named = EpisodeLabel(table_name, label, training_seed)
    play = functools.partial(
        evaluate, args.controller, trial, [args.seed], guard=guard, label=named, **settings
    )
    if isolated(args.controller):  # in a process of its own, as in a leaderboard run
        failed = functools.partial(_failed, args.controller, trial, args.seed, guard, named)
        (result,) = run_isolated(call, play, failed, guard.setup_timeout)
    else:
        (result,) = play()
    row = result.row()
    # after "seed": which of the agent's policies ran (as the leaderboard's episodes name it)
    at = list(row).index("seed") + 1
    items = list(row.items())
    row = dict([*items[:at], ("training_seed", training_seed), ("training_seeds", trained)])
    row |= dict(items[at:])
    randomize = None if suite.randomize is None else suite.randomize.model_dump(mode="json")
    plots = _write(
        out,
        args.force,
        dumps(row, indent=2) + "\n",
        lambda: plot_results([result], out, {table_name: scenario}, randomize),
    )
    if video is not None:
        trained_with = "" if training_seed is None else f", training seed {training_seed}"
        _write_video(video, result, trial, f"{name}: {label}, seed {args.seed}{trained_with}")
    text = "\n".join(f"{k:24s} {_cell(v)}" for k, v in row.items())
    emit(args, row, text)
    policy = "" if training_seed is None else f"; {_seed_phrase(training_seed, trained)}"
    sys.stderr.write(
        f"wrote {out}: {METRICS_FILE}, {', '.join(plots)} (the trial of seed {args.seed} in "
        f"suite {suite.name!r}{policy})\n"
    )
    return 0


def _failed(
    controller: Any, trial: Any, seed: int, guard: Any, label: Any, reason: str, error: str
) -> list[Any]:
    """The episode of a controller whose process ended or was killed before it gave it
    (:mod:`shipgym_baselines.isolation`)."""
    from shipgym_baselines.evaluation import failed_episode

    return [failed_episode(controller, trial, seed, reason, error, guard, label)]


def _write(out: Path, force: bool, metrics: str, draw: Callable[[], list[Path]]) -> list[str]:
    """``metrics.json`` (the text ``metrics``) and the figures (``draw`` writes them and
    returns their paths) into ``out``, locked, each file listed in its manifest as it is
    written (``force``: what the manifest lists deleted first); the figures' names."""
    from shipgym_baselines.records.folders import check_out_dir
    from shipgym_baselines.records.locking import out_lock
    from shipgym_baselines.records.manifest import Manifest, clear_listed
    from shipgym_baselines.records.outfiles import write_text
    from shipgym_baselines.records.runrecord import now

    with out_lock(out, now()):
        check_out_dir(out, force=force)  # again, now that no other run can start there
        if force:
            clear_listed(out)
        manifest = Manifest(out)
        with manifest.recording():
            write_text(out / METRICS_FILE, metrics)
            plots = draw()
        manifest.compact()
    return sorted(p.name for p in plots)


def _training_seed(label: str, trained: list[int], chosen: int | None) -> int | None:
    """The training seed to run: ``chosen`` (checked against ``trained``, the controller's
    training seeds), else the first of ``trained``; None for an untrained controller."""
    if chosen is None:
        return trained[0] if trained else None
    if chosen not in trained:
        valid = ", ".join(map(str, trained))
        has = f"has the training seeds {valid}" if trained else "has no training seeds"
        raise RunError(f"--training-seed {chosen}: controller {label!r} {has}")
    return chosen


def _seed_phrase(training_seed: int, trained: list[int]) -> str:
    """ "training seed 1 of 3 (0, 1, 2)"."""
    return f"training seed {training_seed} of {len(trained)} ({', '.join(map(str, trained))})"


def _suite_file(scenario: str, suite: Any) -> str:
    """``scenario``, or the YAML file of the suite's own scenario of that name (a name that
    is neither a catalogue scenario, a held-out one nor a path)."""
    from shipgym.config import is_path
    from shipgym.scenarios.loader import list_scenarios, load_scenario
    from shipgym_baselines.suite import name_scenarios

    if is_path(scenario) or ":" in scenario or scenario in list_scenarios():
        return scenario
    files = [s for s in suite.all_scenarios() if is_path(s)]
    return name_scenarios(files, load_scenario).files.get(scenario, scenario)


def _write_video(file: Path, result: Any, trial: Any, title: str) -> None:
    """The episode's animation as ``file``; its CPU time per frame on stderr."""
    import numpy as np

    from shipgym.animation import animate_episode

    start = time.process_time()
    path_xy = trial.path.point(np.linspace(0.0, trial.path.length, 400))
    frames = animate_episode(result.trajectory, path_xy, trial.ship_length, file, title)
    cpu = time.process_time() - start
    sys.stderr.write(f"wrote {file}: {frames} frames, {1000 * cpu / frames:.0f} ms CPU a frame\n")


def _cell(value: object) -> str:
    return f"{value:.6g}" if isinstance(value, float) else str(value)
