"""``shipgym report``: the tables and plots rebuilt from one or more run folders.

Each folder is a ``leaderboard`` or ``evaluate`` run (``run.json`` + ``episodes.jsonl``,
:mod:`shipgym_baselines.records`); several merge into one table (separate ``evaluate`` runs of
different
policies on the same suite give the leaderboard of those policies).  Runs that give the same
scenario name different settings, draw their trials differently (``randomize``), or hold the
same (scenario, controller, seed, training_seed) episode, are refused; a reference's episode
(``oracle``, ``zero_rudder``, ``random``: every run adds them) held by several runs with the
same cost is read once.  The output folder
gets the leaderboard's tables, ranking (``aggregate.json``) and figures, and ``report.json``
(which runs, when, with what).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import Any

from shipgym_baselines.errors import RunError, RunFailed
from shipgym_baselines.records.episodes import EpisodeResult, Key, episode_key, read_episodes
from shipgym_baselines.records.folders import check_out_dir, check_out_usable
from shipgym_baselines.records.jsonfiles import differences, write_json
from shipgym_baselines.records.locking import out_lock
from shipgym_baselines.records.manifest import Manifest, clear_listed
from shipgym_baselines.records.runlog import outside_problem
from shipgym_baselines.records.runrecord import git_commit, now, read_run, versions
from shipgym_baselines.records.trajectories import episode_result
from shipgym_baselines.records.trials import (
    ALL,
    LEARNED_TRIALS,
    SHARED,
    TWIN_PLAYERS,
    TWIN_SCENARIOS,
    TWINS,
    shares_trials,
    twin_scenarios,
    twins_of,
)

REPORT_FILE = "report.json"


def merge_runs(
    folders: Sequence[str | os.PathLike],
) -> tuple[dict[str, Any], list[EpisodeResult], list[dict[str, Any]]]:
    """(suite, episodes, sources) of run folders merged: scenarios and controllers in order
    of first appearance, seeds (each scenario's too: ``scenario_seeds``, when some ran on
    fewer) and "does not apply" pairs united, the deal of learned agents' trials
    (``learned_trials``) the same in every run, the no-change twins united
    (:func:`merge_twins`); ``sources`` describes each run (folder, command, status, times,
    episodes of jobs)."""
    suite: dict[str, Any] = {
        "name": None,
        "seeds": [],
        "randomize": None,
        "controllers": [],
        "scenarios": {},
        "does_not_apply": [],
    }
    first_with: dict[str, str] = {}
    ran_on: dict[str, set[int]] = {}  # scenario → the seeds any run ran it on
    episode_in: dict[Key, str] = {}
    cost_of: dict[Key, Any] = {}
    results = []
    sources = []
    for folder in map(str, folders):
        record = read_run(folder)
        run_suite = record["suite"]
        randomize = run_suite.get("randomize")
        if sources and randomize != suite["randomize"]:
            raise RunError(
                f"{folder} draws its trials with randomize {randomize} but "
                f"{sources[0]['folder']} with {suite['randomize']}: their seeds are other "
                "trials; report runs of one randomisation"
            )
        suite["randomize"] = randomize
        if sources and shares_trials(run_suite) != shares_trials(suite):
            raise RunError(
                f"{folder} and {sources[0]['folder']} deal learned agents' trials differently "
                f"({LEARNED_TRIALS} {run_suite.get(LEARNED_TRIALS, ALL)} and "
                f"{suite.get(LEARNED_TRIALS, ALL)}): report runs of one deal"
            )
        if shares_trials(run_suite):
            suite[LEARNED_TRIALS] = SHARED
        for name, settings in run_suite["scenarios"].items():
            if name not in suite["scenarios"]:
                suite["scenarios"][name] = settings
                first_with[name] = folder
                continue
            changed = differences(suite["scenarios"][name], settings)
            if changed:
                raise RunError(
                    f"scenario {name!r} has other settings in {folder} than in "
                    f"{first_with[name]}: {'; '.join(changed[:3])}"
                )
        merge_twins(suite, run_suite, folder, first_with)
        for name, file in run_suite.get("scenario_files", {}).items():
            suite.setdefault("scenario_files", {}).setdefault(name, file)  # the first run's
        known = {c["name"] for c in suite["controllers"]}
        suite["controllers"] += [c for c in run_suite["controllers"] if c["name"] not in known]
        suite["does_not_apply"] += [
            pair for pair in run_suite["does_not_apply"] if pair not in suite["does_not_apply"]
        ]
        suite["seeds"] = sorted({*suite["seeds"], *run_suite["seeds"]})
        fewer = run_suite.get("scenario_seeds", {})
        for name in [*run_suite["scenarios"], *twin_scenarios(run_suite)]:
            ran_on.setdefault(name, set()).update(fewer.get(name, run_suite["seeds"]))
        suite["name"] = suite["name"] or run_suite.get("name")
        episodes = read_episodes(folder, suite=run_suite)
        kinds = {c["name"]: c["kind"] for c in run_suite["controllers"]}
        for episode in episodes:
            key = episode_key(episode)
            if key in episode_in and _same_reference(episode, kinds, cost_of[key]):
                continue  # the references every run adds: the same trial, the same episode
            if key in episode_in:
                raise RunError(
                    f"episode (scenario, controller, seed, training_seed) {key} is in "
                    f"{episode_in[key]} and "
                    f"in {folder}: report one of them"
                )
            episode_in[key] = folder
            cost_of[key] = episode.get("cost")
            results.append(episode_result(episode, folder))
        sources.append(
            {
                "folder": folder,
                "command": record.get("command"),
                "status": record.get("status"),
                "start_time": record.get("start_time"),
                "end_time": record.get("end_time"),
                "episodes": len(episodes),
                "jobs": record.get("jobs"),
            }
        )
    fewer = {n: sorted(s) for n, s in ran_on.items() if s != set(suite["seeds"])}
    if fewer:
        suite["scenario_seeds"] = fewer
    return suite, results, sources


def merge_twins(
    suite: dict[str, Any], run_suite: Mapping[str, Any], folder: str, first_with: dict[str, str]
) -> None:
    """Merge a run's no-change twins into ``suite`` (:mod:`.twins`): its changing scenarios'
    twins, the twins' settings and the controllers that play them, in order of first
    appearance; a :class:`RunError` for a scenario whose twin, or a twin whose settings,
    differ from an earlier run's (``first_with``: where each name was first read)."""
    for scenario, twin in twins_of(run_suite).items():
        known = suite.setdefault(TWINS, {}).setdefault(scenario, twin)
        first_with.setdefault(f"{TWINS}:{scenario}", folder)
        if known != twin:
            raise RunError(
                f"scenario {scenario!r} has the twin {twin!r} in {folder} but {known!r} in "
                f"{first_with[f'{TWINS}:{scenario}']}: report runs of one suite's twins"
            )
    for name, settings in twin_scenarios(run_suite).items():
        kept = suite.setdefault(TWIN_SCENARIOS, {})
        if name not in kept:
            kept[name], first_with[name] = settings, folder
        elif differences(kept[name], settings):
            raise RunError(
                f"twin {name!r} has other settings in {folder} than in {first_with[name]}: "
                f"{'; '.join(differences(kept[name], settings)[:3])}"
            )
    players = suite.setdefault(TWIN_PLAYERS, []) if TWIN_PLAYERS in run_suite else []
    players += [c for c in run_suite.get(TWIN_PLAYERS, []) if c not in players]


