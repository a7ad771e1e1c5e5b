"""Steering and adapting, apart: the nominal ratio and the change share against hand-computed
trials, the exact decomposition of the cost ratio, and the per-scenario intervals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym_baselines.scoring.change_share import (
    NO_TWIN_FIELDS,
    NOMINAL,
    SHARE,
    scenario_twin_cells,
    share_controllers,
    share_grid,
    twin_fields,
    twin_matrices,
)
from shipgym_baselines.scoring.headroom import gap_matrices
from shipgym_baselines.scoring.ranking import AGGREGATE_FIELDS, aggregate_ranking
from shipgym_baselines.scoring.scores import scored_episodes

#: one changing scenario "a" with twin "t", four trials, by hand: per trial
#: (C_oracle, C_frozen, C_x, C_oracle(twin), C_x(twin))
#:   trial 0: headroom 4; D_frozen = 400/100 = 4, D_oracle = 1, D_x = 200/100 = 2:
#:            share (log 4 − log 2) / log 4 = 0.5; nominal 100/100 = 1
#:   trial 1: headroom 2; D_frozen = 200/50 = 4, D_oracle = 100/50 = 2, D_x = 800/200 = 4:
#:            share (log 4 − log 4) / log 2 = 0 (the change cost x as much as never adapting)
#:            nominal 200/50 = 4
#:   trial 2: headroom 1.1 < 1.2: no share; nominal 300/100 = 3
#:   trial 3: headroom 3; D_frozen = 300/100 = 3, D_oracle = 1, D_x = 150/150 = 1:
#:            share (log 3 − 0) / log 3 = 1 (as little as the oracle); nominal 150/100 = 1.5
#: nominal gmean (1 · 4 · 3 · 1.5)^(1/4) = 18^(1/4); share IQM of 0, 0.5, 1: int(0.75) = 0
#: dropped at each end, mean 0.5
HAND = [
    (100.0, 400.0, 200.0, 100.0, 100.0),
    (100.0, 200.0, 800.0, 50.0, 200.0),
    (100.0, 110.0, 120.0, 100.0, 300.0),
    (100.0, 300.0, 150.0, 100.0, 150.0),
]
SHARES = [0.5, 0.0, math.nan, 1.0]
NOMINALS = [1.0, 4.0, 3.0, 1.5]


def _episode(scenario: str, controller: str, kind: str, seed: int, cost: float, k=None) -> dict:
    return {
        "scenario": scenario,
        "controller": controller,
        "kind": kind,
        "seed": seed,
        "training_seed": k,
        "cost": cost,
        "termination_reason": "goal",
    }


def _hand_episodes(twin_of_x: bool = True) -> list[dict]:
    eps = []
    for i, (c_o, c_f, c_x, c_ot, c_xt) in enumerate(HAND):
        seed = 10_000 + i
        eps += [
            _episode("a", "oracle", "reference", seed, c_o),
            _episode("a", "oracle_frozen", "reference", seed, c_f),
            _episode("a", "x", "classical", seed, c_x),
            _episode("t", "oracle", "reference", seed, c_ot),
        ]
        if twin_of_x:
            eps.append(_episode("t", "x", "classical", seed, c_xt))
    return eps


def test_the_cells_of_hand_computed_trials() -> None:
    m = twin_matrices(scored_episodes(_hand_episodes()), "x", ["a"], {"a": "t"})
    assert m is not None
    np.testing.assert_allclose(m["nominal"][:, 0], NOMINALS, rtol=1e-12)
    np.testing.assert_allclose(m["share"][:, 0], SHARES, rtol=1e-12, atol=1e-12)


def test_the_cost_ratio_decomposes_exactly_trial_by_trial() -> None:
    """C_x / C_oracle = nominal ratio × D_x / D_oracle on every trial."""
    for c_o, _, c_x, c_ot, c_xt in HAND:
        nominal = c_xt / c_ot
        assert c_x / c_o == pytest.approx(nominal * (c_x / c_xt) / (c_o / c_ot), rel=1e-12)


def test_the_share_is_the_gap_closed_plus_the_nominal_ratio_over_the_headroom() -> None:
    """share = gap closed + log(nominal ratio) / log(C_frozen / C_oracle), on each trial
    worth 1.2× or more: a controller is no longer charged for how it steers the unchanged
    ship."""
    scored = scored_episodes(_hand_episodes())
    m = twin_matrices(scored, "x", ["a"], {"a": "t"})
    gap = gap_matrices(scored, "x", ["a"])
    assert m is not None and gap is not None
    for i, (c_o, c_f, *_rest) in enumerate(HAND):
        if c_f / c_o < 1.2:
            assert math.isnan(m["share"][i, 0]) and math.isnan(gap["gap"][i, 0])
            continue
        expected = gap["gap"][i, 0] + math.log(m["nominal"][i, 0]) / math.log(c_f / c_o)
        assert m["share"][i, 0] == pytest.approx(expected, rel=1e-12, abs=1e-12)


def test_the_aggregate_fields_and_their_intervals() -> None:
    fields = twin_fields(scored_episodes(_hand_episodes()), "x", ["a"], {"a": "t"})
    assert fields[NOMINAL] == pytest.approx(18.0**0.25, rel=1e-12)
    assert fields[SHARE] == pytest.approx(0.5, rel=1e-12)
    assert fields["change_trials"] == 4 and fields["share_trials"] == 3
    for key in (NOMINAL, SHARE):
        low, high = fields[f"{key}_ci95"]
        assert low <= fields[key] <= high and low < high  # the trials differ
    assert set(fields) <= set(AGGREGATE_FIELDS)


def test_the_references_own_shares() -> None:
    """The oracle's change share is 1 and its nominal ratio 1 by construction."""
    eps = _hand_episodes()
    fields = twin_fields(scored_episodes(eps), "oracle", ["a"], {"a": "t"})
    assert fields[NOMINAL] == pytest.approx(1.0) and fields[SHARE] == pytest.approx(1.0)


