"""The row machinery of the batched trial envs: N single-env episodes as the rows of arrays.

Each row runs one trial (its own :class:`~shipgym.scenarios.Scenario`, route, parameter
schedule, disturbance processes, sensors and episode generator); the plant of all rows is
one call of the ship's compiled period function (the true parameters and disturbances are
per-row inputs), reward, observation and termination are the step core's functions
(:mod:`shipgym.envs.core`) on arrays, and the path tracking is
:mod:`shipgym.envs.row_tracking`'s (one tracker per row, or one per route).  Row i's
episode is that of a :class:`~shipgym.envs.path_follow.ShipPathFollowEnv` on its trial
reset with its episode seed, bit for bit (tested).

Two envs are built on it: the training env
:class:`~shipgym.envs.ship_batch.ShipTrialsVectorEnv` (a fresh drawn trial per reset,
autoreset) and the evaluation env
:class:`~shipgym.envs.eval_trials.EvaluationTrialsVectorEnv` (given trials, one episode per
row, the single env's ``info`` per row).  Rows must share the ship (its model class and
variant) and every step constant but the time limit (:func:`shared_constants_problem`).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import VectorEnv
from gymnasium.vector.utils import batch_space

from shipgym.angles import wrap_angle
from shipgym.autopilot import PIDGains
from shipgym.disturbances import Disturbances, SensorModel
from shipgym.envs import core
from shipgym.envs.row_tracking import RouteGroups, RowTrackers
from shipgym.models.integrator import PeriodIntegrator
from shipgym.numerics import ARRAY, SCALAR
from shipgym.scenarios.loader import Scenario, nominal_nomoto
from shipgym.tracking import PathTracker, TrackFrame


@dataclasses.dataclass
class Trial:
    """One row's current trial: its scenario and the per-trial pieces of the step."""

    scenario: Scenario
    constants: core.StepConstants
    tracker: PathTracker
    disturbances: Disturbances
    sensor: SensorModel
    autopilot_gains: PIDGains | None  # guidance mode (core.guidance_command reads it)
    context_row: np.ndarray | None
    rng: np.random.Generator  # the episode's generator (disturbance and sensor noise)

    @classmethod
    def of(
        cls, sc: Scenario, episode_seed: int | None, action_mode: str, context_features: bool
    ) -> Trial:
        """The trial of scenario ``sc`` run with ``episode_seed`` (a single env's
        ``reset(seed=episode_seed)``): no integrator, no compile."""
        k = core.StepConstants.of(sc)
        gains = None
        if action_mode == "guidance":
            gains = PIDGains.from_nomoto(*nominal_nomoto(sc))
        return cls(
            scenario=sc,
            constants=k,
            tracker=PathTracker(sc.path, sc.acceptance_radius, sc.config.path.switching),
            disturbances=core.scenario_disturbances(sc),
            sensor=SensorModel(sc.config.sensors),
            autopilot_gains=gains,
            context_row=core.scenario_context_row(sc) if context_features else None,
            rng=seeding.np_random(episode_seed)[0],
        )


def shared_constants_problem(first: Scenario, other: Scenario) -> str | None:
    """Why ``other`` cannot be a row beside ``first`` (None: it can): the rows share one
    compiled period function (the model's class and variant, h, the substeps) and the step
    constants (all but the time limit)."""
    if (type(first.model), first.model.variant) != (type(other.model), other.model.variant):
        return f"ship model {other.model.name!r} differs from {first.model.name!r}"
    k0, k = core.StepConstants.of(first), core.StepConstants.of(other)
    for field in dataclasses.fields(k0):
        if field.name != "max_steps" and getattr(k, field.name) != getattr(k0, field.name):
            return f"{field.name} differs ({getattr(k, field.name)} vs {getattr(k0, field.name)})"
    return None


