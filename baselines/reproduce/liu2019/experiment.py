"""Liu et al. (2019) §4: the episodes (case × controller × unit reading) and the rows."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from baselines.classical.nmpc import NMPC, NMPCLambdaLSSVM, NMPCWeightedLSSVM
from baselines.errors import check_seeds
from baselines.reproduce.episodes import seeded_episodes
from baselines.reproduce.protocol import Outcome, Progress
from baselines.reproduce.rows import reproduction_row
from baselines.variants import scenario_variant

CASES = {  # scenario -> (paper's case, parameters that change)
    "rudder_aging": ("Case 1", ("Tc",)),
    "current_shift": ("Case 2", ("d0",)),
    "maneuverability_change": ("Case 3", ("K", "T1", "T2", "T3", "d0", "beta", "Tc")),
}
CONTROLLERS = (NMPCLambdaLSSVM, NMPCWeightedLSSVM, NMPC)
READINGS = ("si", "rudder_degrees")

#: Liu et al. (2019) §4.1–4.3 (SPEC §11): ACE [m] and t_c [s]; inf = "never" (|e| never
#: stays below 0.05 m)
PUBLISHED = {
    ("rudder_aging", "nmpc_lambda_lssvm"): (0.495, 35.5),
    ("rudder_aging", "nmpc_wlssvm"): (0.508, 36.0),
    ("rudder_aging", "nmpc"): (0.502, 38.5),
    ("current_shift", "nmpc_lambda_lssvm"): (0.427, 32.0),
    ("current_shift", "nmpc_wlssvm"): (0.488, 33.5),
    ("current_shift", "nmpc"): (0.544, math.inf),
    ("maneuverability_change", "nmpc_lambda_lssvm"): (0.449, 52.0),
    ("maneuverability_change", "nmpc_wlssvm"): (0.451, 51.5),
    ("maneuverability_change", "nmpc"): (0.502, math.inf),
}


def run_experiment(
    seeds: int = 1, progress: Progress | None = None, readings: tuple[str, ...] = READINGS
) -> Outcome:
    """The rows of SPEC §9b (plus ``unit_reading``, ``seeds``): per reading, case and
    controller our ACE and t_c, means over ``seeds``, beside the paper's.

    ``episodes``: (case, reading) -> (scenario, {controller: (result, policy) of seed 0}).
    """
    check_seeds(seeds)
    rows: list[dict[str, Any]] = []
    episodes: dict[tuple[str, str], tuple[Any, dict[str, tuple[Any, Any]]]] = {}
    for reading in readings:
        for case in CASES:
            scenario = scenario_variant(case, reading)
            first: dict[str, tuple[Any, Any]] = {}
            for cls in CONTROLLERS:
                runs = seeded_episodes(cls, scenario, seeds, progress)
                first[cls.name] = runs[0]
                ace = float(np.mean([r.metrics["ace"] for r, _ in runs]))
                t_c = float(np.mean([r.metrics["t_c"] for r, _ in runs]))
                paper_ace, paper_tc = PUBLISHED[(case, cls.name)]
                for metric, ours, paper in (("ace", ace, paper_ace), ("t_c", t_c, paper_tc)):
                    rows.append(
                        reproduction_row(
                            case, cls.name, metric, ours, paper, seeds, unit_reading=reading
                        )
                    )
            episodes[(case, reading)] = (scenario, first)
    return Outcome(rows, episodes)