def _same_reference(episode: Mapping[str, Any], kinds: Mapping[str, str], cost: Any) -> bool:
    """Whether ``episode`` is a reference's (kind ``reference``: ``evaluate`` and
    ``leaderboard`` add them to every run) with the cost ``cost`` of the one already read."""
    return kinds.get(episode["controller"]) == "reference" and episode.get("cost") == cost


def write_report(
    folders: Sequence[str | os.PathLike],
    out: str | os.PathLike,
    force: bool = False,
    command: Sequence[str] = (),
    vector_figures: bool = False,
) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Merge ``folders`` and write the tables, ranking, figures and ``report.json`` into
    ``out`` (which must be empty, or ``force``: its earlier outputs cleared, and none of
    ``folders``; ``vector_figures``: the figures' vector copies too); returns (rows,
    sources)."""
    if not folders:
        raise RunError("report: give at least one run folder")
    target = check_out_dir(out, force=force)
    for folder in folders:
        if Path(folder).resolve() == target.resolve():
            raise RunError(f"--out {target} is one of the runs read: choose another folder")
    suite, results, sources = merge_runs(folders)
    check_out_usable(target, force=force)
    with out_lock(target, now()):
        check_out_dir(target, force=force)  # again, now that no other run can start there
        if force:
            clear_listed(target)
        try:
            rows = _write(target, suite, results, sources, command, vector_figures)
        except (OSError, BrokenProcessPool) as exc:  # a full disk, a killed worker
            problem = outside_problem(exc)
            if problem is None:
                raise
            raise RunFailed(f"{problem}; the report in {target} is incomplete") from None
    return rows, sources


def _write(
    target: Path,
    suite: dict[str, Any],
    results: list[EpisodeResult],
    sources: list[dict[str, Any]],
    command: Sequence[str],
    vector_figures: bool = False,
) -> list[dict[str, Any]]:
    """The report's files in the locked ``target``, each listed in its manifest."""
    from shipgym_baselines.leaderboard.outputs import write_results

    manifest = Manifest(target)
    with manifest.recording():  # each file listed as it is written
        rows = write_results(target, suite, results, vector_figures=vector_figures)
        document = {
            "command": list(command),
            "time": now(),
            "versions": versions(),
            "git_commit": git_commit(),
            "runs": sources,
            "suite": suite,
        }
        write_json(target / REPORT_FILE, document)
    manifest.compact(keep=(REPORT_FILE,))
    return rows


__all__ = ["REPORT_FILE", "merge_runs", "write_report"]
