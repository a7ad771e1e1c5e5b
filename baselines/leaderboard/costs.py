"""The leaderboard's first estimate of a run's time, from the recorded costs.

:func:`estimate_cpu_s` adds, over a run's jobs, the recorded CPU seconds per control step of
the controller on the scenario's ship × the control steps of the scenario's time limit × the
job's seeds; :func:`eta_line` and :func:`tables_line` are the lines a run prints.  The costs
are measured by :mod:`shipgym_baselines.studies.run_costs` (docs/leaderboard-cost.md).
"""

from __future__ import annotations

import functools
import json
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from shipgym.config import is_path
from shipgym.notices import duration
from shipgym.scenarios.loader import Scenario

if TYPE_CHECKING:
    from shipgym_baselines.leaderboard.jobs import Job


def limit_steps(scenario: Scenario) -> float:
    """Control steps of ``scenario``'s time limit (an episode's most steps)."""
    return scenario.config.time_limit / scenario.control_period


#: the recorded costs (``shipgym_baselines.studies.run_costs.record_costs``), shipped beside
#: the references' tables
COSTS_FILE = Path(__file__).parents[1] / "reference_data" / "leaderboard_costs.json"
#: the kinds whose fallback a controller without a recorded cost takes
FALLBACK_KINDS = ("classical", "learned")
#: CPU seconds of the tables, ranking and figures per scenario of a run, after its episodes
#: (measured: ``shipgym report`` of a default run, 60 scenarios, 24 controllers and 5,760
#: episodes with their twins: 284 CPU s and 224 s wall on 2 cores shared with a test run;
#: the scenario figures of two dozen controllers each are most of it)
TABLES_CPU_S_PER_SCENARIO = 4.7


@functools.lru_cache(maxsize=1)
def recorded_costs() -> dict[str, Any]:
    """The shipped recorded costs (:data:`COSTS_FILE`), read once."""
    return json.loads(COSTS_FILE.read_text())


def median(values: Iterable[float]) -> float:
    return float(np.median(list(values)))


def step_cost(
    job: Job, ship: str, costs: Mapping[str, Any] | None = None, from_table: bool = True
) -> float:
    """The recorded CPU seconds per control step of the time limit of ``job``'s controller
    on ``ship``: its own (by spec), the oracle's computed cost when it does not read its
    table (``from_table`` False, or the job recomputes), a privileged reference read from its
    table at the oracle's table cost unless recorded itself, else its kind's median (a plug-in,
    a trained agent: :data:`FALLBACK_KINDS`; a ship not recorded: the median over ships)."""
    from shipgym_baselines.privileged import grants_truth
    from shipgym_baselines.registry import controller_kind, controller_label

    costs = costs if costs is not None else recorded_costs()
    spec = job.controller if isinstance(job.controller, str) else job.controller.controller
    if grants_truth(job.controller) and (job.references == "recompute" or not from_table):
        per_ship = costs["oracle_computed"]
    elif grants_truth(job.controller) and spec not in costs["cpu_s_per_limit_step"]:
        # a reference read from its table costs what reading the oracle's does
        per_ship = costs["cpu_s_per_limit_step"]["oracle"]
    elif spec in costs["cpu_s_per_limit_step"]:
        per_ship = costs["cpu_s_per_limit_step"][spec]
    else:
        kind = controller_kind(controller_label(job.controller))
        per_ship = costs["fallback"][kind if kind in FALLBACK_KINDS else "classical"]
    return per_ship[ship] if ship in per_ship else median(per_ship.values())


def estimate_cpu_s(
    jobs: Iterable[Job], scenarios: Mapping[str, Scenario], costs: Mapping[str, Any] | None = None
) -> float:
    """CPU seconds the leaderboard's ``jobs`` take by the recorded costs: per job, its
    controller's :func:`step_cost` on the scenario's ship × the scenario's time limit in
    control steps × its seeds.  The oracle reads its table on a named scenario, and is
    computed on a scenario file (the shipped table holds catalogue and held-out trials)."""
    total = 0.0
    for job in jobs:
        scenario = scenarios[job.scenario]
        per_step = step_cost(job, scenario.model.name, costs, from_table=not is_path(job.scenario))
        total += per_step * limit_steps(scenario) * len(job.seeds)
    return total


#: what the estimate of :func:`eta_line` leaves out
COMPILATIONS = "one-off C compilations on a new machine come on top, each announced"


def tables_line(scenarios: int, workers: int) -> str:
    """The line before a run's tables, ranking and figures are written: how many scenarios
    and about how long (:data:`TABLES_CPU_S_PER_SCENARIO` each, over the ``workers``)."""
    wall = TABLES_CPU_S_PER_SCENARIO * scenarios / max(1, min(workers, scenarios))
    plural = "s" if scenarios != 1 else ""
    return (
        f"shipgym: writing the tables, ranking and figures of {scenarios} scenario{plural} "
        f"(about {duration(wall)})"
    )


def eta_line(
    jobs: Sequence[Job], scenarios: Mapping[str, Scenario], workers: int, episodes: int
) -> str:
    """The leaderboard's first line: the episodes to run (of ``episodes`` in the run), the
    workers and the wall time: :func:`estimate_cpu_s` and the tables' time
    (:data:`TABLES_CPU_S_PER_SCENARIO` × ``scenarios``) over the workers (the run is
    CPU-bound; its jobs are spread longest first)."""
    todo = sum(len(job.seeds) for job in jobs)
    count = f"{todo:,} episodes" if todo == episodes else f"{todo:,} of {episodes:,} episodes"
    cpu = estimate_cpu_s(jobs, scenarios) + TABLES_CPU_S_PER_SCENARIO * len(scenarios)
    wall = cpu / max(min(workers, len(jobs)), 1)
    plural = "" if workers == 1 else "s"
    return (
        f"leaderboard: {count} on {workers} worker{plural}, about {duration(wall)} (recorded "
        f"costs; {COMPILATIONS})"
    )