@dataclasses.dataclass
class Period:
    """What one control period gave the rows (arrays over all rows; rows not stepped keep
    their values; ``samples``: per stepped row its single env's ``info["samples"]`` when the
    env asks for them)."""

    frame: TrackFrame
    heading_error: np.ndarray  # true ψ − path angle [rad]
    reward: np.ndarray
    goal: np.ndarray
    corridor: np.ndarray
    diverged: np.ndarray
    truncated: np.ndarray
    samples: dict[int, dict[str, np.ndarray]]

    @property
    def terminated(self) -> np.ndarray:
        return self.goal | self.corridor | self.diverged

    def reasons(self) -> np.ndarray:
        """Each row's termination reason (None where it goes on)."""
        reasons = np.full(self.reward.shape, None, dtype=object)
        reasons[self.goal] = "goal"
        reasons[self.corridor] = "corridor"
        reasons[self.diverged] = "non_finite_state"
        reasons[self.truncated] = "time_limit"
        return reasons


class TrialRowsVectorEnv(VectorEnv):
    """N rows, one trial each, stepped in one plant call (module doc).  Subclasses choose
    the trials (:meth:`_install`) and build ``info``."""

    #: whether :meth:`_advance` records each row's ``samples`` (the single env's info key)
    record_samples = False

    def __init__(
        self,
        num_envs: int,
        first: Scenario,
        action_mode: str,
        compile: bool,
        context_features: bool,
        history_steps: int = 0,
    ) -> None:
        history_steps = core.check_history_steps(history_steps)
        # the plant on the calling thread: the row envs run inside processes that already
        # fill the cores (leaderboard workers, training jobs side by side with one torch
        # thread each), where a second thread waits for a core (≈ 2.5 ms per call instead
        # of 0.05–0.12 ms; docs/training.md "Throughput")
        self._parts = core.EnvParts.build(
            first,
            action_mode,
            compile,
            batch=num_envs,
            context_features=context_features,
            threads=1,
            history_steps=history_steps,
        )
        self.num_envs = num_envs
        self.action_mode = action_mode
        self.context_features = context_features
        #: K: the observation ends with the last K control steps (as the single env)
        self.history_steps = history_steps
        self._history = core.ObservationHistory(num_envs, history_steps) if history_steps else None
        self.render_mode = None
        self.single_observation_space = self._parts.observation_space
        self.single_action_space = self._parts.action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self._k0 = k = self._parts.constants
        self._integrator: PeriodIntegrator = self._parts.integrator
        self._w_block = self._integrator.disturbance_buffer
        self._p_block = self._integrator.parameter_buffer
        self._trials: list[Trial | None] = [None] * num_envs
        self._max_steps = np.zeros(num_envs, dtype=np.int64)
        #: the constants with each row's own time limit (max_steps, updated in place)
        self._kk = dataclasses.replace(k, max_steps=self._max_steps)
        self._p_dirty = np.zeros(num_envs, dtype=bool)
        self._event_start = np.full(num_envs, np.inf)  # first event time [s]
        self._event_end = np.full(num_envs, -np.inf)  # last event end [s]
        self._time_varying = np.zeros(num_envs, dtype=bool)
        #: per row: its disturbances settle from this period start [s] (Disturbances.steady_from)
        self._steady_from = np.full(num_envs, np.inf)
        #: rows whose block holds their settled disturbances (no refill needed)
        self._w_steady = np.zeros(num_envs, dtype=bool)
        self._state = np.zeros((num_envs, first.model.n_states))
        self._steps = np.zeros(num_envs, dtype=np.int64)
        self._t = np.zeros(num_envs)
        self._delta_c = np.zeros(num_envs)
        self._psi_m = np.zeros(num_envs)
        self._r_m = np.zeros(num_envs)
        self._speed = np.full(num_envs, k.nominal_speed)
        self._integral = np.zeros(num_envs)
        self._context = np.zeros((num_envs, self._parts.context_row.size), dtype=np.float32)
        self._noisy = np.zeros(num_envs, dtype=bool)  # rows whose sensors add noise
        #: the rows' path tracking (the subclass sets it: per row, or per route at reset)
        self._tracks: RowTrackers | RouteGroups = RowTrackers(num_envs)
        self._sample_offsets = k.fine_step * np.arange(k.substeps)

    # ------------------------------------------------------------------ rows
    def _install(self, i: int, tr: Trial) -> None:
        """Start row i's episode on trial ``tr`` (a single env's reset; the path tracking
        is the caller's: :class:`RowTrackers` or :class:`RouteGroups`)."""
        k = self._k0
        self._trials[i] = tr
        sc = tr.scenario
        x = self._state[i] = sc.initial_state()
        self._max_steps[i] = tr.constants.max_steps
        events = sc.schedule.events
        self._event_start[i] = min((e.time for e in events), default=np.inf)
        self._event_end[i] = max((e.end_time() for e in events), default=-np.inf)
        self._p_dirty[i] = False
        self._time_varying[i] = tr.disturbances.time_varying
        self._steady_from[i] = tr.disturbances.steady_from
        self._w_steady[i] = False
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
        self._noisy[i] = not tr.sensor.ideal
        if self.context_features:
            self._context[i] = tr.context_row
        if self._history is not None:
            self._history.restart(i)

    def _advance(self, a: np.ndarray, live: np.ndarray) -> Period:
        """One control period of the ``live`` rows with actions ``a`` (n_envs, n_act),
        checked and clipped (:func:`core.batch_actions`); the other rows keep their state.

        While every row steps (and every plant state stays finite), the masked selections
        (``np.where(live, new, old)``) are skipped: they would return ``new`` (the
        step's fixed cost is its ≈ 100 numpy calls)."""
        k = self._k0
        trials: list[Trial] = self._trials  # type: ignore[assignment]
        tracks = self._tracks
        every = bool(live.all())
        if self.action_mode == "rudder":
            delta_c = a[:, 0] * k.rudder_limit
        else:
            delta_c = self._delta_c.copy()
            for i in live.nonzero()[0].tolist():
                delta_c[i], self._integral[i] = core.guidance_command(
                    a[i, 0],
                    a[i, 1],
                    tracks.row_frame(i),
                    self._psi_m[i],
                    self._r_m[i],
                    self._integral[i],
                    trials[i],
                    SCALAR,
                )
        if not every:
            delta_c = np.where(live, delta_c, self._delta_c)
        # the arrays below are replaced, never written in place, during a period
        prev_delta_c = self._delta_c
        t0 = self._t
        # true parameters of the period: only for rows whose event acts on it (or just did)
        t1 = t0 + k.control_period
        changing = (self._event_end >= t0 - 1e-9) & (self._event_start <= t1 + 1e-9)
        for i in ((changing | self._p_dirty) & live).nonzero()[0].tolist():
            tr = trials[i]
            self._p_dirty[i] = core.refresh_parameters(
                tr.scenario.schedule,
                float(t0[i]),
                tr.constants,
                self._p_block[i],
                bool(self._p_dirty[i]),
            )
        # disturbances: a settled block (filled at a start ≥ steady_from) is not refilled
        for i in (live & self._time_varying & ~self._w_steady).nonzero()[0].tolist():
            trials[i].disturbances.fill_one(self._w_block[i], float(t0[i]), trials[i].rng)
            self._w_steady[i] = t0[i] >= self._steady_from[i]
        x_start = self._state
        traj = self._integrator.substep_states(x_start, delta_c, self._w_block, self._p_block)
        last = traj[:, -1]
        finite = np.isfinite(last).all(axis=1)
        moved = every and bool(finite.all())  # every row advances
        if self._history is not None:
            self._history.stepped(live)
        steps = self._steps + 1
        if every:
            self._t = steps * k.control_period
        else:
            steps = np.where(live, steps, self._steps)
            self._t = np.where(live, steps * k.control_period, self._t)
        advance = live if moved else live & finite
        self._steps = steps
        self._delta_c = delta_c
        self._state = last.copy() if moved else np.where(advance[:, None], last, self._state)
        if k.substeps > 1:
            dx = last[:, k.ix] - traj[:, -2, k.ix]
            dy = last[:, k.iy] - traj[:, -2, k.iy]
            speed = core.speed_over_ground(dx, dy, k, ARRAY)
            self._speed = speed if moved else np.where(advance, speed, self._speed)
        psi_m0, r_m0 = self._psi_m, self._r_m
        if moved:
            psi_m, r_m = last[:, k.ipsi].copy(), last[:, k.ir].copy()
        else:
            psi_m = np.where(advance, last[:, k.ipsi], self._psi_m)
            r_m = np.where(advance, last[:, k.ir], self._r_m)
        samples: dict[int, dict[str, np.ndarray]] = {}
        if self.record_samples:  # every row's at once: views into fresh (N, n_sub) arrays
            start = np.concatenate((x_start[:, None], traj[:, :-1]), axis=1)
            # at the substep starts, before the tracker moves on
            e_s = tracks.cross_track_of(start[:, :, k.ix], start[:, :, k.iy])
            measured_psi, measured_r = traj[:, :, k.ipsi].copy(), traj[:, :, k.ir].copy()
            psi_s = np.concatenate((psi_m0[:, None], measured_psi[:, :-1]), axis=1)
            r_s = np.concatenate((r_m0[:, None], measured_r[:, :-1]), axis=1)
            t_s = t0[:, None] + self._sample_offsets
            delta_s = start[:, :, k.idelta]
            delta_c_s = np.repeat(delta_c[:, None], k.substeps, axis=1)
        for i in (advance & self._noisy).nonzero()[0].tolist():
            tr = trials[i]
            p_i, r_i = tr.sensor.measure(traj[i, :, k.ipsi], traj[i, :, k.ir], tr.rng)
            psi_m[i], r_m[i] = p_i[-1], r_i[-1]
            if self.record_samples:
                psi_s[i, 1:], r_s[i, 1:] = p_i[:-1], r_i[:-1]
        if self.record_samples:
            for i in advance.nonzero()[0].tolist():
                samples[i] = {
                    "t": t_s[i],
                    "psi": psi_s[i],
                    "r": r_s[i],
                    "delta": delta_s[i],
                    "delta_c": delta_c_s[i],
                    "e": e_s[i],
                }
        tracks.update(self._state[:, k.ix], self._state[:, k.iy], advance)
        self._psi_m, self._r_m = psi_m, r_m
        frame = tracks.frame
        heading_error = wrap_angle(self._state[:, k.ipsi] - frame.path_angle)
        reward = core.step_reward(frame.cross_track, heading_error, delta_c, prev_delta_c, k, ARRAY)
        kk = self._kk  # the constants with each row's own max_steps
        reward, goal, corridor, truncated = core.terminate(reward, frame, steps, kk, ARRAY)
        if moved:
            return Period(frame, heading_error, reward, goal, corridor, ~live, truncated, samples)
        diverged = live & ~finite
        reward = np.where(diverged, core.diverged_reward(steps, kk), reward)
        return Period(
            frame=frame,
            heading_error=heading_error,
            reward=np.where(live, reward, 0.0),
            goal=goal & advance,
            corridor=corridor & advance,
            diverged=diverged,
            truncated=truncated & advance,
            samples=samples,
        )

    def _observation(self, frame: TrackFrame | None = None) -> np.ndarray:
        k = self._k0
        obs = core.batch_observation(
            self._tracks.frame if frame is None else frame,
            self._psi_m,
            self._r_m,
            self._state[:, k.idelta],
            self._delta_c,
            self._speed,
            k,
            self._context if self.context_features else None,
        )
        return obs if self._history is None else self._history.append(obs)

    def close(self, **kwargs: Any) -> None:
        return None
