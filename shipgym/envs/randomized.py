"""ShipPathFollow on a randomised scenario distribution (training envs for learned agents).

Every ``reset`` draws a scenario from the distribution with the env's own seeded generator
(train split: :func:`~shipgym.scenarios.sampling.train_scenario_seed`; test split: the
named test scenarios in turn, or ``options={"index": i}``) and runs it in an ordinary
:class:`~shipgym.envs.path_follow.ShipPathFollowEnv`: same observation, action, reward,
``info`` and metrics, except that ``info`` has no ``samples`` (as the batched env): their
number per step, Ts/h, differs between the ships of a distribution, which Gymnasium's
vector envs cannot stack (online identification runs on the single env).  The observation
and action spaces do not depend on the scenario, so one policy serves the whole
distribution.  ``reset(seed=s)`` is reproducible.
"""

from __future__ import annotations

from typing import Any, ClassVar

import gymnasium as gym
import numpy as np

from shipgym.envs.path_follow import ShipPathFollowEnv
from shipgym.scenarios.loader import build_scenario
from shipgym.scenarios.sampling import (
    ScenarioDistribution,
    load_distribution,
    train_rng,
    train_scenario_seed,
)


class ShipPathFollowRandomizedEnv(gym.Env):
    """A new scenario from ``distribution`` at every reset: the training env of learned agents.

    .. rubric:: Description

    Every ``reset`` draws a scenario from a scenario distribution (``configs/distributions``:
    ``train``, ``validation``, ``heldout``) with the env's own seeded generator and runs it in
    an ordinary :class:`~shipgym.envs.path_follow.ShipPathFollowEnv`; ``reset(seed=s)`` is
    reproducible.

    .. rubric:: Action space, observation space, reward, episode end

    Those of :class:`~shipgym.envs.path_follow.ShipPathFollowEnv` (see any
    ``ShipPathFollow-*`` page): they do not depend on the scenario, so one policy serves the
    whole distribution.  ``info`` has no ``samples`` (their number per step, Ts/h, differs
    between the ships of a distribution).

    .. rubric:: Starting state

    The drawn scenario's ``initial_state``.

    .. rubric:: Arguments

    ``gym.make("ShipPathFollowRandomized-v0", distribution="train", action_mode="rudder",
    render_mode=None, compile=True)``; ``distribution``: a name in ``configs/distributions``
    or a :class:`~shipgym.scenarios.sampling.ScenarioDistribution`; on a test split
    ``reset(options={"index": i})`` picks the i-th test scenario.  ``context_features`` and
    ``history_steps`` as the single env's (each reset starts a new history window).

    The spec's ``max_episode_steps`` is the longest episode the ``train`` distribution can
    draw (:meth:`~shipgym.scenarios.sampling.ScenarioDistribution.max_episode_steps`); each
    episode ends at its own scenario's time limit first.

    .. rubric:: Version history

    ``-v0``: the only version (``max_episode_steps`` added to its spec, in place).
    """

    metadata: ClassVar[dict[str, Any]] = ShipPathFollowEnv.metadata

    def __init__(
        self,
        distribution: str | ScenarioDistribution = "train",
        action_mode: str = "rudder",
        render_mode: str | None = None,
        compile: bool = True,
        context_features: bool = False,
        history_steps: int = 0,
    ) -> None:
        self.distribution = (
            distribution
            if isinstance(distribution, ScenarioDistribution)
            else load_distribution(distribution)
        )
        self.action_mode = action_mode
        self.render_mode = render_mode
        self._compile = compile
        self.context_features = context_features
        self._next_test_index = 0
        self._env = self._make_env(self._first_config(), history_steps)
        #: K: the observation ends with the last K control steps (as the single env)
        self.history_steps = self._env.history_steps
        self.action_space = self._env.action_space
        self.observation_space = self._env.observation_space

    def _first_config(self):
        if self.distribution.split == "test":
            return self.distribution.test_scenario(0)
        return self.distribution.sample(train_rng(0))

    def _make_env(self, config, history_steps: int) -> ShipPathFollowEnv:
        return ShipPathFollowEnv(
            build_scenario(config, config.name),
            action_mode=self.action_mode,
            render_mode=self.render_mode,
            compile=self._compile,
            context_features=self.context_features,
            history_steps=history_steps,
        )

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        options = options or {}
        if self.distribution.split == "test":
            index = int(options.get("index", self._next_test_index))
            config = self.distribution.test_scenario(index)  # raises on a bad index
            self._next_test_index = (index + 1) % len(self.distribution)
        else:
            scenario_seed = train_scenario_seed(self.np_random)
            config = self.distribution.sample(
                train_rng(scenario_seed), name=f"{self.distribution.name}:train-{scenario_seed}"
            )
        self._env.use_scenario(build_scenario(config, config.name))
        episode_seed = int(self.np_random.integers(0, 2**31 - 1))
        # the scenario's name identifies its schedule: an attribute for logging, never in
        # info or the observation (which controllers read)
        self.scenario_name = config.name
        return self._env.reset(seed=episode_seed)

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self._env.step(action)
        info.pop("samples", None)  # Ts/h samples: their number differs between ships
        return obs, reward, terminated, truncated, info

    def __getattr__(self, name: str) -> Any:
        """The current scenario's env answers the rest (``scenario``, ``model``,
        ``controller_context``, ``episode_metrics``, ``track``, …)."""
        env = self.__dict__.get("_env")
        if env is None or name.startswith("__"):
            raise AttributeError(name)
        return getattr(env, name)

    def render(self) -> np.ndarray | None:
        return self._env.render()

    def close(self) -> None:
        self._env.close()
