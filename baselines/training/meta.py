"""``meta.json``: what a training run records about itself, the same fields for every agent."""

from __future__ import annotations

from typing import Any

from shipgym_baselines.training.agents import AgentConfig


def training_meta(
    config: AgentConfig,
    *,
    algo: str,
    env_steps: int,
    wall_time_s: float,
    stopped_at: int | None,
    tuned_from: dict[str, Any] | None,
    **extra: Any,
) -> dict[str, Any]:
    """The run's record: its config, the zip's algorithm ``algo``, the env steps and wall
    time [s] it took, where the plateau rule stopped it, the settings it started from, the
    library versions; ``extra`` fields (a trainer's own) come before the versions."""
    import stable_baselines3
    import torch

    import shipgym

    return {
        "name": config.name,
        "algo": algo,
        "action_mode": config.env.action_mode,
        # the observation's history window: evaluation builds the same (policy.PolicyMeta)
        "history_steps": config.env.history_steps,
        "env_steps": int(env_steps),
        "wall_time_s": wall_time_s,
        "seed": config.seed,
        "training": config.env.distribution or config.env.scenario,
        "config": config.model_dump(),
        "selection": config.eval.select_on,
        "plateau": None if config.plateau is None else config.plateau.model_dump(),
        "stopped_on_plateau_at": stopped_at,
        "tuned_from": tuned_from,
        **extra,
        "versions": {
            "shipgym": shipgym.__version__,
            "stable_baselines3": stable_baselines3.__version__,
            "torch": torch.__version__,
        },
    }
