"""Xu et al. (2021) §5.2: the episodes of every controller and the rows."""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from shipgym.models import MODELS
from shipgym_baselines.errors import check_seeds
from shipgym_baselines.records.episodes import EpisodeResult
from shipgym_baselines.reproduce.episodes import seeded_episodes
from shipgym_baselines.reproduce.protocol import Outcome, Progress
from shipgym_baselines.reproduce.rows import reproduction_row as _row
from shipgym_baselines.reproduce.xu2021.claims import claims
from shipgym_baselines.reproduce.xu2021.controllers import CONTROLLERS, PID, Recorded
from shipgym_baselines.reproduce.xu2021.current import DisturbanceLog
from shipgym_baselines.reproduce.xu2021.linearised import linear_analysis
from shipgym_baselines.reproduce.xu2021.metrics import PHASES, episode_figures
from shipgym_baselines.reproduce.xu2021.scenario import build_scenario


class FirstRuns(NamedTuple):
    """What the figures show: the scenario and, per controller, its first seed's episode."""

    scenario: Any
    examples: dict[str, tuple[EpisodeResult, Recorded, dict[str, np.ndarray]]]  # label ->
    # (result, the recorded policy, the disturbances the plant saw)


def _mean_std(values: list[Any]) -> tuple[Any, float | None]:
    """Mean and population std over seeds: booleans -> all(); inf stays inf; NaN -> None."""
    if all(isinstance(v, bool) for v in values):
        return all(values), None
    a = np.asarray(values, dtype=float)
    if np.isnan(a).any():
        return None, None
    if np.isinf(a).any():
        return float(np.mean(a)), None
    return float(np.mean(a)), float(np.std(a))


def run_experiment(
    seeds: int = 1,
    progress: Progress | None = None,
    controllers: tuple[str, ...] = tuple(CONTROLLERS),
    time_limit: float | None = None,
) -> Outcome:
    """The reproduction rows (plus ``seeds``, ``ours_std``); ``episodes``: :class:`FirstRuns`.

    ``controllers``: labels of :data:`CONTROLLERS`; ``time_limit`` [s] shortens the 2000 s
    episode (the current's switch moves to half of it) for a quick run.
    """
    check_seeds(seeds)
    unknown = [c for c in controllers if c not in CONTROLLERS]
    if unknown:
        raise ValueError(f"unknown controller label(s) {unknown}; known: {list(CONTROLLERS)}")
    if "esso_osaka" not in MODELS:
        raise ValueError("xu2021 needs the esso_osaka ship model, which is not registered")
    scenario = build_scenario(time_limit)
    first = FirstRuns(scenario, {})
    means: dict[tuple[str, str, str], Any] = {}
    rows: list[dict[str, Any]] = []
    for label in controllers:
        log = DisturbanceLog()
        runs = seeded_episodes(
            lambda label=label: Recorded(CONTROLLERS[label](), label),
            scenario,
            seeds,
            progress,
            after_episode=log.read,
        )
        first.examples[label] = (*runs[0], log.episodes[0])
        per_seed = [episode_figures(scenario, result, recorder) for result, recorder in runs]
        for phase in PHASES:
            for metric in per_seed[0][phase]:
                mean, std = _mean_std([f[phase][metric] for f in per_seed])
                means[(phase, label, metric)] = mean
                rows.append(_row(phase, label, metric, mean, None, seeds, std))
    rows += claims(means, controllers, seeds)
    for label, lin in linear_analysis(scenario).items():
        if label not in controllers:
            continue
        rows.append(_row("linearised", label, "max_pole_real", lin["max_pole_real"], None, 1))
        rows.append(_row("linearised", label, "crossover", lin["crossover"], None, 1))
        rows.append(_row("linearised", label, "phase_margin_deg", lin["phase_margin"], None, 1))
        paper = True if label != PID else None  # §3–4: UGAS (the PID is not analysed)
        rows.append(_row("linearised", label, "stable", bool(lin["max_pole_real"] < 0), paper, 1))
    return Outcome(rows, first)