def test_without_a_twin_episode_or_a_changing_scenario_the_fields_are_none() -> None:
    scored = scored_episodes(_hand_episodes(twin_of_x=False))
    assert twin_fields(scored, "x", ["a"], {"a": "t"}) == NO_TWIN_FIELDS
    assert twin_fields(scored_episodes(_hand_episodes()), "x", ["a"], {}) == NO_TWIN_FIELDS


def test_the_ranking_carries_both_numbers_on_the_changing_scenarios_only() -> None:
    """A split with a changing and an unchanged scenario: the twin fields come from the
    changing one's trials; twins are no split's scenarios and never ranked."""
    eps = _hand_episodes()
    for i in range(len(HAND)):  # "n" never changes: the same costs as the twin
        eps += [
            _episode("n", "oracle", "reference", 10_000 + i, 100.0),
            _episode("n", "oracle_frozen", "reference", 10_000 + i, 100.0),
            _episode("n", "x", "classical", 10_000 + i, 150.0),
        ]
    (row,) = aggregate_ranking(eps, {"a": "catalogue", "n": "catalogue"}, twins={"a": "t"})
    assert row["scenarios"] == ["a", "n"]
    assert row[NOMINAL] == pytest.approx(18.0**0.25) and row[SHARE] == pytest.approx(0.5)
    assert list(row) == list(AGGREGATE_FIELDS)


def test_a_scenarios_cells_resample_its_trials() -> None:
    """Per scenario: the geometric mean and IQM over its trials, with an interval of
    non-zero width wherever its trials differ."""
    cells = scenario_twin_cells(scored_episodes(_hand_episodes()), "x", "a", {"a": "t"})
    assert cells[NOMINAL] == pytest.approx(18.0**0.25) and cells[SHARE] == pytest.approx(0.5)
    for key in (NOMINAL, SHARE):
        low, high = cells[f"{key}_ci95"]
        assert low < cells[key] < high


def test_learned_trials_pair_each_trial_with_its_twin_of_the_same_training_seed() -> None:
    """Dealt trials: seed s of "a" and of its twin played by one training seed; the twin's
    cost of another training seed is never read."""
    eps = _hand_episodes()
    for i, (_, _, c_x, _, c_xt) in enumerate(HAND):
        k = i % 2
        eps.append(_episode("a", "agent", "learned", 10_000 + i, c_x, k))
        eps.append(_episode("t", "agent", "learned", 10_000 + i, c_xt, k))
        eps.append(_episode("t", "agent", "learned", 10_000 + i, 1e6, 1 - k))  # never read
    m = twin_matrices(scored_episodes(eps), "agent", ["a"], {"a": "t"})
    assert m is not None
    order = sorted(range(len(HAND)), key=lambda i: (i % 2, i))  # runs by (training seed, seed)
    np.testing.assert_allclose(m["nominal"][:, 0], [NOMINALS[i] for i in order])


def test_the_share_table_per_ship_and_family() -> None:
    scored = scored_episodes(_hand_episodes())
    grid = share_grid(scored, ["x", "oracle"], {"a": "s"}, {"a": "f"}, ["a"], {"a": "t"})
    assert [(r["ship"], r["family"]) for r in grid] == [("s", "f"), ("all ships", "f")]
    assert grid[0]["shares"] == {"x": pytest.approx(0.5), "oracle": pytest.approx(1.0)}
    assert grid[0]["trials"] == 3  # headroom 4, 2 and 3: three of the four trials


def test_the_share_table_shows_the_top_five_and_the_best_learned_agent() -> None:
    table = [{"controller": f"c{i}", "kind": "classical"} for i in range(7)]
    table.append({"controller": "agent", "kind": "learned"})
    assert share_controllers(table) == ["c0", "c1", "c2", "c3", "c4", "agent"]
    table.insert(1, {"controller": "first", "kind": "learned"})
    assert share_controllers(table) == ["c0", "first", "c1", "c2", "c3"]
