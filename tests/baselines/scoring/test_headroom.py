"""What adaptation is worth: the frozen optimum, the gap closed and the headroom table."""

from __future__ import annotations

import json

import numpy as np
import pytest

from shipgym_baselines.scoring.change_share import TWIN_FIELDS
from shipgym_baselines.scoring.headroom import (
    GAIN,
    GAP_FIELDS,
    gap_matrices,
    headroom_table,
    scenario_ships,
    trial_headroom,
)
from shipgym_baselines.scoring.ranking import (
    AGGREGATE_FIELDS,
    aggregate_ranking,
    scenario_scores,
)
from shipgym_baselines.scoring.scores import controller_kinds, scored_episodes
from shipgym_baselines.scoring.splits import suite_families

#: one scenario, five trials: (C_oracle, C_frozen, C of "x"), by hand
#:   trial 0: headroom 400/100 = 4,   gain 400/200 = 2,       gap log 2 / log 4 = 0.5, beats
#:   trial 1: headroom 2,             gain 200/100 = 2,       gap log 2 / log 2 = 1,   beats
#:   trial 2: headroom 1.1 (< 1.2: no gap), gain 110/121 = 10/11,                      loses
#:   trial 3: headroom 1.5,           gain 150/150 = 1,       gap log 1 / log 1.5 = 0, tie: ½
#:   trial 4: headroom 10,            gain 1000/10000 = 0.1,  gap log 0.1 / log 10 = −1, loses
#: gain: geometric mean (2 · 2 · 10/11 · 1 · 0.1)^(1/5) = (4/11)^(1/5)
#: P(C < C_frozen): (1 + 1 + 0 + ½ + 0) / 5 = 0.5
#: gap closed: 4 trials qualify, sorted −1, 0, 0.5, 1; the IQM drops int(0.25·4) = 1 at each
#: end: (0 + 0.5) / 2 = 0.25
HAND = [(100.0, 400.0, 200.0), (100.0, 200.0, 100.0), (100.0, 110.0, 121.0)]
HAND += [(100.0, 150.0, 150.0), (100.0, 1000.0, 10000.0)]


def _hand_episodes(
    trials: list[tuple[float, float, float]] = HAND, frozen: bool = True, learned: bool = False
) -> list[dict]:
    eps = []
    for k, (c_oracle, c_frozen, c_x) in enumerate(trials):
        costs = [("oracle", "reference", c_oracle, None), ("x", "classical", c_x, None)]
        costs += [("oracle_frozen", "reference", c_frozen, None)] if frozen else []
        # a learned agent: three training seeds, each costing x's on the trial
        costs += [("agent", "learned", c_x, t) for t in (0, 1, 2)] if learned else []
        for controller, kind, cost, training_seed in costs:
            eps.append(
                {
                    "scenario": "a",
                    "controller": controller,
                    "kind": kind,
                    "seed": 10_000 + k,
                    "training_seed": training_seed,
                    "cost": cost,
                    "termination_reason": "goal",
                }
            )
    return eps


def test_the_gap_fields_against_a_hand_computed_case() -> None:
    rows = aggregate_ranking(_hand_episodes(learned=True), {"a": "catalogue"}, reps=300)
    assert all(tuple(r) == AGGREGATE_FIELDS for r in rows)
    assert [r["controller"] for r in rows] == ["agent", "x"]  # oracle_frozen is not ranked
    by = {r["controller"]: r for r in rows}
    for name in ("x", "agent"):
        row = by[name]
        assert row[GAIN] == pytest.approx((4 / 11) ** 0.2, rel=1e-12)
        assert row["prob_beats_frozen"] == 0.5
        assert row["gap_closed_iqm"] == pytest.approx(0.25, abs=1e-12)
        assert row["gap_trials"] == 4  # trials (scenario, seed), not runs
        low, high = row["gap_closed_iqm_ci95"]
        assert -1.0 - 1e-12 <= low <= 0.25 <= high <= 1.0 + 1e-12
        low, high = row[f"{GAIN}_ci95"]
        assert 0.1 <= low < (4 / 11) ** 0.2 < high <= 2.0
        low, high = row["prob_beats_frozen_ci95"]
        assert 0.0 <= low < 0.5 < high <= 1.0
    assert by["x"]["runs"] == 5 and by["agent"]["runs"] == 15


def test_the_gap_matrices_per_trial() -> None:
    scored = scored_episodes(_hand_episodes())
    assert trial_headroom(scored) == pytest.approx(
        {("a", 10_000 + k): h for k, h in enumerate([4.0, 2.0, 1.1, 1.5, 10.0])}
    )
    m = gap_matrices(scored, "x", ["a"])
    assert m is not None
    np.testing.assert_allclose(m["gain"][:, 0], [2.0, 2.0, 10 / 11, 1.0, 0.1])
    np.testing.assert_array_equal(m["beats"][:, 0], [1.0, 1.0, 0.0, 0.5, 0.0])
    np.testing.assert_allclose(m["gap"][:, 0], [0.5, 1.0, np.nan, 0.0, -1.0], atol=1e-12)
    # the frozen optimum's own costs: gain 1 everywhere, a tie on every trial
    frozen = gap_matrices(scored, "oracle_frozen", ["a"])
    assert frozen is not None and set(frozen["beats"].ravel()) == {0.5}


