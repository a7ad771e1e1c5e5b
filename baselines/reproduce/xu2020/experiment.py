"""Xu & Guedes Soares (2020) §5–§6: the identification, the path-following runs and the rows."""

from __future__ import annotations

from functools import partial
from typing import Any, NamedTuple

import numpy as np

from shipgym_baselines.errors import check_seeds
from shipgym_baselines.records.episodes import EpisodeResult
from shipgym_baselines.reproduce.episodes import seeded_episodes
from shipgym_baselines.reproduce.protocol import Outcome, Progress
from shipgym_baselines.reproduce.xu2020.controllers import CONTROLLERS, GAINS
from shipgym_baselines.reproduce.xu2020.identification import identification_rows, setting_row
from shipgym_baselines.reproduce.xu2020.metrics import EPISODE_METRICS, episode_figures
from shipgym_baselines.reproduce.xu2020.published import PUBLISHED
from shipgym_baselines.reproduce.xu2020.scenarios import (
    CASES,
    CURVED_INITIAL_SPEED,
    SETTINGS,
    build_scenario,
)


class FirstRuns(NamedTuple):
    """What the figures show: the first seed of the first gains design."""

    gains: str  # the design's label
    scenarios: dict[tuple[str, str], Any]  # (case, setting) -> scenario, in run order
    examples: dict[tuple[str, str, str], tuple[EpisodeResult, list[float]]]  # (case,
    # setting, controller) -> (result, ψd [rad] per step)


def run_experiment(
    seeds: int = 1,
    progress: Progress | None = None,
    settings: tuple[str, ...] = tuple(SETTINGS),
    gains: tuple[str, ...] = tuple(GAINS),
    cases: tuple[str, ...] = tuple(CASES),
    time_limit: float | None = None,
    curved_initial_speed: float | None = CURVED_INITIAL_SPEED,
    current_speed: float | None = None,
) -> Outcome:
    """The reproduction rows (plus ``setting``, ``gains``, ``seeds``, ``ours_std`` and, on
    the path rows, the run's initial speed and current); ``episodes``: :class:`FirstRuns`.

    ``settings``, ``gains``, ``cases``: subsets of :data:`SETTINGS`, :data:`GAINS`,
    :data:`CASES`; ``time_limit`` [s] shortens the episodes (quick runs);
    ``curved_initial_speed`` [m/s] (None: cruise speed); ``current_speed`` [m/s] (None:
    osaka_curved's 0.03 m/s).
    """
    check_seeds(seeds)
    for name, chosen, valid in (("settings", settings, SETTINGS), ("gains", gains, GAINS)):
        bad = [c for c in chosen if c not in valid]
        if bad or not chosen:
            raise ValueError(f"{name}: unknown or empty {bad}; valid: {list(valid)}")
    rows = identification_rows(settings, gains)
    first = FirstRuns(gains[0], {}, {})
    for case in cases:
        for setting in settings:
            scenario = build_scenario(
                case, setting, time_limit, curved_initial_speed, current_speed
            )
            first.scenarios[(case, setting)] = scenario
            current = scenario.config.disturbances.current
            conditions = {
                "initial_speed": float(scenario.initial_state()[scenario.model.state_index("u")]),
                "current_speed": float(current.speed),
                "current_direction_deg": float(current.direction_deg),
            }
            for label in gains:
                for cls in CONTROLLERS:
                    design = partial(cls, vyshnegradsky_ab=GAINS[label])
                    runs = seeded_episodes(design, scenario, seeds, progress)
                    if label == first.gains:
                        result, policy = runs[0]
                        first.examples[(case, setting, cls.name)] = (result, policy.desired_log)
                    figures = [episode_figures(r, p.desired_log) for r, p in runs]
                    published = PUBLISHED.get((case, cls.name), {})
                    for metric, (quantity, stat, _) in EPISODE_METRICS.items():
                        values = [f[metric] for f in figures]
                        paper = published[quantity][stat] if quantity in published else None
                        row = setting_row(
                            case,
                            cls.name,
                            metric,
                            np.mean(values),
                            paper,
                            setting,
                            label,
                            seeds,
                            np.std(values),
                        )
                        rows.append({**row, **conditions})
    return Outcome(rows, first)
