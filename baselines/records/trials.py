"""Which of a controller's training seeds plays which trial of a scenario.

By default every training seed of a learned agent plays every evaluation seed (trial) of a
scenario: 3 training seeds × 10 trials are 30 episodes, where a classical controller plays
10.  A suite with ``learned_trials: shared`` deals the trials instead: each trial is played
by one training seed, in turn, so every row has one episode per trial, and the spread over
training seeds stays in the numbers (docs/leaderboard.md, "Learned agents share the trials").
``run.json`` records the choice (:data:`LEARNED_TRIALS`), and every reader of a run deals
the same way (:func:`runs_of`).
"""

from __future__ import annotations

import zlib
from collections.abc import Mapping, Sequence
from typing import Any, Literal, TypeVar

#: the key of a suite file and of ``run.json``'s suite record; absent means :data:`ALL`
LEARNED_TRIALS = "learned_trials"
#: every training seed plays every trial
ALL = "all"
#: each trial is played by one training seed (:func:`dealt_seeds`)
SHARED = "shared"
#: the values of :data:`LEARNED_TRIALS`
LearnedTrials = Literal["all", "shared"]

T = TypeVar("T")


def dealt_owners(scenario: str, seeds: Sequence[int], training_seeds: Sequence[T]) -> list[T]:
    """The training seed that plays each of ``seeds`` of ``scenario`` when they are shared:
    the training seeds in turn, starting at an offset fixed by the scenario's name (CRC-32),
    so that over many scenarios each training seed plays about as many trials, and adding a
    scenario to a suite changes no other scenario's deal.  A controller that is not trained
    (``[None]``) plays every seed."""
    if not training_seeds:
        raise ValueError("no training seeds to deal the trials to")
    start = zlib.crc32(scenario.encode()) % len(training_seeds)
    return [training_seeds[(start + i) % len(training_seeds)] for i in range(len(seeds))]


def dealt_seeds(
    scenario: str, seeds: Sequence[int], training_seeds: Sequence[T]
) -> dict[T, list[int]]:
    """Training seed → the evaluation seeds of ``scenario`` it plays when they are shared
    (:func:`dealt_owners`)."""
    dealt: dict[T, list[int]] = {k: [] for k in training_seeds}
    for seed, owner in zip(seeds, dealt_owners(scenario, seeds, training_seeds), strict=True):
        dealt[owner].append(seed)
    return dealt


def shares_trials(suite: Mapping[str, Any]) -> bool:
    """Whether a resolved suite (``run.json``'s) deals its trials to training seeds."""
    return suite.get(LEARNED_TRIALS, ALL) == SHARED


def runs_of(
    scenario: str, seeds: Sequence[int], training_seeds: Sequence[T], shared: bool
) -> set[tuple[T, int]]:
    """The (training seed, evaluation seed) episodes a controller plays on ``scenario``:
    every pair, or with ``shared`` each seed with its :func:`dealt_owners`."""
    if not shared:
        return {(k, s) for k in training_seeds for s in seeds}
    return set(zip(dealt_owners(scenario, seeds, training_seeds), seeds, strict=True))


#: ``run.json``'s suite keys of the no-change twins: changing scenario → its twin's table
#: name, the settings of the twins that are no scenario of the run, and the controllers
#: that play the twins (:mod:`shipgym_baselines.leaderboard.twins`)
TWINS, TWIN_SCENARIOS, TWIN_PLAYERS = "twins", "twin_scenarios", "twin_players"


def twins_of(suite: Mapping[str, Any]) -> dict[str, str]:
    """Changing scenario → its twin's table name, as a resolved suite (``run.json``'s)
    records them; empty for a run without twins."""
    return dict(suite.get(TWINS) or {})


def twin_scenarios(suite: Mapping[str, Any]) -> dict[str, Any]:
    """The recorded settings of the twins that are no scenario of the run, by name."""
    return dict(suite.get(TWIN_SCENARIOS) or {})


def deal_names(suite: Mapping[str, Any]) -> dict[str, str]:
    """Scenario or twin → the name its trials are dealt by (:func:`dealt_owners`): a
    changing scenario's twin's, so that a trial and its twin are played by the same
    training seed; every other scenario's own."""
    names = {s: s for s in suite.get("scenarios", {})}
    names.update({t: t for t in twin_scenarios(suite)})
    names.update(twins_of(suite))
    return names
