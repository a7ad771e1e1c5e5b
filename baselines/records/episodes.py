"""One episode's result: the metrics and trajectory of a (controller, scenario, seed)
episode, as the evaluation loop gives it and a run's ``episodes.jsonl`` keeps it
(:mod:`shipgym_baselines.records.runs`)."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np


@dataclasses.dataclass
class EpisodeResult:
    """Metrics and trajectory of one (controller, scenario, seed) episode; ``training_seed``:
    the seed a learned policy was trained with (None for the rest)."""

    controller: str
    kind: str
    scenario: str
    seed: int
    metrics: dict[str, Any]
    trajectory: dict[str, np.ndarray]
    training_seed: int | None = None

    def row(self) -> dict[str, Any]:
        return {
            "scenario": self.scenario,
            "controller": self.controller,
            "kind": self.kind,
            "seed": self.seed,
            **self.metrics,
        }


__all__ = ["EpisodeResult"]
