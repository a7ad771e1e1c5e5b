"""What adaptation is worth: per trial the headroom C_frozen / C_oracle (the optimum that
never adapts against the oracle), per ranking row the cost against the frozen optimum
(``cost_vs_frozen_gmean``), P(C < C_frozen) and the gap closed with their intervals, and
the headroom per ship × change family (the method: :mod:`.ranking`)."""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterable, Iterator, Mapping, Sequence
from typing import Any

import numpy as np

from shipgym.scenarios.families import FAMILIES
from shipgym_baselines.privileged import ORACLE, ORACLE_FROZEN
from shipgym_baselines.scoring.intervals import (
    AGGREGATE_REPS,
    bounds,
    finite_bounds,
    finite_iqm,
    finite_or_none,
    float_or_nan,
    geometric_mean,
    interval_estimate,
)
from shipgym_baselines.scoring.scores import run_matrix

#: the gap closed is averaged over the trials where knowing the change is worth at least
#: this factor (headroom C_frozen / C_oracle)
GAP_HEADROOM = 1.2
#: an aggregate row's cost against the frozen optimum, the geometric mean of C_frozen / C
#: (None: no frozen optimum's episodes)
GAIN = "cost_vs_frozen_gmean"
#: the fields of an ``aggregate.json`` object against the frozen optimum, in order
GAP_FIELDS = (
    GAIN,
    f"{GAIN}_ci95",
    "prob_beats_frozen",
    "prob_beats_frozen_ci95",
    "gap_closed_iqm",
    "gap_closed_iqm_ci95",
    "gap_trials",
)
#: the gap fields of a row without the frozen optimum's episodes
NO_GAP: dict[str, Any] = dict.fromkeys(GAP_FIELDS)

#: what the headroom table and the gap columns mean (leaderboard.md and the page)
HEADROOM_EXPLAINED = (
    f"What knowing the change is worth: the cost of {ORACLE_FROZEN} (the same NMPC as "
    f"{ORACLE}, its truth frozen at the episode's start: the optimum that never adapts) "
    f"over {ORACLE}'s, geometric mean over the catalogue scenarios' trials of each ship "
    "and change family (how many below). 1: adapting is worth nothing."
)


def _trial_costs(episodes: Iterable[Mapping[str, Any]], controller: str) -> dict:
    """(scenario, seed) → the cost of ``controller``'s episode of that trial (a reference's:
    one per trial)."""
    return {
        (ep["scenario"], int(ep["seed"])): float_or_nan(ep.get("cost"))
        for ep in episodes
        if ep["controller"] == controller
    }


def trial_headroom(episodes: Iterable[Mapping[str, Any]]) -> dict[tuple[str, int], float]:
    """(scenario, seed) → headroom C_frozen / C_oracle of every trial with both references'
    episodes, both costs finite and positive: what knowing the change is worth there."""
    episodes = list(episodes)
    oracle = _trial_costs(episodes, ORACLE)
    out = {}
    for trial, frozen in _trial_costs(episodes, ORACLE_FROZEN).items():
        c_ref = oracle.get(trial, math.nan)
        if math.isfinite(c_ref) and c_ref > 0.0 and math.isfinite(frozen) and frozen > 0.0:
            out[trial] = frozen / c_ref
    return out


def gmean_headroom(
    headroom: Mapping[tuple[str, int], float], scenarios: Iterable[str]
) -> tuple[float, int] | None:
    """(geometric mean of the headroom, trials) over the trials of ``scenarios`` in
    ``headroom`` (:func:`trial_headroom`); None without any."""
    wanted = set(scenarios)
    values = [h for (s, _), h in headroom.items() if s in wanted]
    if not values:
        return None
    return float(geometric_mean(np.array(values))), len(values)


def _gain_estimates(gains: np.ndarray) -> np.ndarray:
    """[geometric mean of C_frozen / C, P(C < C_frozen) + ½ P(C = C_frozen)]: for positive
    finite costs C_frozen / C > 1 exactly when C < C_frozen and = 1 exactly when equal
    (IEEE division is correctly rounded), so one matrix gives both."""
    beats = np.mean((gains > 1.0) + 0.5 * (gains == 1.0))
    return np.array([geometric_mean(gains), beats])


def _gap_estimate(gaps: np.ndarray) -> np.ndarray:
    return np.array([finite_iqm(gaps)])


