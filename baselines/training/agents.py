"""Agent configs (rl-baselines3-zoo style YAML in ``configs/agents``) and their envs.

A config names the algorithm, the policy, the number of env steps, the hyperparameters
passed to the SB3 constructor, the training envs (a scenario distribution, or one fixed
scenario for the batched env) and the periodic evaluation on held-out *validation*
scenarios (never the ``heldout`` or ``inrange`` test sets, kept for the leaderboard).
"""

from __future__ import annotations

import difflib
import inspect
import os
from typing import Any, Literal

from pydantic import Field, StrictInt, ValidationInfo, field_validator, model_validator
from pydantic_core import PydanticCustomError

from shipgym.config import ConfigError, StrictModel, list_names, load_yaml_model, resolve
from shipgym.limits import MAX_HISTORY_STEPS
from shipgym_baselines.learned.curves import PlateauRule

ALGOS = ("ppo", "sac", "td3", "recurrent_ppo", "dagger")


class AgentEnvConfig(StrictModel):
    distribution: str | None = "train"  # scenario distribution (configs/distributions)
    scenario: str | None = None  # or one fixed scenario (needed by vec_env: batched)
    action_mode: Literal["rudder", "guidance"] = "rudder"
    n_envs: int = Field(8, ge=1)
    #: batched: one batched env (a fixed scenario), or on a distribution one
    #: ShipTrialsVectorEnv per ship (n_envs split equally; a fresh trial per reset)
    vec_env: Literal["dummy", "subproc", "batched"] = "subproc"
    normalize_reward: bool = True  # VecNormalize(norm_obs=False): the obs is already scaled
    #: append the controller-context features to the observation (core.CONTEXT_NAMES)
    context_features: bool = False
    #: K: append the last K control steps of (measurements, applied rudder command) to the
    #: observation (core.ObservationHistory; docs/observation.md); 0: none
    history_steps: StrictInt = Field(0, ge=0, le=MAX_HISTORY_STEPS)
    #: discount in physical time: γ = exp(−Ts/τ) per ship with τ = gamma_seconds [s]
    #: (PPO and RecurrentPPO on vec_env batched over a distribution); None: hyperparams.gamma
    gamma_seconds: float | None = Field(None, gt=0)
    #: reward normalisation per ship (each ship's own running return scale) instead of one
    #: VecNormalize over all ships (vec_env batched over a distribution, normalize_reward)
    normalize_per_ship: bool = False

    @model_validator(mode="after")
    def _one_source(self) -> AgentEnvConfig:
        if (self.distribution is None) == (self.scenario is None):
            raise ValueError("env: give exactly one of 'distribution' and 'scenario'")
        per_ship = [key for key in ("gamma_seconds", "normalize_per_ship") if getattr(self, key)]
        if per_ship and not (self.vec_env == "batched" and self.distribution is not None):
            raise ValueError(
                f"env.{per_ship[0]} is per ship: it needs vec_env 'batched' on a distribution"
            )
        if self.normalize_per_ship and not self.normalize_reward:
            raise ValueError("env.normalize_per_ship needs env.normalize_reward: true")
        if self.distribution is not None:
            from shipgym.scenarios.sampling import load_distribution

            if load_distribution(self.distribution).split != "train":
                raise ValueError(
                    f"env.distribution {self.distribution!r} is a test split: agents train on "
                    "a train split only"
                )
            if self.vec_env == "batched":
                ship_env_counts(self.n_envs, len(load_distribution(self.distribution).config.ships))
        if self.scenario is not None and ":" in self.scenario:
            raise ValueError(f"env.scenario {self.scenario!r}: never train on test scenarios")
        return self


class EvalConfig(StrictModel):
    distribution: str = "validation"
    freq: int = Field(20_000, ge=1)  # env steps between evaluations
    #: validation trials per evaluation, the distribution's first (default: all 32 of
    #: ``validation``, :data:`shipgym_baselines.training.selection.SELECTION_TRIALS`)
    n_episodes: int = Field(32, ge=1)
    #: what picks the best model: the mean validation return, or the geometric mean of the
    #: per-trial cost over a reference's (shipgym_baselines.training.selection)
    select_on: Literal["return", "relative_cost"] = "return"

    @model_validator(mode="after")
    def _not_the_test_set(self) -> EvalConfig:
        from shipgym.scenarios.sampling import DistributionError, load_distribution
        from shipgym_baselines.tuning.validation import TEST_ONLY

        test_only = self.distribution in TEST_ONLY
        if not test_only:
            try:
                test_only = load_distribution(self.distribution).config.test_only
            except DistributionError:
                test_only = False  # an unknown distribution is named when training starts
        if test_only:
            raise ValueError(
                f"eval.distribution: {self.distribution!r} is a test split of the leaderboard "
                "(test_only: the held-out or in-range scenarios); select models on 'validation'"
            )
        return self


