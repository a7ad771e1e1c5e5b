"""The trials a study scores on: the validation split only, and the oracle's cost on each.

A validation trial is a named scenario of a validation distribution (``validation:k``, the
training ranges in the test seed space: ``configs/distributions/validation.yaml``) with one
evaluation seed, :data:`~shipgym_baselines.evaluation.EVAL_SEED_OFFSET` + k.  Every
scenario a study runs comes from :func:`validation_trials`, which refuses any distribution
that is not the training ranges in the test seed space and every ``test_only`` one (so never
the held-out or in-range split, never a catalogue scenario).

The denominator of the cost ratio is the ``oracle``'s cost on the same trial
(:mod:`shipgym_baselines.references`): read from the shipped table (which holds every trial
of the ``validation`` split: ``shipgym references --packaged --validation``), else from the per-user
cache of computed references (:func:`~shipgym_baselines.references.user_cache_path`), else
run once with the privileged oracle (the built-in channel,
:mod:`shipgym_baselines.privileged`; the tuned controller never sees the truth) and stored
in that cache, which every later study reads.  Its header carries the env and oracle
revisions and settings (a cache of another revision is ignored as a whole).
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Callable, Sequence
from pathlib import Path

from shipgym.scenarios.loader import Scenario, load_scenario
from shipgym.scenarios.sampling import load_distribution
from shipgym_baselines.errors import RunError
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET

#: the oracle cache's file name in its folder
ORACLE_CACHE = "oracle.json.gz"


@dataclasses.dataclass(frozen=True)
class ValidationTrial:
    """One validation trial: its name (``validation:k``), ship, scenario and env seed."""

    name: str
    ship: str
    scenario: Scenario
    seed: int


#: test splits only the leaderboard reads, whatever their files say (``test_only``)
TEST_ONLY = ("heldout", "inrange")


def check_validation_split(distribution: str) -> None:
    """Raise unless ``distribution`` is a validation split: a test split drawn from a train
    split's ranges (``ranges_of``), never a ``test_only`` one (the held-out and in-range
    splits)."""
    dist = load_distribution(distribution)
    if dist.config.test_only or dist.name in TEST_ONLY:
        raise RunError(
            f"validation distribution {distribution!r}: a test split only the leaderboard "
            "reads (test_only); tuning and model selection score on a validation split "
            "('validation')"
        )
    if dist.split != "test" or dist.config.ranges_of is None:
        raise RunError(
            f"validation distribution {distribution!r}: tuning scores on a validation split "
            "only (a test split with 'ranges_of' a train split), never the held-out, in-range "
            "or catalogue scenarios"
        )


def validation_trials(
    distribution: str = "validation",
    ship: str | None = None,
    per_ship: int | None = None,
    ships: Sequence[str] | None = None,
) -> list[ValidationTrial]:
    """The trials of ``distribution`` in its interleaved order: only ``ship``'s (None:
    every ship's, or those in ``ships``), at most ``per_ship`` of each ship."""
    check_validation_split(distribution)
    dist = load_distribution(distribution)
    models = [s.model for s in dist.config.ships]
    if ship is not None and ship not in models:
        raise RunError(f"--ship {ship!r}: not in {distribution!r}; valid: {', '.join(models)}")
    trials, taken = [], dict.fromkeys(models, 0)
    for index, (k, _) in enumerate(dist.test_layout):
        model = models[k]
        if (ship is not None and model != ship) or (ships is not None and model not in ships):
            continue
        if per_ship is not None and taken[model] >= per_ship:
            continue
        taken[model] += 1
        name = f"{dist.name}:{index}"
        scenario = load_scenario(dist.test_scenario(index))
        trials.append(ValidationTrial(name, model, scenario, EVAL_SEED_OFFSET + index))
    if not trials:
        raise RunError(f"no validation trials in {distribution!r} for ship {ship!r}")
    return trials


def oracle_costs(
    trials: Sequence[ValidationTrial],
    cache_dir: str | os.PathLike | None = None,
    progress: Callable[[str], object] | None = None,
) -> list[float]:
    """The oracle's cost on each trial (module doc: shipped table, else the cache, else run
    now and cached).  ``cache_dir``: the folder of the cache's :data:`ORACLE_CACHE` (default:
    the per-user cache's)."""
    from shipgym_baselines.evaluation import evaluate
    from shipgym_baselines.privileged import ORACLE
    from shipgym_baselines.references import ReferenceCache, announce, lookup

    cache = ReferenceCache(None if cache_dir is None else Path(cache_dir) / ORACLE_CACHE)
    entries = [lookup(trial.scenario, trial.seed, cache) for trial in trials]
    pending = [trial for trial, entry in zip(trials, entries, strict=True) if entry is None]
    announce([trial.scenario for trial in pending], f"once: cached in {cache.path}")
    costs = []
    for trial, entry in zip(trials, entries, strict=True):
        if entry is None:
            if progress is not None:
                progress(f"oracle reference for {trial.name} (seed {trial.seed}): computing")
            (result,) = evaluate(ORACLE, trial.scenario, [trial.seed])
            entry = cache.store(trial.scenario, result)
        costs.append(_cost(entry["metrics"].get("cost")))
    return costs


def _cost(value: object) -> float:
    cost = float(value)  # type: ignore[arg-type]
    if not math.isfinite(cost) or cost <= 0:
        raise RunError(f"the oracle's reference cost {value!r} is not a positive number")
    return cost
