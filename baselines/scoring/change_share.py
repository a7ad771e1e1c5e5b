"""Steering and adapting, apart: each changing trial against its no-change twin.

For a trial with a change and its twin (the same trial without the change,
:mod:`shipgym.scenarios.twins`), write C_X and C_X(twin) for controller X's costs there,
and D_X = C_X / C_X(twin): the factor by which the change raised X's cost.  Then, exactly,

    C_X / C_oracle = [C_X(twin) / C_oracle(twin)] · D_X / D_oracle,

the cost ratio is the **nominal ratio** (how well X steers the unchanged ship) times how
much more the change cost X than the oracle.  Per competitor and split:

* ``nominal_cost_ratio_gmean``: the geometric mean over the split's changing trials of
  C_X(twin) / C_oracle(twin);
* ``change_share_iqm``: over the trials where knowing the change is worth at least
  :data:`~shipgym_baselines.scoring.headroom.GAP_HEADROOM` (C_frozen / C_oracle ≥ 1.2),
  the interquartile mean of the **change share**

      share = (log D_frozen − log D_X) / (log D_frozen − log D_oracle),

  0 when the change costs X as much as it costs the optimum that never adapts
  (``oracle_frozen``), 1 when it costs X as little as it costs the oracle.  On a twin
  nothing changes, so the optimum that never adapts is the oracle there: C_frozen(twin) is
  taken as C_oracle(twin), and the denominator is log(C_frozen / C_oracle) > 0.  The share
  is the gap closed plus log(nominal ratio) / log(C_frozen / C_oracle): a controller that
  steers the unchanged ship worse than the oracle is no longer charged for it.

Each comes with a stratified-bootstrap 95 % interval (rliable's scheme: each resample
redraws every scenario's runs; :func:`~.intervals.stratified_nan_ci`, which leaves out the
cells that do not count).  A trial whose costs are not all
finite and positive leaves its cell out (NaN).  Without the twins' episodes, or the
frozen optimum's for the share, the fields are None.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from shipgym_baselines.privileged import ORACLE, ORACLE_FROZEN
from shipgym_baselines.scoring.headroom import GAP_HEADROOM
from shipgym_baselines.scoring.intervals import (
    AGGREGATE_REPS,
    finite_gmean,
    finite_iqm,
    finite_or_none,
    float_or_nan,
    gmean_rows,
    iqm_rows,
    nan_gmean_rows,
    nan_iqm_rows,
    pooled_bootstrap_ci,
    stratified_nan_ci,
)
from shipgym_baselines.scoring.scores import is_failure, run_keys

NOMINAL = "nominal_cost_ratio_gmean"
SHARE = "change_share_iqm"
#: the fields of an ``aggregate.json`` row on the changing trials, in order: the nominal
#: ratio over ``change_trials``, the change share over ``share_trials`` of them
TWIN_FIELDS = (NOMINAL, f"{NOMINAL}_ci95", SHARE, f"{SHARE}_ci95", "change_trials", "share_trials")
#: those fields without the twins' episodes
NO_TWIN_FIELDS: dict[str, Any] = dict.fromkeys(TWIN_FIELDS)
#: a leaderboard row's fields on its scenario's trials (:func:`scenario_twin_cells`), None
NO_SCENARIO_CELLS: dict[str, Any] = dict.fromkeys(
    (NOMINAL, f"{NOMINAL}_ci95", SHARE, f"{SHARE}_ci95")
)

#: what the two numbers mean, in the tables' words
CHANGE_SHARE_EXPLAINED = (
    "Nominal ratio: the geometric mean over the changing trials of C(twin) / C_oracle(twin), "
    "where the twin is the same trial without the change; it says how well the controller "
    "steers the unchanged ship. Change share: with D = C / C(twin) the factor by which the "
    "change raised a controller's cost, (log D_frozen − log D) / (log D_frozen − log "
    "D_oracle), its IQM over the trials where knowing the change is worth "
    f"{GAP_HEADROOM:g}× or more; 0 = the change costs it as much as the optimum that never "
    "adapts, 1 = as little as the oracle. The cost ratio is the nominal ratio × D / D_oracle."
)

#: what the table of change shares per ship × change family shows
SHARE_GRID_EXPLAINED = (
    "Change share IQM of the top five competitors and the best learned agent over the "
    f"trials of each ship and change family worth {GAP_HEADROOM:g}× or more (how many in "
    "'trials'); 'all ships' pools each family's"
)

Costs = dict[tuple[str, str, Any, int], float]


def episode_costs(episodes: Sequence[Mapping[str, Any]]) -> Costs:
    """(scenario, controller, training seed, seed) → the episode's cost; NaN for an
    ``oracle`` episode that failed (never a denominator, :func:`~.scores.refused_trials`)."""
    out = {}
    for ep in episodes:
        cost = float_or_nan(ep.get("cost"))
        if ep["controller"] == ORACLE and is_failure(ep):
            cost = math.nan
        out[(ep["scenario"], ep["controller"], ep.get("training_seed"), int(ep["seed"]))] = cost
    return out


def _positive(*values: float) -> bool:
    return all(math.isfinite(v) and v > 0.0 for v in values)


def trial_cells(
    costs: Costs,
    controller: str,
    scenario: str,
    twin: str,
    run: tuple[Any, int],
) -> tuple[float, float] | None:
    """(nominal ratio, change share) of ``controller``'s run (training seed, seed) of a
    trial of ``scenario`` whose twin is ``twin`` (module doc); NaN for a value whose costs
    are not all finite and positive, or for the share of a trial worth less than
    :data:`GAP_HEADROOM` or without the frozen optimum's cost.  None when an episode it
    needs is missing: the controller's or the oracle's on the twin, the oracle's on the
    trial."""
    training_seed, seed = run
    try:
        c_x = costs[(scenario, controller, training_seed, seed)]
        c_x_twin = costs[(twin, controller, training_seed, seed)]
        c_o = costs[(scenario, ORACLE, None, seed)]
        c_o_twin = costs[(twin, ORACLE, None, seed)]
    except KeyError:
        return None
    c_f = costs.get((scenario, ORACLE_FROZEN, None, seed), math.nan)
    nominal = c_x_twin / c_o_twin if _positive(c_x_twin, c_o_twin) else math.nan
    share = math.nan
    if _positive(c_x, c_x_twin, c_o, c_o_twin, c_f) and c_f / c_o >= GAP_HEADROOM:
        # log D_frozen − log D_oracle = log(C_frozen / C_oracle): C_frozen(twin) = C_oracle(twin)
        d_frozen, d_x = math.log(c_f / c_o_twin), math.log(c_x / c_x_twin)
        share = (d_frozen - d_x) / math.log(c_f / c_o)
    return nominal, share


def twin_matrices(
    scored: Sequence[Mapping[str, Any]],
    controller: str,
    tasks: Sequence[str],
    twins: Mapping[str, str],
    costs: Costs | None = None,
) -> dict[str, np.ndarray] | None:
    """The (runs, tasks) matrices ``nominal`` and ``share`` of ``controller`` over the
    changing ones of ``tasks`` (those in ``twins``: scenario → its twin's table name), runs
    in :func:`~shipgym_baselines.scoring.scores.run_keys` order; None without a
    changing task or without an episode a cell needs (:func:`trial_cells`)."""
    changing = [t for t in tasks if t in twins]
    if not changing:
        return None
    costs = episode_costs(scored) if costs is None else costs
    keys = run_keys(scored, controller, changing)
    runs = len(keys[changing[0]])
    nominal = np.full((runs, len(changing)), math.nan)
    share = np.full((runs, len(changing)), math.nan)
    for j, task in enumerate(changing):
        for i, run in enumerate(keys[task]):
            cells = trial_cells(costs, controller, task, twins[task], run)
            if cells is None:
                return None
            nominal[i, j], share[i, j] = cells
    return {"nominal": nominal, "share": share}


def twin_fields(
    scored: Sequence[Mapping[str, Any]],
    controller: str,
    tasks: Sequence[str],
    twins: Mapping[str, str],
    reps: int = AGGREGATE_REPS,
    seed: int = 0,
    costs: Costs | None = None,
) -> dict[str, Any]:
    """The :data:`TWIN_FIELDS` of ``controller``'s ``aggregate.json`` row over ``tasks``
    (module doc; :data:`NO_TWIN_FIELDS` without a changing task or a twin's episodes)."""
    m = twin_matrices(scored, controller, tasks, twins, costs)
    if m is None:
        return dict(NO_TWIN_FIELDS)
    out = dict(NO_TWIN_FIELDS)
    for field, values, point, rows in (
        (NOMINAL, m["nominal"], finite_gmean, nan_gmean_rows),
        (SHARE, m["share"], finite_iqm, nan_iqm_rows),
    ):
        if np.isfinite(values).any():
            out[field] = finite_or_none(point(values))
            out[f"{field}_ci95"] = stratified_nan_ci(values, rows, reps, seed=seed)
    out["change_trials"] = int(np.isfinite(m["nominal"]).sum())
    out["share_trials"] = int(np.isfinite(m["share"]).sum())
    return out


def scenario_twin_cells(
    scored: Sequence[Mapping[str, Any]],
    controller: str,
    scenario: str,
    twins: Mapping[str, str],
    costs: Costs | None = None,
    seed: int = 0,
) -> dict[str, Any]:
    """The nominal ratio and change share of ``controller`` on one changing ``scenario``
    (the geometric mean and the IQM over its trials), each with the percentile-bootstrap
    95 % interval that resamples the scenario's trials; None where it has none."""
    m = twin_matrices(scored, controller, [scenario], twins, costs)
    out = dict(NO_SCENARIO_CELLS)
    if m is None:
        return out
    for field, values, estimate in (
        (NOMINAL, m["nominal"], gmean_rows),
        (SHARE, m["share"], iqm_rows),
    ):
        finite = values[np.isfinite(values)]
        if finite.size:
            out[field] = float(estimate(finite))
            out[f"{field}_ci95"] = pooled_bootstrap_ci(finite, estimate, seed=seed)
    return out


#: the ship of a share table's row that pools every ship of a family
ALL_SHIPS = "all ships"
#: how many of a split's top competitors the share table shows (with the best learned agent)
TOP = 5


def share_controllers(table: Sequence[Mapping[str, Any]], top: int = TOP) -> list[str]:
    """The controllers of a share table: the ``top`` first of a ranked table (aggregate rows
    of one split), then its best learned agent when it is not among them."""
    names = [r["controller"] for r in table[:top]]
    learned = [r["controller"] for r in table if r.get("kind") == "learned"]
    if learned and learned[0] not in names:
        names.append(learned[0])
    return names


def share_grid(
    scored: Sequence[Mapping[str, Any]],
    controllers: Sequence[str],
    ships: Mapping[str, str],
    families: Mapping[str, str],
    scenarios: Sequence[str],
    twins: Mapping[str, str],
    costs: Costs | None = None,
) -> list[dict[str, Any]]:
    """The change share per ship × change family of ``controllers`` over ``scenarios`` (a
    split's, ranked), then per family over every ship (:data:`ALL_SHIPS`): rows ``ship``,
    ``family``, ``scenarios``, ``trials`` (those worth :data:`GAP_HEADROOM` or more: a
    share's) and ``shares`` (controller → its change share IQM over them, None without
    one).  ``ships`` / ``families``: scenario → its ship / change family; a family without
    a changing scenario has no row."""
    costs = episode_costs(scored) if costs is None else costs
    cells: dict[tuple[str, str], list[str]] = {}
    for s in scenarios:
        if s in twins:
            cells.setdefault((ships[s], families[s]), []).append(s)
            cells.setdefault((ALL_SHIPS, families[s]), []).append(s)
    order = [*dict.fromkeys(ships[s] for s in scenarios), ALL_SHIPS]
    family_order = list(dict.fromkeys(families[s] for s in scenarios))
    rows = []
    for ship, family in sorted(cells, key=lambda k: (order.index(k[0]), family_order.index(k[1]))):
        names = cells[(ship, family)]
        shares: dict[str, float | None] = {}
        for controller in controllers:
            m = twin_matrices(scored, controller, names, twins, costs)
            value = math.nan if m is None else finite_iqm(m["share"])
            shares[controller] = value if math.isfinite(value) else None
        trials = worth_trials(costs, names)
        rows.append(
            {"ship": ship, "family": family, "scenarios": names, "trials": trials, "shares": shares}
        )
    return rows


def worth_trials(costs: Costs, scenarios: Sequence[str]) -> int:
    """How many trials of ``scenarios`` knowing the change is worth :data:`GAP_HEADROOM` or
    more on (C_frozen / C_oracle, both finite and positive)."""
    wanted = set(scenarios)
    count = 0
    for (scenario, controller, _, seed), c_f in costs.items():
        if controller == ORACLE_FROZEN and scenario in wanted:
            c_o = costs.get((scenario, ORACLE, None, seed), math.nan)
            count += _positive(c_f, c_o) and c_f / c_o >= GAP_HEADROOM
    return count