def test_the_gap_interval_is_rliables_bootstrap_with_nan_where_a_trial_does_not_qualify() -> None:
    """The gap closed's interval: rliable's stratified bootstrap of the run matrix (NaN on
    the trials with headroom < 1.2) with the IQM over the finite entries, the global
    generator seeded with 0, as the other fields."""
    from rliable import library as rly
    from rliable import metrics as rmetrics

    rng = np.random.default_rng(11)
    trials = [(100.0, 100.0 * h, 100.0 * h * g) for h, g in rng.lognormal(0.3, 0.6, (12, 2))]
    eps = _hand_episodes(trials)
    (row,) = aggregate_ranking(eps, {"a": "catalogue"}, reps=300)
    m = gap_matrices(scored_episodes(eps), "x", ["a"])
    assert m is not None and 0 < np.isfinite(m["gap"]).sum() < 12  # some do not qualify

    def finite_iqm(x: np.ndarray) -> np.ndarray:
        return np.array([rmetrics.aggregate_iqm(x[np.isfinite(x)])])

    np.random.seed(0)  # noqa: NPY002 (what rliable draws from)
    point, interval = rly.get_interval_estimates({"x": m["gap"]}, finite_iqm, reps=300)
    assert row["gap_closed_iqm"] == pytest.approx(point["x"][0], rel=1e-12)
    assert row["gap_closed_iqm_ci95"] == pytest.approx(list(interval["x"][:, 0]), rel=1e-12)
    assert row["gap_trials"] == int(np.isfinite(m["gap"]).sum())


def test_the_gap_fields_are_none_without_the_frozen_optimum_or_a_trial_worth_it() -> None:
    assert GAIN == "cost_vs_frozen_gmean"  # the JSON name of C_frozen / C's geometric mean
    assert set(GAP_FIELDS) <= set(AGGREGATE_FIELDS)
    (row,) = aggregate_ranking(_hand_episodes(frozen=False), {"a": "catalogue"}, reps=100)
    assert {row[k] for k in GAP_FIELDS} == {None}
    assert {row[k] for k in TWIN_FIELDS} == {None}  # no twins either
    assert row["cost_ratio_iqm"] is not None  # the ranking is the same without it
    # every headroom below 1.2: the gain and P(beats) are there, no gap closed
    flat = [(100.0, 110.0, c) for c in (90.0, 110.0, 120.0)]
    (row,) = aggregate_ranking(_hand_episodes(flat), {"a": "catalogue"}, reps=100)
    assert row["prob_beats_frozen"] == pytest.approx(0.5)  # beats, ties, loses: (1 + ½ + 0) / 3
    assert row[GAIN] == pytest.approx((110 / 90 * 1.0 * 110 / 120) ** (1 / 3))
    assert row["gap_closed_iqm"] is None and row["gap_closed_iqm_ci95"] is None
    assert row["gap_trials"] == 0


def test_the_gap_fields_are_reproducible_in_any_order_of_episodes() -> None:
    rng = np.random.default_rng(13)
    trials = [(100.0, 100.0 * h, 100.0 * h * g) for h, g in rng.lognormal(0.3, 0.6, (8, 2))]
    eps = _hand_episodes(trials, learned=True)
    first = json.dumps(aggregate_ranking(eps, {"a": "catalogue"}, reps=200))
    assert json.dumps(aggregate_ranking(eps, {"a": "catalogue"}, reps=200)) == first
    shuffled = [eps[i] for i in rng.permutation(len(eps))]
    assert json.dumps(aggregate_ranking(shuffled, {"a": "catalogue"}, reps=200)) == first
    assert '"gap_closed_iqm": null' not in first


def test_scenario_scores_give_the_frozen_optimums_cost_and_the_headroom() -> None:
    eps = _hand_episodes()
    (entry,) = scenario_scores(eps, {"a": "catalogue"})
    # mean of 400, 200, 110, 150, 1000; headroom (4 · 2 · 1.1 · 1.5 · 10)^(1/5) = 132^(1/5)
    assert entry["oracle_frozen_cost"] == pytest.approx(372.0)
    low, high = entry["oracle_frozen_cost_ci95"]
    assert 110.0 <= low < 372.0 < high <= 1000.0
    assert entry["headroom"] == pytest.approx(132**0.2)
    low, high = entry["headroom_ci95"]
    assert 1.1 <= low < 132**0.2 < high <= 10.0
    cells = {c["controller"]: c for c in entry["controllers"]}
    assert cells["oracle_frozen"]["kind"] == "reference"  # a reference cell, like zero_rudder
    assert cells["oracle_frozen"]["cost_ratio_gmean"] == pytest.approx(entry["headroom"])
    (bare,) = scenario_scores(_hand_episodes(frozen=False), {"a": "catalogue"})
    assert [bare[k] for k in ("oracle_frozen_cost", "oracle_frozen_cost_ci95")] == [None, None]
    assert [bare[k] for k in ("headroom", "headroom_ci95")] == [None, None]