class AgentConfig(StrictModel):
    name: str
    #: ``dagger``: a student distilled from the oracle (shipgym_baselines.training.dagger_agent;
    #: ``hyperparams`` then holds the DAgger settings)
    algo: Literal["ppo", "sac", "td3", "recurrent_ppo", "dagger"]
    policy: str = "MlpPolicy"
    n_timesteps: int = Field(ge=1)
    seed: int = Field(0, ge=0)
    env: AgentEnvConfig = AgentEnvConfig()
    hyperparams: dict[str, Any] = Field(default_factory=dict)
    policy_kwargs: dict[str, Any] = Field(default_factory=dict)
    eval: EvalConfig = EvalConfig()
    checkpoint_freq: int = Field(50_000, ge=1)  # env steps between checkpoints
    #: stop early once validation plateaus (shipgym_baselines.learned.curves.PlateauRule);
    #: None: train all n_timesteps
    plateau: PlateauRule | None = None

    @model_validator(mode="after")
    def _per_ship_discount(self) -> AgentConfig:
        if self.env.gamma_seconds is not None and self.algo not in ("ppo", "recurrent_ppo"):
            raise ValueError(
                f"env.gamma_seconds: a per-env discount is built for the on-policy rollout "
                f"buffer (ppo, recurrent_ppo), not {self.algo}"
            )
        if self.plateau is not None and self.plateau.metric == "selection":
            if self.eval.select_on != "relative_cost":
                raise ValueError("plateau.metric 'selection' needs eval.select_on: relative_cost")
        if self.algo == "dagger":
            from shipgym_baselines.learned.dagger_config import check_config

            check_config(self)
        return self

    @field_validator("hyperparams")
    @classmethod
    def _constructor_arguments(cls, v: dict[str, Any], info: ValidationInfo) -> dict[str, Any]:
        """Every hyperparameter is an argument of the algorithm's constructor (a misspelt one
        is named with the valid ones), and none is one the trainer sets itself."""
        algo = info.data.get("algo")
        valid = hyperparameter_names(algo) if algo is not None else None
        if valid is None:  # unknown algo (reported on its own) or SB3 not installed
            return v
        problems = []
        for name in v:
            if name in TRAINER_ARGUMENTS:
                problems.append(f"{name!r} is set by the trainer ({TRAINER_ARGUMENTS[name]})")
            elif name not in valid:
                close = difflib.get_close_matches(name, valid, n=1)
                hint = f" (did you mean {close[0]!r}?)" if close else ""
                problems.append(f"unknown hyperparameter {name!r} of {algo}{hint}")
        if problems:
            message = "; ".join(problems) + f"; valid for {algo}: {', '.join(valid)}"
            raise PydanticCustomError("hyperparameter", "{message}", {"message": message})
        return v


#: constructor arguments the trainer passes itself -> where the config sets them
TRAINER_ARGUMENTS = {
    "policy": "the top-level 'policy' key",
    "env": "the 'env' section",
    "seed": "the top-level 'seed' key or --seed",
    "policy_kwargs": "the top-level 'policy_kwargs' key",
    "device": "always cpu",
    "tensorboard_log": "under the output folder",
    "verbose": "always 0",
}


def hyperparameter_names(algo: str) -> list[str] | None:
    """The keyword arguments of the algorithm's SB3 constructor that ``hyperparams`` may set
    (its signature, less :data:`TRAINER_ARGUMENTS` and private ones), sorted; None when the
    algorithm is unknown or stable-baselines3 is not installed; for ``dagger`` the DAgger
    settings (:class:`~shipgym_baselines.learned.dagger_config.DaggerHyperparams`)."""
    if algo == "dagger":
        from shipgym_baselines.learned.dagger_config import hyperparameter_names as dagger_names

        return dagger_names()
    try:
        cls = algo_class(algo)
    except (ImportError, ValueError):
        return None
    parameters = inspect.signature(cls.__init__).parameters.values()
    return sorted(
        p.name
        for p in parameters
        if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)
        and p.name != "self"
        and not p.name.startswith("_")
        and p.name not in TRAINER_ARGUMENTS
    )


def load_agent_config(name_or_path: str | os.PathLike) -> AgentConfig:
    """An agent config by name (``configs/agents/<name>.yaml``) or path; errors name the key."""
    file = resolve("agents", name_or_path, error=ConfigError)
    return load_yaml_model(file, AgentConfig, ConfigError)


def list_agent_configs() -> list[str]:
    """Names of the packaged agent configs (``configs/agents``)."""
    return list_names("agents")


def algo_class(algo: str) -> type:
    """The SB3 / sb3-contrib class of an algorithm id (``dagger``: PPO, its student's)."""
    if algo == "recurrent_ppo":
        from sb3_contrib import RecurrentPPO

        return RecurrentPPO
    import stable_baselines3 as sb3

    classes = {"ppo": sb3.PPO, "sac": sb3.SAC, "td3": sb3.TD3, "dagger": sb3.PPO}
    if algo not in classes:
        raise ValueError(f"unknown algorithm {algo!r}; valid: {', '.join(ALGOS)}")
    return classes[algo]