def gap_matrices(
    scored: Sequence[Mapping[str, Any]], controller: str, tasks: list[str]
) -> dict[str, np.ndarray] | None:
    """The (runs, tasks) matrices of ``controller`` against the frozen optimum, runs as
    :func:`run_matrix` orders them: ``gain`` C_frozen / C, ``beats`` 1 where C < C_frozen
    (½ where equal, else 0), ``gap`` log(C_frozen / C) / log(C_frozen / C_oracle) where the
    trial's headroom is at least :data:`GAP_HEADROOM` (NaN elsewhere) and ``seed`` the
    evaluation seeds.  None unless ``oracle_frozen`` has every trial of the row with a
    finite positive cost."""
    headroom = trial_headroom(scored)
    frozen_cost = _trial_costs(scored, ORACLE_FROZEN)
    seeds = run_matrix(scored, controller, tasks, "seed").astype(np.int64)
    keys = [[(task, int(seed)) for task, seed in zip(tasks, row, strict=True)] for row in seeds]
    if not all(key in headroom for row in keys for key in row):
        return None
    cost = run_matrix(scored, controller, tasks, "cost")
    frozen = np.array([[frozen_cost[key] for key in row] for row in keys], dtype=np.float64)
    room = np.array([[headroom[key] for key in row] for row in keys], dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        gain = frozen / cost
        gap = np.where(room >= GAP_HEADROOM, np.log(gain) / np.log(room), math.nan)
    beats = (cost < frozen) + 0.5 * (cost == frozen)
    return {"gain": gain, "beats": beats.astype(np.float64), "gap": gap, "seed": seeds}


def gap_fields(
    scored: Sequence[Mapping[str, Any]],
    controller: str,
    tasks: list[str],
    reps: int = AGGREGATE_REPS,
    seed: int = 0,
) -> dict[str, Any]:
    """The gap fields of an ``aggregate.json`` row (module doc; :data:`NO_GAP` without the
    frozen optimum's episodes on every trial of the row): each with rliable's stratified
    bootstrap (the same seed and so the same resamples as the row's other fields)."""
    m = gap_matrices(scored, controller, tasks)
    if m is None:
        return dict(NO_GAP)
    point, interval = interval_estimate(m["gain"], _gain_estimates, reps, seed)
    qualified = np.isfinite(m["gap"])
    out = {
        GAIN: finite_or_none(point[0]),
        f"{GAIN}_ci95": finite_bounds(interval, 0),
        "prob_beats_frozen": float(point[1]),
        "prob_beats_frozen_ci95": bounds(interval, 1),
        "gap_closed_iqm": None,
        "gap_closed_iqm_ci95": None,
        "gap_trials": 0,
    }
    if qualified.any():
        gap_point, gap_interval = interval_estimate(m["gap"], _gap_estimate, reps, seed)
        trials = {(t, int(s)) for t, s, q in _cells(tasks, m["seed"], qualified) if q}
        out["gap_closed_iqm"] = finite_or_none(gap_point[0])
        out["gap_closed_iqm_ci95"] = finite_bounds(gap_interval, 0)
        out["gap_trials"] = len(trials)
    return out


def _cells(tasks: list[str], seeds: np.ndarray, mask: np.ndarray) -> Iterator[tuple]:
    """(task, seed, mask value) of every cell of a (runs, tasks) matrix."""
    for r in range(seeds.shape[0]):
        for c, task in enumerate(tasks):
            yield task, seeds[r, c], bool(mask[r, c])


def scenario_ships(settings: Mapping[str, Mapping[str, Any]]) -> dict[str, str]:
    """scenario → its ship (the model's name) from scenario settings as ``run.json`` keeps
    them (``scenarios``: name → the scenario's settings, ``ship.model``)."""
    out = {}
    for name, config in settings.items():
        ship = config.get("ship") if isinstance(config, Mapping) else None
        if not isinstance(ship, Mapping) or not isinstance(ship.get("model"), str):
            raise ValueError(f"scenario {name!r}: its settings name no ship model (ship.model)")
        out[name] = ship["model"]
    return out


def headroom_table(
    episodes: Sequence[Mapping[str, Any]],
    ships: Mapping[str, str],
    families: Mapping[str, str],
    splits: Mapping[str, str],
    split: str = "catalogue",
) -> list[dict[str, Any]]:
    """The headroom per ship × change family over the trials of ``split``'s scenarios:
    rows ``ship``, ``family``, ``scenarios`` (their names), ``trials`` and
    ``headroom_gmean`` (the geometric mean of C_frozen / C_oracle over the trials,
    :func:`trial_headroom`); ships in the order of ``ships``, families in the order of
    :data:`shipgym.scenarios.families.FAMILIES`.  ``ships`` / ``families``: scenario → its
    ship (:func:`scenario_ships`) / change family
    (:func:`~shipgym_baselines.scoring.splits.suite_families`); a scenario of the split
    missing from either raises ValueError.  Empty without both references' episodes."""
    headroom = trial_headroom(episodes)
    mine = sorted({s for s, _ in headroom if splits.get(s, "catalogue") == split})
    for what, known in (("ship", ships), ("change family", families)):
        missing = [s for s in mine if s not in known]
        if missing:
            raise ValueError(f"headroom_table: no {what} for scenario(s) {', '.join(missing)}")
    order = list(dict.fromkeys(ships.values()))
    family_order = list(FAMILIES)
    cells: dict[tuple[str, str], list[str]] = defaultdict(list)
    for s in mine:
        cells[(ships[s], families[s])].append(s)
    rows = []
    for ship, family in sorted(cells, key=lambda k: (order.index(k[0]), family_order.index(k[1]))):
        names = cells[(ship, family)]
        gmean, trials = gmean_headroom(headroom, names) or (math.nan, 0)
        rows.append(
            {
                "ship": ship,
                "family": family,
                "scenarios": names,
                "trials": trials,
                "headroom_gmean": gmean,
            }
        )
    return rows


def headroom_grid(
    headroom: Sequence[Mapping[str, Any]],
) -> tuple[list[str], list[str], dict[tuple[str, str], Mapping[str, Any]]]:
    """The layout of :func:`headroom_table`'s rows as a table: the ships in row order, the
    families present in the order of :data:`shipgym.scenarios.families.FAMILIES` and the
    row of each (ship, family)."""
    present = {r["family"] for r in headroom}
    families = [f for f in FAMILIES if f in present]
    ships = list(dict.fromkeys(r["ship"] for r in headroom))
    return ships, families, {(r["ship"], r["family"]): r for r in headroom}