def test_the_frozen_optimum_is_a_reference_whatever_its_kind_says() -> None:
    eps = _hand_episodes()
    for ep in eps:
        ep["kind"] = "classical"
    assert controller_kinds(eps)["oracle_frozen"] == "reference"
    assert controller_kinds(eps, {"oracle_frozen": "learned"})["oracle_frozen"] == "reference"
    assert "oracle_frozen" not in {r["controller"] for r in aggregate_ranking(eps, {"a": "c"})}


def test_the_headroom_table_per_ship_and_change_family() -> None:
    def trial(scenario: str, seed: int, oracle: float, frozen: float) -> list[dict]:
        return [
            {"scenario": scenario, "controller": c, "seed": seed, "cost": cost}
            for c, cost in (("oracle", oracle), ("oracle_frozen", frozen))
        ]

    eps = trial("rudder_aging", 1, 10.0, 20.0) + trial("rudder_aging_long", 1, 10.0, 80.0)
    eps += trial("rudder_aging_long", 2, 10.0, 10.0)  # headroom 1
    eps += trial("mariner_current_shift_curved", 1, 5.0, 15.0)
    eps += trial("mariner_nominal", 1, 5.0, 5.0) + trial("mariner_track", 1, 5.0, 6.0)
    eps += trial("heldout:0", 1, 1.0, 100.0)  # held out: not the catalogue's
    settings = {
        name: {"ship": {"model": ship}}
        for name, ship in (
            ("mariner_nominal", "mariner"),
            ("rudder_aging", "nomoto2"),
            ("rudder_aging_long", "nomoto2"),
            ("mariner_current_shift_curved", "mariner"),
            ("mariner_track", "mariner"),
            ("heldout:0", "blanke"),
        )
    }
    ships = scenario_ships(settings)
    families = suite_families({"scenarios": settings})  # the catalogue files' family: keys
    splits = {s: "heldout" if s.startswith("heldout") else "catalogue" for s in ships}
    rows = headroom_table(eps, ships, families, splits)
    table = {(r["ship"], r["family"]): (r["headroom_gmean"], r["trials"]) for r in rows}
    assert [(r["ship"], r["family"]) for r in rows] == [  # ships as run.json lists them
        ("mariner", "nominal"),
        ("mariner", "current_shift"),
        ("mariner", "other"),
        ("nomoto2", "rudder_aging"),
    ]
    # nomoto2 rudder aging: headrooms 2, 8 and 1 over three trials: (2 · 8 · 1)^(1/3)
    assert table[("nomoto2", "rudder_aging")] == (pytest.approx(16 ** (1 / 3)), 3)
    assert table[("mariner", "current_shift")] == (pytest.approx(3.0), 1)
    assert table[("mariner", "nominal")] == (pytest.approx(1.0), 1)
    assert table[("mariner", "other")] == (pytest.approx(1.2), 1)
    assert rows[3]["scenarios"] == ["rudder_aging", "rudder_aging_long"]
    without = {k: v for k, v in ships.items() if k != "mariner_track"}
    with pytest.raises(ValueError, match=r"no ship .*mariner_track"):
        headroom_table(eps, without, families, splits)
    without = {k: v for k, v in families.items() if k != "mariner_track"}
    with pytest.raises(ValueError, match=r"no change family .*mariner_track"):
        headroom_table(eps, ships, without, splits)
    with pytest.raises(ValueError, match=r"'x'.*ship\.model"):
        scenario_ships({"x": {"name": "x"}})
    oracle_only = [e for e in eps if e["controller"] == "oracle"]
    assert headroom_table(oracle_only, ships, families, splits) == []


def test_the_headroom_table_reads_the_family_never_the_name() -> None:
    """A scenario named as one family and filed under another is in the other's cell."""
    eps = [
        {"scenario": "rudder_aging", "controller": c, "seed": 1, "cost": cost}
        for c, cost in (("oracle", 1.0), ("oracle_frozen", 2.0))
    ]
    ships = {"rudder_aging": "nomoto2"}
    splits = {"rudder_aging": "catalogue"}
    rows = headroom_table(eps, ships, {"rudder_aging": "current_shift"}, splits)
    assert [(r["family"], r["scenarios"]) for r in rows] == [("current_shift", ["rudder_aging"])]
