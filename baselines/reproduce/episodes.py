"""The episodes of one controller on one scenario over the evaluation seeds."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from shipgym_baselines.evaluation import EVAL_SEED_OFFSET, run_episode
from shipgym_baselines.records.episodes import EpisodeResult
from shipgym_baselines.reproduce.protocol import Progress


def seeded_episodes(
    make_policy: Callable[[], Any],
    scenario: Any,
    seeds: int,
    progress: Progress | None = None,
    **run_options: Any,
) -> list[tuple[EpisodeResult, Any]]:
    """(result, policy) of a fresh ``make_policy()`` on seeds ``EVAL_SEED_OFFSET + i``,
    i < ``seeds`` (:func:`shipgym_baselines.evaluation.run_episode` with ``run_options``), calling
    ``progress`` after each."""
    out = []
    for i in range(seeds):
        policy = make_policy()
        out.append((run_episode(policy, scenario, EVAL_SEED_OFFSET + i, **run_options), policy))
        if progress is not None:
            progress()
    return out