def _single_env_factory(
    source: dict[str, Any],
    action_mode: str,
    context_features: bool = False,
    history_steps: int = 0,
):
    def make() -> Any:
        import gymnasium as gym

        import shipgym

        if source.get("scenario") is not None:
            # the configured scenario itself, truncated at its own time limit
            return gym.make(
                "ShipPathFollow-v0",
                scenario=source["scenario"],
                action_mode=action_mode,
                context_features=context_features,
                history_steps=history_steps,
                randomize=False,
                max_episode_steps=-1,
            )
        return gym.make(
            shipgym.RANDOMIZED_ENV_ID,
            distribution=source["distribution"],
            action_mode=action_mode,
            context_features=context_features,
            history_steps=history_steps,
            max_episode_steps=-1,  # each drawn scenario's own time limit
        )

    return make


def ship_env_counts(n_envs: int, n_ships: int) -> list[int]:
    """Envs per ship when ``n_envs`` are split over ``n_ships`` batched envs: equal shares
    (each ship then gets the same share of env steps); a ValueError (in a config: its
    ConfigError naming the key) unless ``n_envs`` is a positive multiple of ``n_ships``."""
    if n_envs < n_ships or n_envs % n_ships:
        raise ValueError(
            f"env.n_envs {n_envs}: vec_env 'batched' on a distribution of {n_ships} ships "
            f"needs a multiple of {n_ships} (one batched env per ship, equal shares)"
        )
    return [n_envs // n_ships] * n_ships


def make_ship_envs(config: AgentEnvConfig) -> list[Any]:
    """One :class:`~shipgym.envs.ship_batch.ShipTrialsVectorEnv` per ship of the config's
    distribution (in the distribution's ship order), ``n_envs`` split equally."""
    from shipgym.envs.ship_batch import ShipTrialsVectorEnv
    from shipgym.scenarios.sampling import load_distribution

    dist = load_distribution(config.distribution)
    counts = ship_env_counts(config.n_envs, len(dist.config.ships))
    return [
        ShipTrialsVectorEnv(
            n,
            dist,
            k,
            config.action_mode,
            context_features=config.context_features,
            history_steps=config.history_steps,
        )
        for k, n in enumerate(counts)
    ]


def make_training_env(config: AgentEnvConfig, seed: int) -> Any:
    """The SB3 VecEnv of a config (DummyVecEnv / SubprocVecEnv / batched), seeded."""
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv, VecMonitor

    if config.vec_env == "batched" and config.distribution is not None:
        from shipgym_baselines.learned.vec_env import SB3ShipsVecEnv

        venv = SB3ShipsVecEnv(make_ship_envs(config))
    elif config.vec_env == "batched":
        from shipgym.envs.vector import ShipPathFollowVectorEnv
        from shipgym_baselines.learned.vec_env import SB3BatchedVecEnv

        venv = SB3BatchedVecEnv(
            ShipPathFollowVectorEnv(
                config.n_envs,
                config.scenario,
                config.action_mode,
                context_features=config.context_features,
                history_steps=config.history_steps,
            )
        )
    else:
        factory = _single_env_factory(
            {"scenario": config.scenario, "distribution": config.distribution},
            config.action_mode,
            config.context_features,
            config.history_steps,
        )
        cls = SubprocVecEnv if config.vec_env == "subproc" and config.n_envs > 1 else DummyVecEnv
        venv = cls([factory] * config.n_envs)
    venv.seed(seed)
    return VecMonitor(venv)


def make_eval_env(config: EvalConfig, env: AgentEnvConfig, seed: int) -> Any:
    """One env cycling through the validation scenarios in order, seeded (reproducible
    model selection), observing and acting as the training envs of ``env`` do."""
    from stable_baselines3.common.vec_env import DummyVecEnv

    factory = _single_env_factory(
        {"distribution": config.distribution},
        env.action_mode,
        env.context_features,
        env.history_steps,
    )
    venv = DummyVecEnv([factory])
    venv.seed(seed)
    return venv


def build_hyperparams(config: AgentConfig, n_actions: int) -> dict[str, Any]:
    """SB3 constructor kwargs from the config (action noise objects built here)."""
    kwargs = dict(config.hyperparams)
    noise = kwargs.pop("action_noise", None)
    if noise is not None:
        import numpy as np
        from stable_baselines3.common.noise import NormalActionNoise

        if noise.get("type", "normal") != "normal":
            raise ValueError(f"hyperparams.action_noise.type: only 'normal', got {noise}")
        sigma = float(noise.get("sigma", 0.1))
        kwargs["action_noise"] = NormalActionNoise(np.zeros(n_actions), sigma * np.ones(n_actions))
    if config.policy_kwargs:
        kwargs["policy_kwargs"] = dict(config.policy_kwargs)
    return kwargs
