"""The row machinery of the batched trial envs: N single-env episodes as the rows of arrays.

Each row runs one trial (its own :class:`~shipgym.scenarios.loader.Scenario`, route, parameter
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
        self.history_steps = k_history = self._parts.history_steps
        self._history = core.ObservationHistory(num_envs, k_history) if k_history else None
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
        self._state = core.EnvState.rows(num_envs, first.model.n_states, k.nominal_speed)
        self._context = np.zeros((num_envs, self._parts.context_row.size), dtype=np.float32)
        self._noisy = np.zeros(num_envs, dtype=bool)  # rows whose sensors add noise
        #: the rows' path tracking (the subclass sets it: per row, or per route at reset)
        self._tracks: RowTrackers | RouteGroups = RowTrackers(num_envs)
        self._sample_offsets = k.fine_step * np.arange(k.substeps)
        #: per row stepped in the last period: its single env's ``info["samples"]`` (when
        #: :attr:`record_samples`)
        self._samples: dict[int, dict[str, np.ndarray]] = {}

    # ------------------------------------------------------------------ rows
    def _install(self, i: int, tr: Trial) -> None:
        """Start row i's episode on trial ``tr`` (a single env's reset; the path tracking
        is the caller's: :class:`RowTrackers` or :class:`RouteGroups`)."""
        k, s = self._k0, self._state
        self._trials[i] = tr
        sc = tr.scenario
        x = s.x[i] = sc.initial_state()
        self._max_steps[i] = tr.constants.max_steps
        events = sc.schedule.events
        self._event_start[i] = min((e.time for e in events), default=np.inf)
        self._event_end[i] = max((e.end_time() for e in events), default=-np.inf)
        self._p_dirty[i] = False
        self._time_varying[i] = tr.disturbances.time_varying
        self._steady_from[i] = tr.disturbances.steady_from
        self._w_steady[i] = False
        s.steps[i] = 0
        s.t[i] = 0.0
        s.delta_c[i] = 0.0
        s.integral[i] = 0.0
        s.speed[i] = tr.constants.nominal_speed
        self._p_block[i] = sc.schedule.vector_at(0.0)
        self._w_block[i] = tr.disturbances.constant_row()
        tr.disturbances.reset(0, tr.rng)  # before the sensor's draws (as the single env)
        tr.sensor.reset()
        psi_m, r_m = tr.sensor.measure(x[k.ipsi : k.ipsi + 1], x[k.ir : k.ir + 1], tr.rng)
        s.psi_m[i], s.r_m[i] = float(psi_m[0]), float(r_m[0])
        self._noisy[i] = not tr.sensor.ideal
        if self.context_features:
            self._context[i] = tr.context_row
        if self._history is not None:
            self._history.restart(i)

    def _advance(self, a: np.ndarray, live: np.ndarray) -> core.Period:
        """One control period (:func:`core.transition`) of the ``live`` rows with actions
        ``a`` (n_envs, n_act), checked and clipped (:func:`core.batch_actions`); the other
        rows keep their state.  Each row ends at its own time limit."""
        self._samples = {}
        kk = self._kk  # the constants with each row's own max_steps
        self._state, period = core.transition(
            self._state, a, live, kk, ARRAY, self._command, self._plant, self._measure, self._tracks
        )
        if self._history is not None:
            self._history.stepped(live)
        return period

    def _command(
        self, a: np.ndarray, s: core.EnvState, live: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The period's rudder commands [rad] and PID integrals (core.transition's
        command); in guidance mode per row, with its trial's law and gains."""
        if self.action_mode == "rudder":
            return core.rudder_command(a, s, self._tracks.frame, self._parts, ARRAY)
        trials: list[Trial] = self._trials  # type: ignore[assignment]
        delta_c, integral = s.delta_c.copy(), s.integral.copy()
        for i in live.nonzero()[0].tolist():
            delta_c[i], integral[i] = core.guidance_command(
                a[i, 0],
                a[i, 1],
                self._tracks.row_frame(i),
                s.psi_m[i],
                s.r_m[i],
                s.integral[i],
                trials[i],
                SCALAR,
            )
        return delta_c, integral

    def _plant(self, s: core.EnvState, delta_c: np.ndarray, live: np.ndarray) -> np.ndarray:
        """The period's true parameters and disturbances of the ``live`` rows, then the
        plant of all: the integrator's (N, n_sub, n_x) buffer (core.transition's plant)."""
        trials: list[Trial] = self._trials  # type: ignore[assignment]
        t0 = s.t
        # true parameters of the period: only for rows whose event acts on it (or just did)
        t1 = t0 + self._k0.control_period
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
        return self._integrator.substep_states(s.x, delta_c, self._w_block, self._p_block)

    def _measure(
        self, trajectory: np.ndarray, s: core.EnvState, new: core.EnvState, advance: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Noisy sensors of the ``advance`` rows, each with its trial's generator
        (core.transition's measure); with :attr:`record_samples` each such row's single env
        ``info["samples"]`` (every row's at once: views into fresh (N, n_sub) arrays)."""
        k = self._k0
        record = self.record_samples
        if record:
            start = np.concatenate((s.x[:, None], trajectory[:, :-1]), axis=1)
            # at the substep starts, before the tracker moves on
            e_s = self._tracks.cross_track_of(start[:, :, k.ix], start[:, :, k.iy])
            psi_s = np.concatenate((s.psi_m[:, None], trajectory[:, :-1, k.ipsi]), axis=1)
            r_s = np.concatenate((s.r_m[:, None], trajectory[:, :-1, k.ir]), axis=1)
        psi, r = new.psi_m, new.r_m
        noisy = (advance & self._noisy).nonzero()[0].tolist()
        if noisy:
            psi, r = psi.copy(), r.copy()
        for i in noisy:
            tr = self._trials[i]
            p_i, r_i = tr.sensor.measure(trajectory[i, :, k.ipsi], trajectory[i, :, k.ir], tr.rng)
            psi[i], r[i] = p_i[-1], r_i[-1]
            if record:
                psi_s[i, 1:], r_s[i, 1:] = p_i[:-1], r_i[:-1]
        if record:
            t_s = s.t[:, None] + self._sample_offsets
            delta_c_s = np.repeat(new.delta_c[:, None], k.substeps, axis=1)
            for i in advance.nonzero()[0].tolist():
                self._samples[i] = {
                    "t": t_s[i],
                    "psi": psi_s[i],
                    "r": r_s[i],
                    "delta": start[i, :, k.idelta],
                    "delta_c": delta_c_s[i],
                    "e": e_s[i],
                }
        return psi, r

    def _observation(self, frame: TrackFrame | None = None) -> np.ndarray:
        k, s = self._k0, self._state
        obs = core.batch_observation(
            self._tracks.frame if frame is None else frame,
            s.psi_m,
            s.r_m,
            s.x[:, k.idelta],
            s.delta_c,
            s.speed,
            k,
            self._context if self.context_features else None,
        )
        return obs if self._history is None else self._history.append(obs)

    def close(self, **kwargs: Any) -> None:
        return None
