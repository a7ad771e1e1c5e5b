"""The deal of a learned agent's trials among its training seeds."""

from __future__ import annotations

import itertools

import pytest

from shipgym_baselines.records.trials import (
    LEARNED_TRIALS,
    SHARED,
    dealt_seeds,
    runs_of,
    shares_trials,
)

SEEDS = list(range(10_000, 10_010))


def test_each_seed_is_dealt_to_exactly_one_training_seed_in_turn() -> None:
    dealt = dealt_seeds("rudder_aging", SEEDS, [0, 1, 2])
    assert sorted(s for mine in dealt.values() for s in mine) == SEEDS
    assert sorted(len(mine) for mine in dealt.values()) == [3, 3, 4]
    # in turn: consecutive seeds go to consecutive training seeds
    owner = {s: k for k, mine in dealt.items() for s in mine}
    assert all(owner[a] != owner[b] for a, b in itertools.pairwise(SEEDS))
    assert dealt == dealt_seeds("rudder_aging", SEEDS, [0, 1, 2])  # the same every time


def test_the_deal_starts_at_an_offset_fixed_by_the_scenario_name() -> None:
    """With two seeds a scenario and three training seeds, every training seed still plays
    some of 16 scenarios' trials (no seed is always left out), and about as many."""
    played = {0: 0, 1: 0, 2: 0}
    for i in range(16):
        for k, mine in dealt_seeds(f"inrange:{i}", SEEDS[:2], [0, 1, 2]).items():
            played[k] += len(mine)
    assert sum(played.values()) == 32
    assert min(played.values()) >= 6, played


def test_a_controller_that_is_not_trained_plays_every_seed() -> None:
    assert dealt_seeds("nominal", SEEDS, [None]) == {None: SEEDS}
    with pytest.raises(ValueError, match="no training seeds"):
        dealt_seeds("nominal", SEEDS, [])


def test_runs_are_every_pair_unless_shared() -> None:
    every = runs_of("nominal", SEEDS[:2], [0, 1], shared=False)
    assert every == {(0, 10_000), (0, 10_001), (1, 10_000), (1, 10_001)}
    shared = runs_of("nominal", SEEDS[:2], [0, 1], shared=True)
    assert len(shared) == 2 and {s for _, s in shared} == {10_000, 10_001}
    assert shared < every
    assert shares_trials({LEARNED_TRIALS: SHARED}) and not shares_trials({})
    assert not shares_trials({LEARNED_TRIALS: "all"})
