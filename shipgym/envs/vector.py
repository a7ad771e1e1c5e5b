"""Batched ShipPathFollow: N ships stepped in one call.

Built from a scenario, like the single env (:class:`shipgym.envs.core.EnvParts`).  The plant
of all N ships is one call of the compiled CasADi period function mapped over the ships (the
single env's function, so the physics is bit-identical); tracking (polylines and PCHIP
curves), every guidance law, the autopilot, reward, observation, termination and info are
the step core's functions (:mod:`shipgym.envs.core`) evaluated on arrays, the same code the
single env runs on floats, so that ``ShipPathFollowVectorEnv(N)`` equals N single envs
under ``SyncVectorEnv`` bit for bit, in both action modes and on both path types (tested).

Python loops over ships remain only where randomness must be drawn per env in the single
env's order (noisy sensors, the noise of stochastic disturbances, whose processes then
advance over all ships at once), for the rare parameter-event periods, and for the metrics
of finished episodes.

Autoreset follows Gymnasium's default NEXT_STEP mode (``reset(options={"reset_mask": m})``
resets only the masked envs).  ``info`` holds the scalar keys of the single env as arrays,
in SyncVectorEnv's layout (``episode_metrics`` as a dict of arrays with ``_``-masks, present
at the steps where an episode ended, with SyncVectorEnv's dtypes), except: ``position`` is
an (N, 2) float array, there is no ``samples`` (online identification runs on the single
env).  With ``randomize=True`` (the registered ids' default) each env's reset draws its trial
from its own generator as the single env does (:attr:`trials`: the scenarios of the
episodes; a per-env copy of the disturbance processes then carries each trial's current).
It is what
``gym.make_vec("ShipPathFollow-v0", num_envs=N)`` returns by default (Gymnasium prefers a
registered vector entry point); pass ``vectorization_mode="sync"`` for N single envs.
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from shipgym.disturbances import Disturbances, SensorModel
from shipgym.envs import core
from shipgym.envs.core import LOG_FIELDS
from shipgym.metrics import compute_metrics
from shipgym.numerics import ARRAY
from shipgym.scenarios.events import EVENT_TIME_EPS as _EVENT_EPS
from shipgym.scenarios.loader import Scenario, load_scenario
from shipgym.scenarios.trials import apply_trial, draw_trial, env_randomization


class ShipPathFollowVectorEnv(VectorEnv):
    """N copies of ``ShipPathFollow`` on one scenario, stepped together (module doc)."""

    metadata: ClassVar[dict[str, Any]] = {
        "autoreset_mode": AutoresetMode.NEXT_STEP,
        "render_modes": [],
    }

    def __init__(
        self,
        num_envs: int,
        scenario: Any = "rudder_aging",
        action_mode: str = "rudder",
        compile: bool = True,
        render_mode: str | None = None,
        episode_metrics: bool = True,
        max_episode_steps: int | None = None,
        context_features: bool = False,
        history_steps: int = 0,
        randomize: bool = False,
    ) -> None:
        if not isinstance(randomize, bool):
            raise ValueError(f"randomize must be True or False, got {randomize!r}")
        if num_envs < 1:
            raise ValueError(f"num_envs must be ≥ 1, got {num_envs}")
        if max_episode_steps is not None and not (
            isinstance(max_episode_steps, int) and max_episode_steps >= 1
        ):
            raise ValueError(f"max_episode_steps must be an int ≥ 1, got {max_episode_steps!r}")
        if render_mode is not None:
            raise ValueError("the batched env does not render; use a single env for that")
        sc = load_scenario(scenario)
        parts = core.EnvParts.build(
            sc,
            action_mode,
            compile,
            batch=num_envs,
            context_features=context_features,
            history_steps=history_steps,
        )
        self._parts = parts
        #: the observation ends with the controller-context features (as the single env)
        self.context_features = context_features
        #: K: then the last K control steps (as the single env)
        self.history_steps = k = parts.history_steps
        self._history = core.ObservationHistory(num_envs, k) if k else None
        self.num_envs = num_envs
        #: the scenario as given (with ``randomize`` each env's reset draws a trial of it)
        self.scenario = sc
        #: draw a trial of ``scenario`` at every env's reset, from its generator (as the
        #: single env: the default suite's ranges)
        self.randomize = randomize
        self._randomization = env_randomization() if randomize else None
        #: each env's scenario this episode (``scenario`` itself without ``randomize``)
        self.trials: list[Scenario] = [sc] * num_envs
        self.action_mode = action_mode
        self.render_mode = None
        #: compute info["episode_metrics"] for finished envs (≈ 0.2 ms each; training loops
        #: that do not read them switch it off)
        self.episode_metrics = episode_metrics
        self.single_observation_space = parts.observation_space
        self.single_action_space = parts.action_space
        self.observation_space = batch_space(parts.observation_space, num_envs)
        self.action_space = batch_space(parts.action_space, num_envs)
        self._k = k = parts.constants
        #: truncation after this many steps (``gym.make_vec(..., max_episode_steps=M)``, as
        #: the TimeLimit wrapper of single envs; the corridor penalty keeps the scenario's
        #: time limit, as under that wrapper)
        self.max_episode_steps = k.max_steps if max_episode_steps is None else max_episode_steps
        self._tracker = parts.tracker
        self._integrator = parts.integrator
        self._disturbances = parts.disturbances
        #: with ``randomize``: each env's own processes (its trial's current), else None
        self._row_disturbances: list[Disturbances] | None = None
        if randomize:
            self._row_disturbances = [parts.disturbances] * num_envs  # replaced at reset
        self._event_start, self._event_end = _event_bounds([sc] * num_envs)
        self._w_block = self._integrator.disturbance_buffer  # filled in place, never copied
        self._w_block[:] = self._disturbances.constant_row()
        self._p_block = self._integrator.parameter_buffer
        self._p_dirty = np.zeros(num_envs, dtype=bool)
        self._sensors = [SensorModel(sc.config.sensors) for _ in range(num_envs)]
        self._ideal = self._sensors[0].ideal
        self._rngs: list[np.random.Generator | None] = [None] * num_envs
        self._state = core.EnvState.rows(num_envs, sc.model.n_states)
        self._autoreset = np.zeros(num_envs, dtype=bool)
        self._log = np.zeros(
            (len(LOG_FIELDS), num_envs, min(k.max_steps, self.max_episode_steps) + 1)
        )
        self._started = False

    # ------------------------------------------------------------------ gym vector API
    def reset(
        self, *, seed: int | list[int | None] | None = None, options: dict | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        mask = core.reseed_rows(self._rngs, seed, options)
        self._reset_envs(mask)
        self._autoreset[mask] = False
        self._started = True
        return self._observation(), self._info()

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if not self._started:
            raise RuntimeError("call reset() before step()")
        a = core.batch_actions(actions, self.action_space.shape)
        k = self._k
        resetting = self._autoreset.copy()
        live = ~resetting  # envs being autoreset ignore their action
        if np.any(resetting):
            self._reset_envs(resetting)
        self._state, period = core.transition(
            self._state, a, live, k, ARRAY, self._command, self._plant, self._measure, self._tracker
        )
        if self._history is not None:
            self._history.stepped(live)
        s = self._state
        if self.max_episode_steps < k.max_steps:  # as a TimeLimit wrapper of single envs
            time_up = live & ~period.terminated & (s.steps >= self.max_episode_steps)
            period.truncated = period.truncated | time_up
        # --- episode log (true values), one column per control step
        rows = np.flatnonzero(live)
        col = s.steps[rows] - 1
        e, heading_error = period.frame.cross_track, period.heading_error
        for j, values in enumerate(
            (s.t, e, heading_error, s.x[:, k.idelta], s.delta_c, period.reward)
        ):
            self._log[j, rows, col] = values[rows]
        terminated, truncated = period.terminated, period.truncated
        done = terminated | truncated
        info = self._info()
        if np.any(done):
            info["termination_reason"] = period.reasons()
            info["_termination_reason"] = done
            if self.episode_metrics:
                info["episode_metrics"] = self._stacked_metrics(done, period.goal)
                info["_episode_metrics"] = done
        self._autoreset = done
        return self._observation(), period.reward, terminated, truncated, info

    def reset_finished(self) -> tuple[np.ndarray, np.ndarray]:
        """Reset now the envs whose episode ended at the last step (instead of at the next
        step); returns (observations of all envs, mask of the envs reset).  For adapters to
        same-step autoreset frameworks such as stable-baselines3."""
        mask = self._autoreset.copy()
        if np.any(mask):
            self._reset_envs(mask)
            self._autoreset[:] = False
        return self._observation(), mask

    # ------------------------------------------------------------------ pieces
    def _reset_envs(self, mask: np.ndarray) -> None:
        sc, k, s = self.scenario, self._k, self._state
        if self._randomization is None:
            s.x[mask] = sc.initial_state()
            self._p_block[mask] = sc.schedule.vector_at(0.0)
        else:
            for i in np.flatnonzero(mask).tolist():
                self._install_trial(i)
        s.steps[mask] = 0
        s.t[mask] = 0.0
        s.delta_c[mask] = 0.0
        s.integral[mask] = 0.0
        self._p_dirty[mask] = False
        s.speed[mask] = k.nominal_speed
        self._log[:, mask] = 0.0
        if self._history is not None:
            self._history.restart(mask)
        for i in np.flatnonzero(mask):
            sensor = self._sensors[i]
            if self._row_disturbances is None:
                self._disturbances.reset(i, self._rngs[i])  # before the sensor's draws
            else:
                self._row_disturbances[i].reset(0, self._rngs[i])
            sensor.reset()
            x = s.x[i]
            if self._ideal:
                s.psi_m[i], s.r_m[i] = x[k.ipsi], x[k.ir]
            else:
                p_i, r_i = sensor.measure(x[k.ipsi : k.ipsi + 1], x[k.ir : k.ir + 1], self._rngs[i])
                s.psi_m[i], s.r_m[i] = p_i[0], r_i[0]
        self._tracker.reset(s.x[:, k.ix], s.x[:, k.iy], mask)

    def _install_trial(self, i: int) -> None:
        """Env i's next trial, drawn from its generator (the single env's reset): its
        scenario, start, parameters, event times and current."""
        rng = self._rngs[i]
        trial = apply_trial(self.scenario, draw_trial(self._randomization, rng))
        self.trials[i] = trial
        self._state.x[i] = trial.initial_state()
        self._p_block[i] = trial.schedule.vector_at(0.0)
        start, end = _event_bounds([trial])
        self._event_start[i], self._event_end[i] = start[0], end[0]
        dist = self._row_disturbances[i] = core.scenario_disturbances(trial)
        self._w_block[i] = dist.constant_row()

    def _command(
        self, a: np.ndarray, s: core.EnvState, live: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The period's rudder commands [rad] and PID integrals (core.transition's command)."""
        return core.rudder_command(a, s, self._tracker.frame, self._parts, ARRAY)

    def _plant(self, s: core.EnvState, delta_c: np.ndarray, live: np.ndarray) -> np.ndarray:
        """The period's true parameters and disturbances of the ``live`` envs, then the
        plant of all: the integrator's (N, n_sub, n_x) buffer (core.transition's plant)."""
        t0 = s.t
        self._refresh_parameters(t0, live)
        # disturbances: noise per env (its generator, the single env's order), the
        # processes over all advancing ships at once
        if self._disturbances.time_varying and np.any(live):
            rows = np.flatnonzero(live)
            if self._row_disturbances is not None:  # each env's trial has its own current
                for i in rows.tolist():
                    self._row_disturbances[i].fill_one(
                        self._w_block[i], float(t0[i]), self._rngs[i]
                    )
            else:
                dist = self._disturbances
                noise = [dist.draw(self._rngs[i]) for i in rows] if dist.n_noise else None
                dist.fill(self._w_block, t0[rows], None if noise is None else np.stack(noise), rows)
        return self._integrator.substep_states(s.x, delta_c, self._w_block, self._p_block)

    def _measure(
        self, trajectory: np.ndarray, s: core.EnvState, new: core.EnvState, advance: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Noisy sensors of the ``advance`` envs, each with its generator in the single
        env's order (core.transition's measure)."""
        if self._ideal:
            return new.psi_m, new.r_m
        k = self._k
        psi, r = new.psi_m.copy(), new.r_m.copy()
        for i in np.flatnonzero(advance):
            p_i, r_i = self._sensors[i].measure(
                trajectory[i, :, k.ipsi], trajectory[i, :, k.ir], self._rngs[i]
            )
            psi[i], r[i] = p_i[-1], r_i[-1]
        return psi, r

    def _refresh_parameters(self, t0: np.ndarray, live: np.ndarray) -> None:
        """Parameter rows of the period [t0, t0 + Ts] per env (core.refresh_parameters);
        an env's events act on it when one starts or ramps within it (as
        ParameterSchedule.changing_on, with each env's event times)."""
        if not self._event_start.shape[1]:
            return
        t1 = t0 + self._k.control_period
        changing = np.any(
            (self._event_end >= (t0 - _EVENT_EPS)[:, None])
            & (self._event_start <= (t1 + _EVENT_EPS)[:, None]),
            axis=1,
        )
        for i in np.flatnonzero(live & (changing | self._p_dirty)):
            self._p_dirty[i] = core.refresh_parameters(
                self.trials[i].schedule,
                float(t0[i]),
                self._k,
                self._p_block[i],
                bool(self._p_dirty[i]),
            )

    def _observation(self) -> np.ndarray:
        k, s = self._k, self._state
        obs = core.batch_observation(
            self._tracker.frame,
            s.psi_m,
            s.r_m,
            s.x[:, k.idelta],
            s.delta_c,
            s.speed,
            k,
            self._parts.context_row if self.context_features else None,
        )
        return obs if self._history is None else self._history.append(obs)

    def _info(self) -> dict[str, Any]:
        k, s = self._k, self._state
        values = core.info_values(
            s.t,
            self._tracker.frame,
            s.psi_m,
            s.r_m,
            s.x[:, k.idelta],
            s.delta_c,
            s.x[:, [k.ix, k.iy]],
        )
        info: dict[str, Any] = {}
        every = np.ones(self.num_envs, dtype=bool)
        for key, value in values.items():
            info[key] = np.array(value, copy=True)
            info[f"_{key}"] = every.copy()
        return info

    def _stacked_metrics(self, done: np.ndarray, goal: np.ndarray) -> dict[str, Any]:
        """Metrics of the finished envs in SyncVectorEnv's layout and dtypes (key → (N,)
        array with a ``_key`` mask), by Gymnasium's own ``VectorEnv._add_info``."""
        stacked: dict[str, Any] = {}
        for i in np.flatnonzero(done):
            stacked = self._add_info(stacked, self._episode_metrics(int(i), bool(goal[i])), int(i))
        return stacked

    def _episode_metrics(self, i: int, reached: bool) -> dict[str, Any]:
        n = int(self._state.steps[i])
        columns = {name: self._log[j, i, :n].copy() for j, name in enumerate(LOG_FIELDS)}
        log = core.episode_log(columns, self.trials[i], reached)
        return compute_metrics(log, self._parts.metric_settings)


def _event_bounds(scenarios: list[Scenario]) -> tuple[np.ndarray, np.ndarray]:
    """(start, end) times [s] of each scenario's events, (n, n_events) arrays (the
    scenarios are trials of one scenario: as many events each)."""
    start = np.array([[e.time for e in sc.schedule.events] for sc in scenarios])
    end = np.array([[e.end_time() for e in sc.schedule.events] for sc in scenarios])
    n = len(scenarios[0].schedule.events)
    return start.reshape(len(scenarios), n), end.reshape(len(scenarios), n)
