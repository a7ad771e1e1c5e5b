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
directly, or through ``shipgym_baselines.learned.agents`` (one per ship, combined).
"""

from __future__ import annotations

import dataclasses
import operator
from typing import Any, ClassVar

import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from shipgym.angles import wrap_angle
from shipgym.autopilot import PIDGains
from shipgym.disturbances import Disturbances, SensorModel
from shipgym.envs import core
from shipgym.envs.core import OBS_HIGH, OBS_LOW
from shipgym.models.integrator import PeriodIntegrator
from shipgym.numerics import ARRAY, SCALAR
from shipgym.scenarios import Scenario, ScenarioConfig
from shipgym.scenarios.loader import build_scenario, nominal_nomoto
from shipgym.scenarios.sampling import (
    DistributionError,
    ScenarioDistribution,
    load_distribution,
    train_rng,
    train_scenario_seed,
)
from shipgym.tracking import PathTracker, TrackFrame

#: a TrackFrame's fields as a tuple, in declaration order
_FRAME_ROW = operator.attrgetter(*(f.name for f in dataclasses.fields(TrackFrame)))

#: the constants every trial of a ship shares (the time limit, max_steps, differs)
_SHARED = ("ship_length", "rudder_limit", "control_period", "fine_step", "substeps")


@dataclasses.dataclass
class Trial:
    """One env's current trial: its scenario and the per-trial pieces of the step."""

    scenario: Scenario
    constants: core.StepConstants
    tracker: PathTracker
    disturbances: Disturbances
    sensor: SensorModel
    autopilot_gains: PIDGains | None  # guidance mode (core.guidance_command reads it)
    context_row: np.ndarray | None
    rng: np.random.Generator  # the episode's generator (disturbance and sensor noise)


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


