"""The ``hyperparams`` block of an ``algo: dagger`` agent config, checked: DAgger's settings
(:class:`~shipgym_baselines.learned.dagger.DaggerSettings`) as an agent config gives them.
The agent config reads it when it is validated; the DAgger agent
(:mod:`shipgym_baselines.training.dagger_agent`) trains with it."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field

from shipgym.config import StrictModel

#: env seeds per training seed: seed k's rollouts use env seeds k·stride, k·stride + 1, …
ENV_SEED_STRIDE = 1000
#: the student's ``policy_kwargs`` (JSON data the data-only loader reads)
STUDENT_KWARGS = ("net_arch", "log_std_init")


class DaggerHyperparams(StrictModel):
    """The ``hyperparams`` block of an ``algo: dagger`` config (docs/training.md); the fields of
    :class:`~shipgym_baselines.learned.dagger.DaggerSettings` but the seeds and the
    network, and the run's ``rounds`` and ``workers``."""

    #: rounds at most (round 0: the teacher's own rollouts)
    rounds: int = Field(10, ge=1)
    episodes_per_round: int = Field(8, ge=1)
    beta_schedule: Literal["indicator", "exponential"] = "indicator"
    beta_decay: float = Field(0.5, gt=0, lt=1)
    epochs: int = Field(20, ge=1)
    batch_size: int = Field(256, ge=1)
    learning_rate: float = Field(1e-3, gt=0)
    warm_start: bool = True
    #: processes labelling a round's rollouts (1: here); the data do not depend on it
    workers: int = Field(1, ge=1)


def hyperparameter_names() -> list[str]:
    """The keys an ``algo: dagger`` config's ``hyperparams`` may set, sorted."""
    return sorted(DaggerHyperparams.model_fields)


def check_config(config: Any) -> None:
    """A ValueError naming the key unless the ``algo: dagger`` config ``config`` can train:
    rudder commands (the oracle's), the relative-cost selection, an ``MlpPolicy`` student
    whose ``policy_kwargs`` are data, valid DAgger hyperparameters."""
    if config.env.action_mode != "rudder":
        raise ValueError(
            "env.action_mode: the dagger student imitates the oracle's rudder commands"
        )
    if config.eval.select_on != "relative_cost":
        raise ValueError(
            "eval.select_on: a dagger agent selects its round on the relative cost "
            "('relative_cost')"
        )
    if config.policy != "MlpPolicy":
        raise ValueError(f"policy: the dagger student is an MlpPolicy, not {config.policy!r}")
    extra = sorted(set(config.policy_kwargs) - set(STUDENT_KWARGS))
    if extra:
        raise ValueError(
            f"policy_kwargs: the dagger student takes {', '.join(STUDENT_KWARGS)}, not "
            f"{', '.join(extra)}"
        )
    settings(config)  # the values' types and ranges


def hyperparams(config: Any) -> DaggerHyperparams:
    """The config's DAgger hyperparameters, checked."""
    return DaggerHyperparams.model_validate(config.hyperparams)


def settings(config: Any) -> Any:
    """The :class:`~shipgym_baselines.learned.dagger.DaggerSettings` of the config (its
    seed, its env seeds from ``seed ×`` :data:`ENV_SEED_STRIDE`, its network)."""
    from shipgym_baselines.learned.dagger import DaggerSettings

    found = hyperparams(config).model_dump(exclude={"rounds", "workers"})
    student = {k: config.policy_kwargs[k] for k in STUDENT_KWARGS if k in config.policy_kwargs}
    return DaggerSettings(
        seed=config.seed, env_seed_start=config.seed * ENV_SEED_STRIDE, **found, **student
    )
