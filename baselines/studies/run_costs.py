"""Where a leaderboard run's CPU time goes: per controller, per ship and per control step.

:func:`profile_suite` runs a suite's jobs as the leaderboard does
(:func:`shipgym_baselines.leaderboard.jobs.work`, one process, a few evaluation seeds, a learned
agent's first training seed only) and measures each job's CPU seconds
(:func:`time.process_time`: not inflated by other work on the machine) and, inside them,
the CPU seconds of the controller's ``act`` calls (:func:`shipgym_baselines.evaluation.act_clock`);
the rest of a job is the env (stepping, reset, trial building) and the controller's
per-episode setup.  The oracle's jobs read its reference table and cost next to nothing.
``shipgym bench leaderboard`` prints it.
"""

from __future__ import annotations

import json
import os
import time
from collections import defaultdict
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from shipgym_baselines import evaluation
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET
from shipgym_baselines.leaderboard.costs import COSTS_FILE, FALLBACK_KINDS, limit_steps, median
from shipgym_baselines.plugins import ControllerSpec


def _entry() -> dict[str, float]:
    return {
        "episodes": 0,
        "steps": 0,
        "limit_steps": 0.0,
        "cpu_s": 0.0,
        "act_cpu_s": 0.0,
        "suite_cpu_s": 0.0,
    }


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

    Returns ``cpu_s`` (all measured jobs), ``suite_cpu_s`` (the estimate for the whole
    suite: each (controller, scenario) cell's CPU per episode × the suite's seeds ×
    training seeds, or × 1 where the suite shares the trials, whose learned jobs are
    measured as the suite runs them, all training seeds in one lockstep job),
    ``per_controller`` / ``per_ship`` / ``per_controller_ship`` entries of ``episodes``,
    ``steps``, ``cpu_s``, ``act_cpu_s`` (the controller's ``act`` calls), ``suite_cpu_s``,
    ``us_per_step``, ``act_us_per_step`` and ``other_us_per_step`` (env, setup) [µs], and
    the machine's ``load_average`` (1 min) at the start and the end.  ``show_progress``: a
    progress bar of the jobs on stderr.
    """

    import sys

    import torch
    from tqdm import tqdm

    from shipgym_baselines.errors import check_seeds
    from shipgym_baselines.leaderboard.jobs import (
        check_controllers,
        plan_jobs,
        suite_record,
        suite_scenario,
        work,
    )
    from shipgym_baselines.privileged import grants_truth
    from shipgym_baselines.records.trials import SHARED
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
    shared = spec.learned_trials == SHARED
    # a suite that shares the trials: a learned agent's training seeds in one lockstep job,
    # as the suite runs them; else its first training seed on all seeds
    measured = seeds_of if shared else {label: ts[:1] for label, ts in seeds_of.items()}
    seed_list = [EVAL_SEED_OFFSET + i for i in range(seeds)]
    jobs = plan_jobs(
        names, record["scenarios"], seed_list, measured, record["randomize"], skip, shared=shared
    )
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
        cell["limit_steps"] += len(results) * limit_steps(loaded[job.scenario])
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
        suite_seeds = len(spec.scenario_seeds(range(spec.seeds)).get(scenario, range(spec.seeds)))
        runs = suite_seeds * (1 if shared else len(seeds_of[label]))
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


# --- recorded costs: measured here, read by the leaderboard's estimate ----------------------

#: evaluation seeds of the other controllers' measured jobs (in lockstep, as a run's)
OTHER_SEEDS = 3
#: evaluation seeds of a learned agent's measured job (the quick and default suites share
#: them among its training seeds: one lockstep job of 8 seeds in the default suite)
LEARNED_SEEDS = 8


def _per_step(entry: Mapping[str, float]) -> float:
    """CPU seconds per control step of the time limit of an entry of :func:`profile_suite`."""
    return entry["cpu_s"] / max(entry["limit_steps"], 1.0)


def record_costs(
    suite: str = "quick", show_progress: bool = False, cache: Path | None = None
) -> dict[str, Any]:
    """Measure the costs :func:`estimate_cpu_s` reads (written to :data:`COSTS_FILE` by
    ``python -m shipgym_baselines.studies.run_costs``): per controller and ship, CPU seconds per
    control step of the scenario's time limit, from :func:`profile_suite` on ``suite``
    (classical controllers and references with :data:`OTHER_SEEDS` evaluation seeds, learned
    agents with :data:`LEARNED_SEEDS`, each job's seeds in lockstep as a run's; a learned
    agent's first training seed); the oracle computed
    (not read from its table) on the suite's first scenario of each ship, 1 seed; and per
    kind and ship the median over the kind's controllers (the fallback of a plug-in).
    ``cache``: a folder keeping each profile once measured (a second call reads it)."""
    import platform

    from shipgym_baselines.leaderboard.jobs import Job, suite_scenario, work
    from shipgym_baselines.records.runrecord import git_commit
    from shipgym_baselines.registry import controller_kind, controller_label
    from shipgym_baselines.suite import load_suite

    spec = load_suite(suite)
    labels = [controller_label(c) for c in spec.controllers]
    kinds = dict(zip(labels, map(controller_kind, labels), strict=True))
    learned = [
        c for c, label in zip(spec.controllers, labels, strict=True) if kinds[label] == "learned"
    ]
    others = [c for c in spec.controllers if c not in learned]
    start = time.process_time()

    def profile(part: str, controllers: list[ControllerSpec], seeds: int) -> dict[str, Any]:
        file = None if cache is None else cache / f"{spec.name}_{part}.json"
        if file is not None and file.is_file():
            return json.loads(file.read_text())
        found = profile_suite(suite, seeds, controllers, show_progress=show_progress)
        if file is not None:
            file.write_text(json.dumps(found))
        return found

    profiles = [
        profile("others", others, OTHER_SEEDS),
        profile("learned", learned, LEARNED_SEEDS),
    ]
    per_step: dict[str, dict[str, float]] = {}
    for found in profiles:
        for label, ships in found["per_controller_ship"].items():
            per_step[label] = {ship: _per_step(entry) for ship, entry in ships.items()}
    first: dict[str, str] = {}
    for name in spec.all_scenarios():
        first.setdefault(suite_scenario(name).model.name, name)
    oracle_computed = {}
    for ship, name in sorted(first.items()):
        job = Job("oracle", name, (EVAL_SEED_OFFSET,), None, _randomize(spec))
        clock = time.process_time()
        work(job._replace(references="recompute"))  # the oracle run, not read from its table
        oracle_computed[ship] = (time.process_time() - clock) / limit_steps(suite_scenario(name))
    fallback = {
        kind: {
            ship: median(
                steps[ship] for c, steps in per_step.items() if kinds[c] == kind and ship in steps
            )
            for ship in sorted(first)
        }
        for kind in FALLBACK_KINDS
    }
    return {
        "about": "CPU seconds per control step of a scenario's time limit (time_limit / "
        "control_period), per controller and ship, as the leaderboard runs its jobs; "
        "shipgym_baselines.leaderboard.costs.estimate_cpu_s reads it",
        "measured": {
            "suite": spec.name,
            "commit": git_commit(),
            "machine": platform.processor() or platform.machine(),
            "cpu_s": time.process_time() - start,
            "profiles_cpu_s": [found["cpu_s"] for found in profiles],
            "load_average": [found["load_average"] for found in profiles],
            "command": "python -m shipgym_baselines.studies.run_costs",
        },
        "cpu_s_per_limit_step": dict(sorted(per_step.items())),
        "oracle_computed": oracle_computed,
        "fallback": fallback,
    }


def _randomize(spec: Any) -> dict[str, Any] | None:
    return None if spec.randomize is None else spec.randomize.model_dump(mode="json")


if __name__ == "__main__":
    import sys

    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else None  # the profiles' cache
    costs = record_costs(show_progress=True, cache=folder)
    COSTS_FILE.write_text(json.dumps(costs, indent=1) + "\n")
    print(f"wrote {COSTS_FILE}")