class ShipTrialsVectorEnv(VectorEnv):
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
        first = build_scenario(self._draw(train_rng(0), "first"))
        self._parts = core.EnvParts.build(
            first, action_mode, compile, batch=num_envs, context_features=context_features
        )
        self.num_envs = num_envs
        self.action_mode = action_mode
        self.context_features = context_features
        self.render_mode = None
        self.episode_metrics = False  # a training env: no per-episode metrics
        self.single_observation_space = self._parts.observation_space
        self.single_action_space = self._parts.action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self._k0 = k = self._parts.constants
        self._integrator: PeriodIntegrator = self._parts.integrator
        self._w_block = self._integrator.disturbance_buffer
        self._p_block = self._integrator.parameter_buffer
        self._rngs: list[np.random.Generator | None] = [None] * num_envs
        self._trials: list[Trial | None] = [None] * num_envs
        #: the config of each env's current trial (names ``<distribution>:train-<seed>``)
        self.trial_configs: list[ScenarioConfig | None] = [None] * num_envs
        self._max_steps = np.zeros(num_envs, dtype=np.int64)
        #: the constants with each env's own time limit (max_steps, updated in place)
        self._kk = dataclasses.replace(k, max_steps=self._max_steps)
        self._p_dirty = np.zeros(num_envs, dtype=bool)
        self._event_start = np.full(num_envs, np.inf)  # first event time [s]
        self._event_end = np.full(num_envs, -np.inf)  # last event end [s]
        self._time_varying = np.zeros(num_envs, dtype=bool)
        self._state = np.zeros((num_envs, first.model.n_states))
        self._steps = np.zeros(num_envs, dtype=np.int64)
        self._t = np.zeros(num_envs)
        self._delta_c = np.zeros(num_envs)
        self._psi_m = np.zeros(num_envs)
        self._r_m = np.zeros(num_envs)
        self._speed = np.full(num_envs, k.nominal_speed)
        self._integral = np.zeros(num_envs)
        self._context = np.zeros((num_envs, self._parts.context_row.size), dtype=np.float32)
        self._frames: list[TrackFrame | None] = [None] * num_envs
        self._autoreset = np.zeros(num_envs, dtype=bool)
        self._started = False

    def _draw(self, rng: np.random.Generator, label: str) -> ScenarioConfig:
        return self.distribution.sample(
            rng, name=f"{self.distribution.name}:train-{label}", ship_index=self.ship_index
        )

    # ------------------------------------------------------------------ gym vector API
    def reset(
        self, *, seed: int | list[int | None] | None = None, options: dict | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        if seed is None or isinstance(seed, int):
            seeds = [None if seed is None else seed + i for i in range(self.num_envs)]
        else:
            if len(seed) != self.num_envs:
                raise ValueError(f"need {self.num_envs} seeds, got {len(seed)}")
            seeds = list(seed)
        mask = np.ones(self.num_envs, dtype=bool)
        if options and "reset_mask" in options:
            mask = np.asarray(options["reset_mask"], dtype=bool)
            if mask.shape != (self.num_envs,):
                raise ValueError(f"reset_mask must have shape ({self.num_envs},)")
        for i, s in enumerate(seeds):
            if mask[i] and (s is not None or self._rngs[i] is None):
                self._rngs[i], _ = seeding.np_random(s)
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
        k = self._k0
        resetting = self._autoreset.copy()
        if np.any(resetting):
            self._reset_envs(resetting)
        live = ~resetting
        rows = np.flatnonzero(live)
        trials: list[Trial] = self._trials  # type: ignore[assignment]
        if self.action_mode == "rudder":
            delta_c = a[:, 0] * k.rudder_limit
        else:
            delta_c = self._delta_c.copy()
            for i in rows:
                delta_c[i], self._integral[i] = core.guidance_command(
                    a[i, 0],
                    a[i, 1],
                    self._frames[i],
                    self._psi_m[i],
                    self._r_m[i],
                    self._integral[i],
                    trials[i],
                    SCALAR,
                )
        delta_c = np.where(live, delta_c, self._delta_c)
        prev_delta_c = self._delta_c.copy()
        t0 = self._t.copy()
        # true parameters of the period: only for envs whose event acts on it (or just did)
        t1 = t0 + k.control_period
        changing = live & (self._event_end >= t0 - 1e-9) & (self._event_start <= t1 + 1e-9)
        for i in np.flatnonzero(changing | (live & self._p_dirty)).tolist():
            tr = trials[i]
            self._p_dirty[i] = core.refresh_parameters(
                tr.scenario.schedule,
                float(t0[i]),
                tr.constants,
                self._p_block[i],
                bool(self._p_dirty[i]),
            )
        for i in np.flatnonzero(live & self._time_varying).tolist():  # disturbances
            trials[i].disturbances.fill_one(self._w_block[i], float(t0[i]), trials[i].rng)
        traj = self._integrator.substep_states(self._state, delta_c, self._w_block, self._p_block)
        steps = np.where(live, self._steps + 1, self._steps)
        last = traj[:, -1]
        finite = np.all(np.isfinite(last), axis=1)
        advance = live & finite
        self._steps = steps
        self._t = np.where(live, steps * k.control_period, self._t)
        self._delta_c = delta_c
        self._state = np.where(advance[:, None], last, self._state)
        if k.substeps > 1:
            dx = last[:, k.ix] - traj[:, -2, k.ix]
            dy = last[:, k.iy] - traj[:, -2, k.iy]
            self._speed = np.where(advance, core.speed_over_ground(dx, dy, k, ARRAY), self._speed)
        psi_m = np.where(advance, last[:, k.ipsi], self._psi_m)
        r_m = np.where(advance, last[:, k.ir], self._r_m)
        xs, ys = self._state[:, k.ix].tolist(), self._state[:, k.iy].tolist()
        for i in np.flatnonzero(advance).tolist():
            tr = trials[i]
            if not tr.sensor.ideal:
                p_i, r_i = tr.sensor.measure(traj[i, :, k.ipsi], traj[i, :, k.ir], tr.rng)
                psi_m[i], r_m[i] = p_i[-1], r_i[-1]
            self._frames[i] = tr.tracker.update(xs[i], ys[i])
        self._psi_m, self._r_m = psi_m, r_m
        frame = self._stacked_frames()
        heading_error = wrap_angle(self._state[:, k.ipsi] - frame.path_angle)
        reward = core.step_reward(frame.cross_track, heading_error, delta_c, prev_delta_c, k, ARRAY)
        kk = self._kk  # the constants with each env's own max_steps
        reward, goal, corridor, truncated = core.terminate(reward, frame, steps, kk, ARRAY)
        goal, corridor, truncated = goal & advance, corridor & advance, truncated & advance
        diverged = live & ~finite
        reward = np.where(diverged, core.diverged_reward(steps, kk), reward)
        terminated = goal | corridor | diverged
        rewards = np.where(live, reward, 0.0)
        done = terminated | truncated
        info: dict[str, Any] = {}
        if np.any(done):
            reasons = np.full(self.num_envs, None, dtype=object)
            reasons[goal] = "goal"
            reasons[corridor] = "corridor"
            reasons[diverged] = "non_finite_state"
            reasons[truncated] = "time_limit"
            info["termination_reason"] = reasons
            info["_termination_reason"] = done
        self._autoreset = done
        self._obs = self._observation(frame)
        return self._obs, rewards, terminated, truncated, info

    # ------------------------------------------------------------------ pieces
    def _new_trial(self, i: int) -> Trial:
        """Draw env i's next trial from its generator (the randomised env's order)."""
        rng = self._rngs[i]
        scenario_seed = train_scenario_seed(rng)
        config = self._draw(train_rng(scenario_seed), str(scenario_seed))
        episode_seed = int(rng.integers(0, 2**31 - 1))
        sc = build_scenario(config, config.name)
        k = core.StepConstants.of(sc)
        for name in _SHARED:
            if getattr(k, name) != getattr(self._k0, name):
                raise DistributionError(
                    f"{self.distribution.name}: ship {self.ship!r} draws trials with "
                    f"different {name} ({getattr(k, name)} vs {getattr(self._k0, name)}); "
                    "the trial env needs them shared"
                )
        gains = None
        if self.action_mode == "guidance":
            gains = PIDGains.from_nomoto(*nominal_nomoto(sc))
        self.trial_configs[i] = config
        return Trial(
            scenario=sc,
            constants=k,
            tracker=PathTracker(sc.path, sc.acceptance_radius, sc.config.path.switching),
            disturbances=Disturbances(
                sc.config.disturbances,
                sc.model.disturbance_names,
                k.fine_step,
                k.substeps,
                time_limit=sc.config.time_limit,
            ),
            sensor=SensorModel(sc.config.sensors),
            autopilot_gains=gains,
            context_row=core.scenario_context_row(sc) if self.context_features else None,
            rng=seeding.np_random(episode_seed)[0],
        )

    def _reset_envs(self, mask: np.ndarray) -> None:
        k = self._k0
        for i in np.flatnonzero(mask):
            tr = self._trials[i] = self._new_trial(i)
            sc = tr.scenario
            x = self._state[i] = sc.initial_state()
            self._max_steps[i] = tr.constants.max_steps
            events = sc.schedule.events
            self._event_start[i] = min((e.time for e in events), default=np.inf)
            self._event_end[i] = max((e.end_time() for e in events), default=-np.inf)
            self._p_dirty[i] = False
            self._time_varying[i] = tr.disturbances.time_varying
            self._steps[i] = 0
            self._t[i] = 0.0
            self._delta_c[i] = 0.0
            self._integral[i] = 0.0
            self._speed[i] = tr.constants.nominal_speed
            self._p_block[i] = sc.schedule.vector_at(0.0)
            self._w_block[i] = tr.disturbances.constant_row()
            tr.disturbances.reset(0, tr.rng)  # before the sensor's draws (as the single env)
            tr.sensor.reset()
            psi_m, r_m = tr.sensor.measure(x[k.ipsi : k.ipsi + 1], x[k.ir : k.ir + 1], tr.rng)
            self._psi_m[i], self._r_m[i] = float(psi_m[0]), float(r_m[0])
            self._frames[i] = tr.tracker.reset(float(x[k.ix]), float(x[k.iy]))
            if self.context_features:
                self._context[i] = tr.context_row

    def _stacked_frames(self) -> TrackFrame:
        """The envs' frames as one TrackFrame of arrays."""
        table = np.array([_FRAME_ROW(f) for f in self._frames], dtype=float)
        cols = table.T
        return TrackFrame(
            cols[0], cols[1], cols[2], cols[3].astype(np.int64), cols[4], cols[5], cols[6] > 0.5
        )

    def _observation(self, frame: TrackFrame | None = None) -> np.ndarray:
        k = self._k0
        columns = core.observation_columns(
            self._stacked_frames() if frame is None else frame,
            self._psi_m,
            self._r_m,
            self._state[:, k.idelta],
            self._delta_c,
            self._speed,
            k,
            ARRAY,
        )
        obs = np.stack(columns, axis=1).astype(np.float32)
        np.clip(obs, OBS_LOW, OBS_HIGH, out=obs)
        if self.context_features:
            return np.concatenate([obs, self._context], axis=1)
        return obs

    def close(self, **kwargs: Any) -> None:
        return None
