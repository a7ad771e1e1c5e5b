"""What ``shipgym train`` says before and after a run: one start-up line (what it trains,
how long, when it validates, an estimate) and, after a run too short to validate, why it has
no ``best_model.zip`` and no learning curve."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from shipgym_baselines.training.agents import AgentConfig


def recorded_step_seconds(name: str) -> float | None:
    """Wall seconds per env step of the shipped ``name``'s training (the median over its
    seeds' ``meta.json``); None when nothing of that name is shipped."""
    from shipgym_baselines.learned.policy import POLICY_DIR

    rates = []
    for meta in sorted((Path(POLICY_DIR) / name).glob("seed_*/meta.json")):
        record = json.loads(meta.read_text())
        steps, wall = record.get("env_steps"), record.get("wall_time_s")
        if isinstance(steps, int) and steps > 0 and isinstance(wall, int | float) and wall > 0:
            rates.append(wall / steps)
    return sorted(rates)[len(rates) // 2] if rates else None


def _duration(seconds: float) -> str:
    return f"about {seconds / 60:.0f} min" if seconds >= 90 else f"about {seconds:.0f} s"


def start_line(config: AgentConfig, steps: int, seed: int | None, out: str) -> str:
    """The start-up line of one training run of ``steps`` env steps into ``out``."""
    rate = recorded_step_seconds(config.name)
    estimate = (
        f"{_duration(rate * steps)} (the shipped {config.name}'s training rate, "
        f"{1e3 * rate:.2f} ms an env step; one-off C compilations come on top)"
        if rate is not None
        else "no shipped training of this name to estimate from"
    )
    every = config.eval.freq
    validation = (
        "validation after each DAgger round"
        if config.algo == "dagger"
        else (
            f"validation every {every:,} env steps on {config.eval.n_episodes} episodes"
            if steps >= every
            else f"likely no validation: it runs every {every:,} env steps (eval.freq)"
        )
    )
    return (
        f"train: {config.name} ({config.algo}), seed {seed if seed is not None else config.seed}, "
        f"{steps:,} env steps into {out}; {validation}; {estimate}"
    )


def too_short_line(config: AgentConfig, meta: dict[str, Any]) -> str | None:
    """After a run: why it has no ``best_model.zip`` and no learning curve when it ended
    before its first validation (its folder, ``meta["out_dir"]``, has no curve); None when
    it validated."""
    from shipgym_baselines.learned.curves import CURVE_FILE

    steps, every = int(meta.get("env_steps", 0)), config.eval.freq
    folder = meta.get("out_dir")
    validated = folder is not None and (Path(folder) / CURVE_FILE).is_file()
    if config.algo == "dagger" or validated or steps >= every:
        return None
    return (
        f"note: {config.name} seed {meta.get('seed')}: {steps:,} env steps, fewer than the "
        f"first validation at {every:,} (eval.freq): no best_model.zip and no learning curve "
        f"(model.zip is the last model); train longer (--timesteps {every:,} or more) to "
        "validate"
    )
