"""Batched ShipPathFollow: N ships stepped in one call (SPEC §5 "Batched simulation").

The plant of all N ships is one call of the compiled CasADi period function mapped over the
ships (the single env's function, so the physics is bit-identical); guidance, reward,
observation and termination are numpy expressions over the N ships written with the same
operations as the single env (no ``hypot``/``arctan2`` whose SIMD versions differ from libm
in the last bit), so that ``ShipPathFollowVectorEnv(N)`` equals N single envs under
``SyncVectorEnv`` bit for bit in rudder mode (tested).  Python loops over ships remain only
where randomness must be drawn per env in the single env's order (noisy sensors, the noise
of stochastic disturbances, whose processes then advance over all ships at once), for the
rare parameter-event periods, and for the metrics of finished episodes.

Autoreset follows Gymnasium's default NEXT_STEP mode (``reset(options={"reset_mask": m})``
resets only the masked envs).  ``info`` holds the scalar keys of the single env as arrays,
in SyncVectorEnv's layout (``episode_metrics`` as a dict of arrays with ``_``-masks, present
at the steps where an episode ended), except: ``position`` is an (N, 2) float array, there
is no ``samples`` (online identification runs on the single env), and the episode metrics'
``compute_ms_*`` are NaN (no per-env controller timing in a batch).  It is what
``gym.make_vec("ShipPathFollow-v0", num_envs=N)`` returns by default (Gymnasium prefers a
registered vector entry point); pass ``vectorization_mode="sync"`` for N single envs.
Waypoint (polyline) paths only; a PCHIP scenario raises ValueError (use ``SyncVectorEnv`` /
``SubprocVecEnv`` over single envs there).
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from shipgym.disturbances import Disturbances, SensorModel
from shipgym.envs.path_follow import GUIDANCE_OFFSET_MAX, ShipPathFollowEnv, field_law_heading
from shipgym.metrics import ARRAY_FIELDS, EpisodeLog, compute_metrics

_PI = math.pi
_TWO_PI = 2.0 * math.pi


def _wrap(a: np.ndarray) -> np.ndarray:
    """shipgym.paths.wrap_angle for arrays (same operations as its float branch)."""
    w = np.mod(a + _PI, _TWO_PI) - _PI
    return np.where(w >= _PI, w - _TWO_PI, w)


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
    ) -> None:
        if num_envs < 1:
            raise ValueError(f"num_envs must be ≥ 1, got {num_envs}")
        if render_mode is not None:
            raise ValueError("the batched env does not render; use a single env for that")
        # one single env supplies the validated scenario, spaces and constants
        proto = ShipPathFollowEnv(scenario, action_mode, compile=compile)
        sc = proto.scenario
        if sc.config.path.type != "waypoints":
            raise ValueError(
                f"scenario {sc.name!r}: the batched env supports waypoint paths only "
                f"(got {sc.config.path.type!r}); use SyncVectorEnv over single envs"
            )
        self.num_envs = num_envs
        self.scenario = sc
        self.action_mode = action_mode
        self.render_mode = None
        #: compute info["episode_metrics"] for finished envs (≈ 0.2 ms each; training loops
        #: that do not read them switch it off)
        self.episode_metrics = episode_metrics
        self.single_observation_space = proto.observation_space
        self.single_action_space = proto.action_space
        self.observation_space = batch_space(proto.observation_space, num_envs)
        self.action_space = batch_space(proto.action_space, num_envs)
        self._proto = proto
        self._n = proto._n
        self._h, self._Ts = proto._h, proto._Ts
        self._L, self._u0, self._dmax = proto._L, proto._u0, proto._dmax
        self._e_max = proto._e_max
        self._max_steps = proto._max_steps
        self._idx = (proto._ix, proto._iy, proto._ipsi, proto._ir, proto._idelta)
        self._obs_low, self._obs_high = proto.observation_space.low, proto.observation_space.high
        # per-leg constants, computed exactly as shipgym.paths.segment_frame does
        wp = [(float(p[0]), float(p[1])) for p in sc.path.waypoints]
        legs = range(len(wp) - 1)
        lengths = [math.hypot(wp[i + 1][0] - wp[i][0], wp[i + 1][1] - wp[i][1]) for i in legs]
        self._leg_x0 = np.array([wp[i][0] for i in legs])
        self._leg_y0 = np.array([wp[i][1] for i in legs])
        self._leg_x1 = np.array([wp[i + 1][0] for i in legs])
        self._leg_y1 = np.array([wp[i + 1][1] for i in legs])
        self._leg_c = np.array([(wp[i + 1][0] - wp[i][0]) / lengths[i] for i in legs])
        self._leg_s = np.array([(wp[i + 1][1] - wp[i][1]) / lengths[i] for i in legs])
        self._leg_len = np.array(lengths)
        self._leg_angle = np.array(
            [math.atan2(wp[i + 1][1] - wp[i][1], wp[i + 1][0] - wp[i][0]) for i in legs]
        )
        self._leg_change = np.array([sc.path.next_leg_angle_change(i) for i in legs])
        self._last_leg = len(wp) - 2
        self._goal = wp[-1]
        self._radius = sc.acceptance_radius
        self._switching = sc.config.path.switching
        # plant, parameters, disturbances
        self._integrator = proto._integrator.__class__(
            proto.model, self._h, self._n, compile=compile, batch=num_envs
        )
        self._w_block = self._integrator.disturbance_buffer  # filled in place, never copied
        self._w_block[:] = proto._w_block
        self._disturbances = Disturbances(
            sc.config.disturbances,
            proto.model.disturbance_names,
            self._h,
            self._n,
            batch=num_envs,
            time_limit=sc.config.time_limit,
        )
        self._p_block = self._integrator.parameter_buffer
        self._p_dirty = np.zeros(num_envs, dtype=bool)
        self._sensors = [SensorModel(sc.config.sensors) for _ in range(num_envs)]
        self._ideal = self._sensors[0].ideal
        self._rngs: list[np.random.Generator | None] = [None] * num_envs
        if action_mode == "guidance":
            g = proto._autopilot.gains
            self._kp, self._ki, self._kd = g.kp, g.ki, g.kd
            self._gcfg = sc.config.guidance
        w = sc.config.reward
        self._w_psi, self._w_delta = w.heading_weight, w.rudder_weight
        self._w_rate, self._goal_bonus = w.rudder_rate_weight, w.goal_bonus
        self._metric_settings = proto._metric_settings
        # state
        n_x = proto.model.n_states
        self._state = np.zeros((num_envs, n_x))
        self._steps = np.zeros(num_envs, dtype=np.int64)
        self._t = np.zeros(num_envs)
        self._delta_c = np.zeros(num_envs)
        self._psi_m = np.zeros(num_envs)
        self._r_m = np.zeros(num_envs)
        self._speed = np.zeros(num_envs)
        self._leg = np.zeros(num_envs, dtype=np.int64)
        self._integral = np.zeros(num_envs)
        self._autoreset = np.zeros(num_envs, dtype=bool)
        self._log = np.zeros((len(ARRAY_FIELDS), num_envs, self._max_steps + 1))
        self._frame: dict[str, np.ndarray] = {}
        self._started = False

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
        if options and "reset_mask" in options:  # as SyncVectorEnv: reset only these envs
            mask = np.asarray(options["reset_mask"], dtype=bool)
            if mask.shape != (self.num_envs,):
                raise ValueError(f"reset_mask must have shape ({self.num_envs},)")
        for i, s in enumerate(seeds):
            if mask[i] and (s is not None or self._rngs[i] is None):
                self._rngs[i], _ = seeding.np_random(s)
        self._reset_envs(mask)
        self._autoreset[mask] = False
        self._started = True
        return self._observation(), self._info(np.ones(self.num_envs, dtype=bool))

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if not self._started:
            raise RuntimeError("call reset() before step()")
        a = np.asarray(actions, dtype=np.float64).reshape(self.action_space.shape)
        bad = ~np.all(np.isfinite(a), axis=1)
        if np.any(bad):
            raise ValueError(
                f"actions of envs {np.flatnonzero(bad).tolist()} contain NaN or inf; "
                "the env state is unchanged"
            )
        a = np.clip(a, -1.0, 1.0)
        n = self.num_envs
        reasons = np.full(n, None, dtype=object)
        resetting = self._autoreset.copy()
        live = ~resetting
        if np.any(resetting):
            self._reset_envs(resetting)
        # --- action -> rudder command
        if self.action_mode == "rudder":
            delta_c = a[:, 0] * self._dmax
        else:
            delta_c = self._autopilot(a, live)
        delta_c = np.where(live, delta_c, self._delta_c)
        prev_delta_c = self._delta_c.copy()
        # --- true parameters of the period (per env: times differ after resets)
        t0 = self._t.copy()
        self._refresh_parameters(t0, live)
        # --- disturbances of the period: noise per env (its generator, the single env's
        # order), the processes over all advancing ships at once
        if self._disturbances.time_varying and np.any(live):
            rows = np.flatnonzero(live)
            dist = self._disturbances
            noise = [dist.draw(self._rngs[i]) for i in rows] if dist.n_noise else None
            dist.fill(self._w_block, t0[rows], None if noise is None else np.stack(noise), rows)
        # --- plant: one call for all ships
        # states at t0 + h … t0 + Ts (the integrator's buffer, valid until the next step)
        traj = self._integrator.substep_states(self._state, delta_c, self._w_block, self._p_block)
        steps = np.where(live, self._steps + 1, self._steps)
        finite = np.all(np.isfinite(traj[:, -1]), axis=1)
        advance = live & finite
        self._steps = steps
        self._t = np.where(live, steps * self._Ts, self._t)
        self._delta_c = np.where(live, delta_c, self._delta_c)
        ix, iy, ipsi, ir, idel = self._idx
        self._state = np.where(advance[:, None], traj[:, -1], self._state)
        # --- sensors
        if self._ideal:
            psi_m, r_m = traj[:, -1, ipsi], traj[:, -1, ir]
        else:
            psi_m, r_m = self._psi_m.copy(), self._r_m.copy()
            for i in np.flatnonzero(advance):
                p_i, r_i = self._sensors[i].measure(traj[i, :, ipsi], traj[i, :, ir], self._rngs[i])
                psi_m[i], r_m[i] = p_i[-1], r_i[-1]
        self._psi_m = np.where(advance, psi_m, self._psi_m)
        self._r_m = np.where(advance, r_m, self._r_m)
        if self._n > 1:
            dx = traj[:, -1, ix] - traj[:, -2, ix]
            dy = traj[:, -1, iy] - traj[:, -2, iy]
            self._speed = np.where(advance, np.sqrt(dx * dx + dy * dy) / self._h, self._speed)
        # --- path
        self._update_frame(advance)
        f = self._frame
        e = f["cross_track"]
        heading_error = _wrap(self._state[:, ipsi] - f["path_angle"])
        dd = (delta_c - prev_delta_c) / self._dmax
        q = delta_c / self._dmax
        reward = -(
            np.abs(e) / self._L
            + self._w_psi * np.abs(heading_error)
            + self._w_delta * q * q
            + self._w_rate * dd * dd
        )
        goal = advance & f["at_goal"]
        corridor = advance & ~f["at_goal"] & (np.abs(e) > self._e_max)
        reward = np.where(goal, reward + self._goal_bonus, reward)
        left = self._max_steps - steps
        reward = np.where(corridor, reward - (self._e_max / self._L) * left, reward)
        diverged = live & ~finite
        reward = np.where(diverged, -(self._e_max / self._L) * (left + 1), reward)
        terminated = goal | corridor | diverged
        truncated = advance & ~terminated & (steps >= self._max_steps)
        rewards = np.where(live, reward, 0.0)
        reasons[goal] = "goal"
        reasons[corridor] = "corridor"
        reasons[diverged] = "non_finite_state"
        reasons[truncated] = "time_limit"
        # --- episode log (true values), one column per control step
        rows = np.flatnonzero(live)
        col = steps[rows] - 1
        compute_time = np.full(rows.size, np.nan)
        heading_log = np.where(
            diverged, _wrap(self._state[:, ipsi] - f["path_angle"]), heading_error
        )
        for k, values in enumerate(
            (self._t, e, heading_log, self._state[:, idel], delta_c, rewards)
        ):
            self._log[k, rows, col] = values[rows]
        self._log[len(ARRAY_FIELDS) - 1, rows, col] = compute_time
        done = terminated | truncated
        info = self._info(np.ones(n, dtype=bool))
        if np.any(done):
            info["termination_reason"] = reasons
            info["_termination_reason"] = done
            if self.episode_metrics:
                info["episode_metrics"] = self._stacked_metrics(done, goal)
                info["_episode_metrics"] = done
        self._autoreset = done
        return self._observation(), rewards, terminated, truncated, info

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
        sc = self.scenario
        ipsi, ir = self._idx[2], self._idx[3]
        self._state[mask] = sc.initial_state()
        self._steps[mask] = 0
        self._t[mask] = 0.0
        self._delta_c[mask] = 0.0
        self._integral[mask] = 0.0
        self._p_block[mask] = sc.schedule.vector_at(0.0)
        self._p_dirty[mask] = False
        self._speed[mask] = self._u0
        self._log[:, mask] = 0.0
        for i in np.flatnonzero(mask):
            sensor = self._sensors[i]
            self._disturbances.reset(i, self._rngs[i])  # before the sensor's draws
            sensor.reset()
            x = self._state[i]
            if self._ideal:
                self._psi_m[i], self._r_m[i] = x[ipsi], x[ir]
            else:
                p_i, r_i = sensor.measure(x[ipsi : ipsi + 1], x[ir : ir + 1], self._rngs[i])
                self._psi_m[i], self._r_m[i] = p_i[0], r_i[0]
        self._leg[mask] = 0
        self._update_frame(mask)

    def _refresh_parameters(self, t0: np.ndarray, live: np.ndarray) -> None:
        """Parameter rows of the period [t0, t0 + Ts] per env (see ShipPathFollowEnv.step)."""
        schedule = self.scenario.schedule
        if not schedule.events:
            return
        t1 = t0 + self._Ts
        changing = np.zeros(self.num_envs, dtype=bool)
        for event in schedule.events:
            changing |= (event.end_time() >= t0 - 1e-9) & (event.time <= t1 + 1e-9)
        for i in np.flatnonzero(live & (changing | self._p_dirty)):
            if changing[i]:
                schedule.fill_matrix(float(t0[i]), self._h, self._p_block[i])
                self._p_dirty[i] = True
            else:
                self._p_block[i] = schedule.vector_at(float(t1[i]))
                self._p_dirty[i] = False

    def _update_frame(self, mask: np.ndarray) -> None:
        """Active legs (switching rule) and the leg frame for the envs in ``mask``."""
        ix, iy = self._idx[0], self._idx[1]
        x, y = self._state[:, ix], self._state[:, iy]
        leg = self._leg
        for _ in range(self._last_leg):  # may skip several waypoints, never past the last leg
            nxt = np.minimum(leg, self._last_leg)
            if self._switching == "circle":
                dx = x - self._leg_x1[nxt]
                dy = y - self._leg_y1[nxt]
                reached = dx * dx + dy * dy <= self._radius * self._radius
            else:
                rx, ry = x - self._leg_x0[nxt], y - self._leg_y0[nxt]
                along = rx * self._leg_c[nxt] + ry * self._leg_s[nxt]
                reached = self._leg_len[nxt] - along < self._radius
            step = mask & reached & (leg < self._last_leg)
            if not np.any(step):
                break
            leg = leg + step
        self._leg = leg
        rx, ry = x - self._leg_x0[leg], y - self._leg_y0[leg]
        c, s = self._leg_c[leg], self._leg_s[leg]
        along = rx * c + ry * s
        cross = -rx * s + ry * c
        gx, gy = x - self._goal[0], y - self._goal[1]
        dist_goal = np.sqrt(gx * gx + gy * gy)
        nx_, ny_ = x - self._leg_x1[leg], y - self._leg_y1[leg]
        last = leg == self._last_leg
        at_goal = last & ((dist_goal <= self._radius) | (along >= self._leg_len[leg]))
        new = {
            "cross_track": cross,
            "path_angle": self._leg_angle[leg],
            "angle_change": self._leg_change[leg],
            "distance_next": np.sqrt(nx_ * nx_ + ny_ * ny_),
            "at_goal": at_goal,
        }
        if not self._frame:
            self._frame = new
        else:
            for key, value in new.items():
                self._frame[key] = np.where(mask, value, self._frame[key])

    def _autopilot(self, a: np.ndarray, live: np.ndarray) -> np.ndarray:
        """The single env's guidance-mode PID, over all ships (shipgym.guidance laws)."""
        f = self._frame
        scale = 2.0 ** a[:, 0]
        e, angle = f["cross_track"], f["path_angle"]
        if self._gcfg.law == "los":
            n = self._gcfg.los_radius_L * scale
            radius = np.where(np.abs(e) <= n * self._L, n * self._L, np.abs(e) + self._L)
            desired = angle - np.arcsin(e / radius)
        elif self._gcfg.law == "lookahead_los":
            desired = angle + np.arctan(-e / (self._gcfg.lookahead_L * self._L * scale))
            desired = _wrap(desired)
        else:  # VF / TVVF: the single env's own functions, evaluated over the N ships
            desired = field_law_heading(self._gcfg, e, angle, self._L, scale)
        desired = desired + a[:, 1] * GUIDANCE_OFFSET_MAX
        error = _wrap(desired - self._psi_m)
        dt = self._Ts
        trial = self._kp * error - self._kd * self._r_m + self._ki * (self._integral + error * dt)
        lim = self._dmax
        inside = (-lim < trial) & (trial < lim)
        # envs being autoreset this step ignore their action: their integral stays at 0
        self._integral = np.where(inside & live, self._integral + error * dt, self._integral)
        raw = self._kp * error - self._kd * self._r_m + self._ki * self._integral
        return np.minimum(lim, np.maximum(-lim, raw))

    def _observation(self) -> np.ndarray:
        f = self._frame
        idel = self._idx[4]
        err = self._psi_m - f["path_angle"]
        d = f["distance_next"]
        obs = np.stack(
            [
                f["cross_track"] / self._e_max,
                np.sin(err),
                np.cos(err),
                self._r_m / (2.0 * self._u0 / self._L),
                self._state[:, idel] / self._dmax,
                self._delta_c / self._dmax,
                self._speed / self._u0,
                f["angle_change"] / math.pi,
                d / (d + 10.0 * self._L),
            ],
            axis=1,
        ).astype(np.float32)
        return np.clip(obs, self._obs_low, self._obs_high, out=obs)

    def _info(self, mask: np.ndarray) -> dict[str, Any]:
        ix, iy, _, _, idel = self._idx
        f = self._frame
        info = {
            "t": self._t.copy(),
            "cross_track_error": f["cross_track"].copy(),
            "heading_error": _wrap(self._psi_m - f["path_angle"]),
            "heading": self._psi_m.copy(),
            "yaw_rate": self._r_m.copy(),
            "rudder_angle": self._state[:, idel].copy(),
            "rudder_command": self._delta_c.copy(),
            "position": self._state[:, [ix, iy]].copy(),
            "waypoint_index": self._leg.copy(),
        }
        for key in list(info):
            info[f"_{key}"] = mask.copy()
        return info

    def _stacked_metrics(self, done: np.ndarray, goal: np.ndarray) -> dict[str, np.ndarray]:
        """Metrics of the finished envs in SyncVectorEnv's layout: key -> (N,) array, with a
        ``_key`` mask."""
        per_env = {
            int(i): self._episode_metrics(int(i), bool(goal[i])) for i in np.flatnonzero(done)
        }
        stacked: dict[str, np.ndarray] = {}
        for key in next(iter(per_env.values())):
            values = np.zeros(self.num_envs)
            for i, metrics in per_env.items():
                values[i] = metrics[key]
            stacked[key] = values
            stacked[f"_{key}"] = done.copy()
        return stacked

    def _episode_metrics(self, i: int, reached: bool) -> dict[str, Any]:
        k = int(self._steps[i])
        columns = {name: self._log[j, i, :k].copy() for j, name in enumerate(ARRAY_FIELDS)}
        log = EpisodeLog(
            **columns,
            change_time=self.scenario.change_time,
            ship_length=self._L,
            reached_goal=reached,
            dt=self._Ts,
        )
        return compute_metrics(log, self._metric_settings)
