"""Batched training env on one ship of a distribution: a fresh trial per env at every reset.

:class:`ShipTrialsVectorEnv` steps N envs of one ship of a train-split distribution
(``configs/distributions``); each env draws a new trial (parameters, route, jumps,
disturbances, sensors, guidance law, time limit) at every reset, exactly as
:class:`~shipgym.envs.randomized.ShipPathFollowRandomizedEnv` does with that ship fixed:
env i's generator (seeded ``seed + i``) gives the scenario seed
(:func:`~shipgym.scenarios.sampling.train_scenario_seed`), the trial is
``distribution.sample(train_rng(scenario_seed), ship_index=k)`` and the episode seed (for
disturbance and sensor noise) follows; so env i's episode is that of a
:class:`~shipgym.envs.path_follow.ShipPathFollowEnv` on the drawn trial reset with the
episode seed (tested).

The plant of all N envs is one call of the ship's compiled period function (the true
parameters and disturbances are per-row inputs); reward, observation and termination are
the step core's functions (:mod:`shipgym.envs.core`) on arrays.  Per env, in Python, remain
what differs between trials: the path tracker, the parameter schedule, the disturbance
processes and the sensors.  A reset builds the trial's scenario (no integrator, no
compile).  Its per-call cost is spread over the envs of the call: it pays off with many
envs per ship (docs/training.md gives the measured rates).

Autoreset as :class:`~shipgym.envs.vector.ShipPathFollowVectorEnv` (NEXT_STEP, plus
:meth:`reset_finished` for same-step adapters such as stable-baselines3's).  ``info``
holds, at episode ends only, ``termination_reason`` (with its ``_`` mask): no per-step
keys and no episode metrics (a training env).  Not registered with ``gym.make``: build it
directly, or through ``shipgym_baselines.training.agents`` (one per ship, combined).
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from gymnasium.vector import AutoresetMode

from shipgym.envs import core
from shipgym.envs.trial_rows import Trial, TrialRowsVectorEnv, shared_constants_problem
from shipgym.scenarios.loader import Scenario, build_scenario
from shipgym.scenarios.sampling import (
    DistributionError,
    ScenarioDistribution,
    load_distribution,
    train_rng,
    train_scenario_seed,
)

__all__ = [
    "ShipTrialsVectorEnv",
    "ship_index_of",
]


def ship_index_of(distribution: ScenarioDistribution, ship: int | str) -> int:
    """The index in ``distribution``'s ship list of ``ship`` (an index or a model name)."""
    ships = [s.model for s in distribution.config.ships]
    if isinstance(ship, int) and not isinstance(ship, bool):
        if 0 <= ship < len(ships):
            return ship
    elif ship in ships:
        return ships.index(ship)
    raise DistributionError(
        f"ship {ship!r} is not in distribution {distribution.name!r}; valid: "
        f"{', '.join(ships)} or 0 … {len(ships) - 1}"
    )


class ShipTrialsVectorEnv(TrialRowsVectorEnv):
    """N envs of one ship of a train distribution, a fresh trial each reset (module doc)."""

    metadata: ClassVar[dict[str, Any]] = {
        "autoreset_mode": AutoresetMode.NEXT_STEP,
        "render_modes": [],
    }

    def __init__(
        self,
        num_envs: int,
        distribution: str | ScenarioDistribution = "train",
        ship: int | str = 0,
        action_mode: str = "rudder",
        compile: bool = True,
        context_features: bool = False,
        history_steps: int = 0,
    ) -> None:
        if not (isinstance(num_envs, int) and num_envs >= 1):
            raise ValueError(f"num_envs must be an int ≥ 1, got {num_envs!r}")
        dist = (
            distribution
            if isinstance(distribution, ScenarioDistribution)
            else load_distribution(distribution)
        )
        if dist.split != "train":
            raise DistributionError(
                f"distribution {dist.name!r} is a {dist.split} split: the trial env draws "
                "training trials (train split) only"
            )
        self.distribution = dist
        self.ship_index = ship_index_of(dist, ship)
        self.ship = dist.config.ships[self.ship_index].model
        self._first = self._draw(train_rng(0), "first")
        super().__init__(
            num_envs, self._first, action_mode, compile, context_features, history_steps
        )
        self.episode_metrics = False  # a training env: no per-episode metrics
        self._rngs: list[np.random.Generator | None] = [None] * num_envs
        #: each env's current trial (names ``<distribution>:train-<seed>``)
        self.trial_scenarios: list[Scenario | None] = [None] * num_envs
        self._autoreset = np.zeros(num_envs, dtype=bool)
        self._started = False

    def _draw(self, rng: np.random.Generator, label: str) -> Scenario:
        """The trial ``label`` drawn from the ship's distribution with ``rng``."""
        config = self.distribution.sample(
            rng, name=f"{self.distribution.name}:train-{label}", ship_index=self.ship_index
        )
        return build_scenario(config, config.name)

    # ------------------------------------------------------------------ gym vector API
    def reset(
        self, *, seed: int | list[int | None] | None = None, options: dict | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        mask = core.reseed_rows(self._rngs, seed, options)
        self._reset_envs(mask)
        self._autoreset[mask] = False
        self._started = True
        self._obs = self._observation()
        return self._obs, {}

    def reset_finished(self) -> tuple[np.ndarray, np.ndarray]:
        """Reset now the envs whose episode ended at the last step; returns (observations
        of all envs, mask of the envs reset) (as ShipPathFollowVectorEnv.reset_finished)."""
        mask = self._autoreset.copy()
        if np.any(mask):
            self._reset_envs(mask)
            self._autoreset[:] = False
            self._obs = self._observation()
        return self._obs, mask

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if not self._started:
            raise RuntimeError("call reset() before step()")
        a = core.batch_actions(actions, self.action_space.shape)
        resetting = self._autoreset.copy()
        if np.any(resetting):
            self._reset_envs(resetting)
        period = self._advance(a, ~resetting)
        terminated, truncated = period.terminated, period.truncated
        done = terminated | truncated
        info: dict[str, Any] = {}
        if np.any(done):
            info["termination_reason"] = period.reasons()
            info["_termination_reason"] = done
        self._autoreset = done
        self._obs = self._observation(period.frame)
        return self._obs, period.reward, terminated, truncated, info

    # ------------------------------------------------------------------ pieces
    def _new_trial(self, i: int) -> Trial:
        """Draw env i's next trial from its generator (the randomised env's order)."""
        rng = self._rngs[i]
        scenario_seed = train_scenario_seed(rng)
        sc = self._draw(train_rng(scenario_seed), str(scenario_seed))
        episode_seed = int(rng.integers(0, 2**31 - 1))
        problem = shared_constants_problem(self._first, sc)
        if problem is not None:
            raise DistributionError(
                f"{self.distribution.name}: ship {self.ship!r} draws trials whose {problem}; "
                "the trial env needs them shared"
            )
        self.trial_scenarios[i] = sc
        return Trial.of(sc, episode_seed, self.action_mode, self.context_features)

    def _reset_envs(self, mask: np.ndarray) -> None:
        k = self._k0
        for i in np.flatnonzero(mask).tolist():
            trial = self._new_trial(i)
            self._install(i, trial)
            x, y = float(self._state.x[i, k.ix]), float(self._state.x[i, k.iy])
            self._tracks.install(i, trial.tracker, x, y)
