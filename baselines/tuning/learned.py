"""The learned side of a study: train a short run per trial, score it on the validation
trials, prune on its intermediate evaluations.

A trial's parameters are dotted paths into the agent config (``configs/agents``):
``hyperparams.learning_rate``, ``hyperparams.gamma``, ``policy_kwargs.log_std_init``,
``policy_kwargs.net_arch`` (a choice written ``"64x64"``), ``env.n_envs``, ….  The run
trains ``training.n_timesteps`` env steps in ``training.evaluations`` equal parts (each
part ends at a checkpoint, and the next resumes from it); after each part the current model
is scored on the study's validation trials — the cost ratio to the oracle, their geometric
mean reported to the pruner — so a poor configuration stops early.  The value of the trial
is the last part's.  An ``algo: dagger`` agent's env steps are its teacher labels: each part
runs its rounds until the part's labels are reached (:func:`dagger_part`).  Runs live in
``<study folder>/runs/trial_<n>`` (the default in ``runs/default``).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from shipgym_baselines.errors import RunError
from shipgym_baselines.scoring.intervals import geometric_mean
from shipgym_baselines.tuning.objective import controller_ratios
from shipgym_baselines.tuning.space import TuningConfig
from shipgym_baselines.tuning.validation import ValidationTrial

#: the agent-config blocks a dotted parameter may set
BLOCKS = ("hyperparams", "policy_kwargs", "env")


def apply_overrides(agent: Any, overrides: dict[str, Any]) -> Any:
    """The agent config ``agent`` with each dotted ``block.key`` of ``overrides`` set."""
    blocks: dict[str, dict[str, Any]] = {}
    for name, value in overrides.items():
        block, _, key = name.partition(".")
        if block not in BLOCKS or not key:
            raise RunError(
                f"learned parameter {name!r}: write it as <block>.<key>, block one of {BLOCKS}"
            )
        if key == "net_arch" and isinstance(value, str):
            value = [int(width) for width in value.split("x")]
        blocks.setdefault(block, {})[key] = value
    updates: dict[str, Any] = {}
    for block, values in blocks.items():
        current = getattr(agent, block)
        if block == "env":
            updates[block] = current.model_copy(update=values)
        else:
            updates[block] = {**current, **values}
    return agent.model_validate(
        {
            **agent.model_dump(),
            **{k: (v.model_dump() if hasattr(v, "model_dump") else v) for k, v in updates.items()},
        }
    )


def dagger_part(agent: Any, labels: int) -> Any:
    """The ``algo: dagger`` config ``agent`` trained to the end of a part: its rounds until
    ``labels`` teacher labels (env steps) are reached, after the round that reaches them (a
    DAgger run continues to a higher cap); no plateau rule (the study's pruner stops a poor
    trial)."""
    return agent.model_copy(update={"n_timesteps": labels, "plateau": None})


def train_and_score(
    config: TuningConfig,
    overrides: dict[str, Any],
    trials: Sequence[ValidationTrial],
    oracle: Sequence[float],
    folder: Path,
    report: Callable[[float, int], None] | None = None,
) -> list[float]:
    """Train the agent with ``overrides`` in parts, score each part (module doc); the last
    part's per-trial ratios."""
    from shipgym_baselines.training.agents import load_agent_config
    from shipgym_baselines.training.train import latest_checkpoint, train

    spec = config.training
    assert spec is not None  # a learned config has one (validated)
    agent = apply_overrides(load_agent_config(spec.agent), overrides)
    part = max(1, spec.n_timesteps // spec.evaluations)
    # checkpoints at the parts' ends; no periodic evaluation of its own (scored here)
    quiet = agent.eval.model_copy(update={"freq": 10 * spec.n_timesteps})
    agent = agent.model_copy(
        update={"checkpoint_freq": part, "eval": quiet, "n_timesteps": spec.n_timesteps}
    )
    fit = functools.partial(train, progress=False, tensorboard=False)
    ratios: list[float] = []
    for k in range(1, spec.evaluations + 1):
        steps = part * k if k < spec.evaluations else spec.n_timesteps
        if agent.algo == "dagger":
            # a re-run trial (failed before) starts afresh: force deletes what its run wrote
            meta = fit(dagger_part(agent, steps), folder, resume=k > 1, force=k == 1)
            steps = int(meta["env_steps"])
        else:
            latest = latest_checkpoint(folder) if k > 1 else None
            if latest is None or latest[1] < steps:  # a part a long rollout covered: skip
                fit(agent, folder, n_timesteps=steps, resume=k > 1, force=k == 1)
        ratios = controller_ratios(str(folder / "model.zip"), {}, trials, oracle)
        if report is not None:
            report(geometric_mean(ratios), steps)
    return ratios
