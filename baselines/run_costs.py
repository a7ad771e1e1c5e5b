"""Where a leaderboard run's CPU time goes: per controller, per ship and per control step.

:func:`profile_suite` runs a suite's jobs as the leaderboard does
(:func:`shipgym_baselines.leaderboard.work`, one process, a few evaluation seeds, a learned
agent's first training seed only) and measures each job's CPU seconds
(:func:`time.process_time`: not inflated by other work on the machine) and, inside them,
the CPU seconds of the controller's ``act`` calls (:func:`shipgym_baselines.evaluation.act_clock`);
the rest of a job is the env (stepping, reset, trial building) and the controller's
per-episode setup.  The oracle's jobs read its reference table and cost next to nothing.
``shipgym bench leaderboard`` prints it.
"""

from __future__ import annotations

import os
import time
from collections import defaultdict
from collections.abc import Iterable, Mapping
from typing import Any

from shipgym_baselines import evaluation
from shipgym_baselines.plugins import ControllerSpec


def _entry() -> dict[str, float]:
    return {"episodes": 0, "steps": 0, "cpu_s": 0.0, "act_cpu_s": 0.0, "suite_cpu_s": 0.0}


def _finish(entry: dict[str, float]) -> dict[str, float]:
    """``entry`` with its per-step figures [µs] and the share of ``act``."""
    steps = max(entry["steps"], 1)
    return {
        **entry,
        "us_per_step": 1e6 * entry["cpu_s"] / steps,
        "act_us_per_step": 1e6 * entry["act_cpu_s"] / steps,
        "other_us_per_step": 1e6 * (entry["cpu_s"] - entry["act_cpu_s"]) / steps,
    }


def profile_suite(
    suite: str = "default",
    seeds: int = 1,
    controllers: Iterable[ControllerSpec] | None = None,
    scenarios: Iterable[str] | None = None,
    show_progress: bool = False,
) -> dict[str, Any]:
    """CPU seconds of ``suite``'s jobs with ``seeds`` evaluation seeds (the suite's first
    ones), optionally only ``controllers`` / ``scenarios`` (names as the suite gives them).

    Returns ``cpu_s`` (all measured jobs), ``suite_cpu_s`` (the estimate for the whole suite:
    each (controller, scenario) cell's CPU per episode × the suite's seeds × training
    seeds; a learned agent's batch of all seeds costs less per episode than measured with
    one), ``per_controller`` / ``per_ship`` / ``per_controller_ship`` entries of
    ``episodes``, ``steps``, ``cpu_s``, ``act_cpu_s`` (the controller's ``act`` calls),
    ``suite_cpu_s``, ``us_per_step``, ``act_us_per_step`` and ``other_us_per_step`` (env,
    setup) [µs], and the machine's ``load_average`` (1 min) at the start and the end.
    ``show_progress``: a progress bar of the jobs on stderr.
    """
    import sys

    import torch
    from tqdm import tqdm

    from shipgym_baselines.errors import check_seeds
    from shipgym_baselines.evaluation import EVAL_SEED_OFFSET
    from shipgym_baselines.leaderboard import (
        check_controllers,
        plan_jobs,
        suite_record,
        suite_scenario,
        work,
    )
    from shipgym_baselines.privileged import grants_truth
    from shipgym_baselines.registry import controller_label, training_seeds
    from shipgym_baselines.suite import load_suite

    torch.set_num_threads(1)
    check_seeds(seeds, "--seeds")
    spec = load_suite(suite)
    names = list(controllers) if controllers else list(spec.controllers)
    labels = check_controllers(names)
    seeds_of = {label: training_seeds(c) for label, c in zip(labels, names, strict=True)}
    chosen = list(scenarios) if scenarios else spec.all_scenarios()
    loaded = {s: suite_scenario(s) for s in chosen}
    record = suite_record(spec, names, loaded, list(range(seeds)), seeds_of)
    skip = {tuple(pair) for pair in record["does_not_apply"]}
    measured = {label: ts[:1] for label, ts in seeds_of.items()}  # a learned agent's first
    seed_list = [EVAL_SEED_OFFSET + i for i in range(seeds)]
    jobs = plan_jobs(names, record["scenarios"], seed_list, measured, record["randomize"], skip)
    ship_of = {s: sc.model.name for s, sc in loaded.items()}
    load_start = os.getloadavg()[0]
    cells: dict[tuple[str, str], dict[str, float]] = defaultdict(_entry)
    for job in tqdm(jobs, desc="profile", file=sys.stderr, disable=not show_progress):
        start = time.process_time()
        with evaluation.act_clock(time.process_time):
            results = work(job)
        cpu = time.process_time() - start
        from_table = grants_truth(job.controller)
        cell = cells[(controller_label(job.controller), job.scenario)]
        cell["episodes"] += len(results)
        cell["cpu_s"] += cpu
        for r in results:
            steps = max(len(r.trajectory.get("t", ())) - 1, 0)
            cell["steps"] += steps
            if not from_table:
                cell["act_cpu_s"] += 1e-3 * r.metrics["compute_ms"] * steps
    per_controller: dict[str, dict[str, float]] = defaultdict(_entry)
    per_ship: dict[str, dict[str, float]] = defaultdict(_entry)
    per_pair: dict[str, dict[str, dict[str, float]]] = defaultdict(lambda: defaultdict(_entry))
    for (label, scenario), cell in cells.items():
        runs = spec.seeds * len(seeds_of[label])
        cell["suite_cpu_s"] = cell["cpu_s"] / max(cell["episodes"], 1) * runs
        for target in (
            per_controller[label],
            per_ship[ship_of[scenario]],
            per_pair[label][ship_of[scenario]],
        ):
            for key, value in cell.items():
                target[key] += value
    return {
        "suite": spec.name,
        "seeds": seeds,
        "suite_seeds": spec.seeds,
        "scenarios": len(chosen),
        "jobs": len(jobs),
        "cpu_s": sum(c["cpu_s"] for c in cells.values()),
        "suite_cpu_s": sum(c["suite_cpu_s"] for c in cells.values()),
        "load_average": {"start": load_start, "end": os.getloadavg()[0]},
        "per_controller": _sorted(per_controller),
        "per_ship": _sorted(per_ship),
        "per_controller_ship": {
            label: {ship: _finish(e) for ship, e in sorted(ships.items())}
            for label, ships in sorted(
                per_pair.items(), key=lambda item: -per_controller[item[0]]["cpu_s"]
            )
        },
    }


def _sorted(entries: Mapping[str, dict[str, float]]) -> dict[str, dict[str, float]]:
    """The entries, most CPU first, with their per-step figures."""
    ordered = sorted(entries.items(), key=lambda item: -item[1]["cpu_s"])
    return {name: _finish(entry) for name, entry in ordered}
