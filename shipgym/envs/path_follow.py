"""ShipPathFollow: one ship follows a path while its dynamics change (SPEC §5).

Data flow through one ``step`` (one control period Ts):

    action → rudder command δc → plant RK4 substeps at h (true parameters from the event
    schedule, disturbances) → sensor model → measurements → path tracker / guidance →
    observation, reward, info → episode log → metrics at the end.

Observation (float32, 9 entries, each within its documented bound):

    0  e / e_max                       cross-track error over the corridor half-width, [-1, 1]
    1  sin ψ̃, 2  cos ψ̃                 heading error to the path angle (measured heading)
    3  r / (2 u0 / L)                  yaw rate, clipped to [-1, 1]
    4  δ / δmax                        rudder angle
    5  δc_prev / δmax                  last rudder command
    6  U / U0                          speed over ground over nominal speed, clipped [0, 2]
    7  Δψ_next / π                     path-angle change to the next leg
    8  d_next / (d_next + 10 L)        distance to the next waypoint, squashed to [0, 1)

Reward per step (SPEC §5), from the *true* state (the score, the same for everyone):

    r = −( |e|/L + w_ψ·|ψ̃| + w_δ·(δc/δmax)² + w_Δ·(Δδc/δmax)² )

plus ``goal_bonus`` when the last waypoint is reached (terminated), and, when the ship
leaves the corridor |e| > max_cross_track (terminated), a penalty equal to the cost of
staying at the corridor edge for the rest of the time limit, (e_max/L)·(steps left), so
that leaving is never cheaper than staying.  The time limit truncates.

``info["samples"]`` (for online identifiers at the fine step h): the period's samples at
the substep starts t0, t0 + h, …, t0 + Ts − h, i.e. each sample's ``delta_c`` is exactly the
command acting on [t, t + h).  Concatenated over an episode they form one uniform grid
0, h, 2h, … without repeats; the state at t0 + Ts opens the next step's samples.  Measured
values (ψ, r with sensor noise) are measured once per instant, so the first sample of a
step equals the previous step's ``info["heading"]`` / ``info["yaw_rate"]``.  The key is
absent at reset (no period yet) and on a non-finite step, so that every ``samples`` array
has the same length (vector envs stack infos across sub-envs).
"""

from __future__ import annotations

import math
import time
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from shipgym.autopilot import HeadingPID, PIDGains
from shipgym.disturbances import Disturbances, SensorModel
from shipgym.envs.context import ControllerContext
from shipgym.guidance import (
    TVVF_ERROR_UNITS,
    lookahead_los_heading,
    los_desired_heading,
    tvvf_heading,
    vector_field_heading,
)
from shipgym.metrics import ARRAY_FIELDS, EpisodeLog, MetricSettings, compute_metrics
from shipgym.models.integrator import PeriodIntegrator
from shipgym.paths import wrap_angle
from shipgym.scenarios import Scenario, load_scenario
from shipgym.tracking import PathTracker

OBS_NAMES = (
    "cross_track",
    "sin_heading_error",
    "cos_heading_error",
    "yaw_rate",
    "rudder_angle",
    "last_rudder_command",
    "speed",
    "next_angle_change",
    "next_distance",
)
_OBS_LOW = np.array([-1, -1, -1, -1, -1, -1, 0, -1, 0], dtype=np.float32)
_OBS_HIGH = np.array([1, 1, 1, 1, 1, 1, 2, 1, 1], dtype=np.float32)

#: guidance action: a0 scales the law's length scale (LOS R_LOS = nL, look-ahead / TVVF Δ,
#: VF τ) by 2^a0 ∈ [½, 2]; a1 → course offset a1·30°.
GUIDANCE_OFFSET_MAX = math.radians(30.0)


def field_law_heading(
    gcfg: Any, cross_track: Any, path_angle: Any, ship_length: float, scale: Any
) -> Any:
    """Desired heading [rad] of a scenario's VF or TVVF law for one ship (floats) or N ships
    (arrays, the batched env): the same operations for both (shipgym.guidance module doc)."""
    if gcfg.law == "vf":
        return vector_field_heading(
            cross_track,
            path_angle,
            gcfg.vf_tau_L * ship_length * scale,
            math.radians(gcfg.vf_chi_e_deg),
            gcfg.vf_k,
        )
    if gcfg.law == "tvvf":
        return tvvf_heading(
            cross_track,
            path_angle,
            gcfg.tvvf_delta_L * ship_length * scale,
            theta_slope=gcfg.tvvf_theta_slope,
            theta_offset=gcfg.tvvf_theta_offset,
            error_unit=TVVF_ERROR_UNITS[gcfg.tvvf_error_unit](ship_length),
        )
    raise ValueError(f"not a vector-field guidance law: {gcfg.law!r}")


class ShipPathFollowEnv(gym.Env):
    """Path following of one ship under scheduled parameter changes (see module doc)."""

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["human", "rgb_array"], "render_fps": 10}

    def __init__(
        self,
        scenario: Any = "rudder_aging",
        action_mode: str = "rudder",
        render_mode: str | None = None,
        compile: bool = True,
    ) -> None:
        if action_mode not in ("rudder", "guidance"):
            raise ValueError(f"action_mode must be 'rudder' or 'guidance', got {action_mode!r}")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode must be None or one of {self.metadata['render_modes']}, "
                f"got {render_mode!r}"
            )
        self.scenario: Scenario = load_scenario(scenario)
        self.action_mode = action_mode
        self.render_mode = render_mode
        sc = self.scenario
        self.model = sc.model
        self._L = sc.ship_length
        self._u0 = self.model.nominal_speed
        self._dmax = self.model.rudder_limit
        self._Ts = sc.control_period
        self._h = sc.fine_step
        self._n = sc.substeps
        self._e_max = sc.max_cross_track
        self._max_steps = math.ceil(sc.config.time_limit / self._Ts - 1e-9)
        self._integrator = PeriodIntegrator(self.model, self._h, self._n, compile=compile)
        self._sensor = SensorModel(sc.config.sensors)
        self._tracker = PathTracker(sc.path, sc.acceptance_radius, sc.config.path.switching)
        self._ix = self.model.state_index("x")
        self._iy = self.model.state_index("y")
        self._ipsi = self.model.state_index("psi")
        self._ir = self.model.state_index("r")
        self._idelta = self.model.state_index("delta")
        # per-substep disturbance and parameter blocks (rows = substeps)
        # (disturbances: the mean current, refilled every period when time-varying)
        self._disturbances = Disturbances(
            sc.config.disturbances,
            self.model.disturbance_names,
            self._h,
            self._n,
            time_limit=sc.config.time_limit,
        )
        self._w_block = np.zeros((self._n, self.model.n_disturbances))
        self._w_block[:] = self._disturbances.constant_row()
        self._p_block = np.zeros((self._n, self.model.n_params))
        self._sample_offsets = self._h * np.arange(self._n)
        weights = sc.config.reward
        self._w_psi = weights.heading_weight
        self._w_delta = weights.rudder_weight
        self._w_rate = weights.rudder_rate_weight
        self._goal_bonus = weights.goal_bonus
        self._metric_settings = MetricSettings(
            convergence_threshold=sc.config.convergence_threshold
        )
        if action_mode == "rudder":
            self.action_space = spaces.Box(-1.0, 1.0, shape=(1,), dtype=np.float32)
        else:
            self.action_space = spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)
            K, T = self.model.first_order_nomoto(sc.nominal_params)
            self._autopilot = HeadingPID(PIDGains.from_nomoto(K, T), self._dmax)
        self.observation_space = spaces.Box(_OBS_LOW, _OBS_HIGH, dtype=np.float32)
        self._fig = None
        self._state: np.ndarray | None = None

    # ------------------------------------------------------------------ public helpers
    @property
    def controller_context(self) -> ControllerContext:
        """What a controller may know (nominal model, path, timing); never the truth."""
        sc = self.scenario
        return ControllerContext(
            ship=self.model.name,
            nominal_model=self.model.with_params(sc.nominal_params),
            waypoints=np.array(sc.path.waypoints),
            path_type=sc.config.path.type,
            ship_length=self._L,
            nominal_speed=self._u0,
            rudder_limit=self._dmax,
            control_period=self._Ts,
            fine_step=self._h,
            acceptance_radius=sc.acceptance_radius,
            switching=sc.config.path.switching,
            los_radius_L=sc.config.guidance.los_radius_L,
            action_mode=self.action_mode,
            guidance=sc.config.guidance,
        )

    # ------------------------------------------------------------------ gym API
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        sc = self.scenario
        self._state = sc.initial_state()
        self._step_count = 0
        self._t = 0.0
        self._delta_c = 0.0
        self._p_block[:] = sc.schedule.vector_at(0.0)
        self._p_block_dirty = False
        self._disturbances.reset(0, self.np_random)  # before the sensor's draws
        self._sensor.reset()
        if self.action_mode == "guidance":
            self._autopilot.reset()
        x = self._state
        psi_m, r_m = self._sensor.measure(
            x[self._ipsi : self._ipsi + 1], x[self._ir : self._ir + 1], self.np_random
        )
        self._psi_m, self._r_m = float(psi_m[0]), float(r_m[0])
        frame = self._tracker.reset(float(x[self._ix]), float(x[self._iy]))
        self._speed = self._u0
        self._track = [(float(x[self._ix]), float(x[self._iy]))]
        self._log: dict[str, list[float]] = {name: [] for name in ARRAY_FIELDS}
        self._reached_goal = False
        info = self._info(frame, None)  # no period integrated yet: no samples
        self._last_return_time = time.perf_counter()
        return self._observation(frame), info

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        if self._state is None:
            raise RuntimeError("call reset() before step()")
        called = time.perf_counter()
        compute_time = called - self._last_return_time
        a = self._check_action(action)
        frame = self._tracker.frame
        sc = self.scenario
        # --- action -> rudder command (rad)
        if self.action_mode == "rudder":
            delta_c = float(a[0]) * self._dmax
        else:
            delta_c = self._autopilot_command(a, frame)
        prev_delta_c = self._delta_c
        # --- true parameters for the substeps of this period
        t0 = self._t
        t1 = t0 + self._Ts
        if not sc.schedule.is_constant_on(t0, t1):
            sc.schedule.fill_matrix(t0, self._h, self._p_block)
            self._p_block_dirty = True
        elif self._p_block_dirty:
            self._p_block[:] = sc.schedule.vector_at(t1)
            self._p_block_dirty = False
        # --- disturbances of the period, then the plant
        if self._disturbances.time_varying:
            self._disturbances.fill_one(self._w_block, t0, self.np_random)
        trajectory = self._integrator(self._state, delta_c, self._w_block, self._p_block)
        self._step_count += 1
        self._t = self._step_count * self._Ts
        self._delta_c = delta_c
        # NaN/inf propagate through RK4: checking the final state suffices
        if not all(map(math.isfinite, trajectory[-1].tolist())):
            return self._non_finite_step(frame, delta_c, compute_time)
        states = trajectory[1:]  # ends of the substeps
        xs, ys = states[:, self._ix], states[:, self._iy]
        # fine samples at the substep *starts* t0, t0+h, …, t0+Ts−h (module doc)
        start = trajectory[:-1]
        e_samples = self._tracker.cross_track_of(start[:, self._ix], start[:, self._iy])
        psi_m0, r_m0 = self._psi_m, self._r_m
        self._state = states[-1]
        x = self._state
        px, py = float(x[self._ix]), float(x[self._iy])
        self._track.append((px, py))
        psi, delta = float(x[self._ipsi]), float(x[self._idelta])
        # --- sensors
        psi_m, r_m = self._sensor.measure(
            states[:, self._ipsi], states[:, self._ir], self.np_random
        )
        self._psi_m, self._r_m = float(psi_m[-1]), float(r_m[-1])
        self._speed = (
            math.sqrt((xs[-1] - xs[-2]) * (xs[-1] - xs[-2]) + (ys[-1] - ys[-2]) * (ys[-1] - ys[-2]))
            / self._h
            if self._n > 1
            else self._u0
        )
        # --- path
        frame = self._tracker.update(px, py)
        e = frame.cross_track
        heading_error_true = float(wrap_angle(psi - frame.path_angle))
        # --- reward (true state)
        dd = (delta_c - prev_delta_c) / self._dmax
        reward = -(
            abs(e) / self._L
            + self._w_psi * abs(heading_error_true)
            + self._w_delta * (delta_c / self._dmax) * (delta_c / self._dmax)
            + self._w_rate * dd * dd
        )
        terminated = False
        reason = None
        if frame.at_goal:
            terminated, reason = True, "goal"
            self._reached_goal = True
            reward += self._goal_bonus
        elif abs(e) > self._e_max:
            terminated, reason = True, "corridor"
            reward -= (self._e_max / self._L) * (self._max_steps - self._step_count)
        truncated = not terminated and self._step_count >= self._max_steps
        if truncated:
            reason = "time_limit"
        self._record(e, heading_error_true, delta, delta_c, reward, compute_time)
        samples = {
            "t": t0 + self._sample_offsets,
            "psi": np.concatenate(([psi_m0], psi_m[:-1])),
            "r": np.concatenate(([r_m0], r_m[:-1])),
            "delta": start[:, self._idelta],  # a view into this step's fresh trajectory
            "delta_c": np.full(self._n, delta_c),
            "e": e_samples,
        }
        info = self._info(frame, samples)
        if terminated or truncated:
            info["termination_reason"] = reason
            info["episode_metrics"] = self.episode_metrics()
        if self.render_mode == "human":
            self.render()
        self._last_return_time = time.perf_counter()
        return self._observation(frame), float(reward), terminated, truncated, info

    # ------------------------------------------------------------------ pieces
    def _check_action(self, action: Any) -> list[float]:
        """The action as floats clipped to [-1, 1]; ValueError (state untouched) if malformed."""
        try:
            values = np.asarray(action, dtype=np.float64).reshape(self.action_space.shape).tolist()
        except (TypeError, ValueError) as exc:
            raise ValueError(
                f"action must be an array of shape {self.action_space.shape}, got {action!r}"
            ) from exc
        if not all(map(math.isfinite, values)):
            raise ValueError(f"action contains NaN or inf: {action!r}; the env state is unchanged")
        return [min(1.0, max(-1.0, v)) for v in values]

    def _autopilot_command(self, a: list[float], frame: Any) -> float:
        """Guidance mode: heading reference from the guidance law, PID to δc (module doc)."""
        gcfg = self.scenario.config.guidance
        scale = 2.0 ** float(a[0])
        if gcfg.law == "los":
            desired = los_desired_heading(
                frame.cross_track, frame.path_angle, self._L, gcfg.los_radius_L * scale
            )
        elif gcfg.law == "lookahead_los":
            desired = lookahead_los_heading(
                frame.cross_track, frame.path_angle, gcfg.lookahead_L * self._L * scale
            )
        else:
            desired = field_law_heading(gcfg, frame.cross_track, frame.path_angle, self._L, scale)
        desired += float(a[1]) * GUIDANCE_OFFSET_MAX
        return self._autopilot.command(desired, self._psi_m, self._r_m, self._Ts)

    def _observation(self, frame: Any) -> np.ndarray:
        x = self._state
        err = self._psi_m - frame.path_angle
        r_scale = 2.0 * self._u0 / self._L
        d = frame.distance_to_next
        obs = np.array(
            [
                frame.cross_track / self._e_max,
                math.sin(err),
                math.cos(err),
                self._r_m / r_scale,
                float(x[self._idelta]) / self._dmax,
                self._delta_c / self._dmax,
                self._speed / self._u0,
                frame.angle_change_next / math.pi,
                d / (d + 10.0 * self._L),
            ],
            dtype=np.float32,
        )
        return np.clip(obs, _OBS_LOW, _OBS_HIGH, out=obs)

    def _info(self, frame: Any, samples: dict[str, np.ndarray] | None) -> dict[str, Any]:
        x = self._state
        info = {
            "t": self._t,
            "cross_track_error": frame.cross_track,
            "heading_error": float(wrap_angle(self._psi_m - frame.path_angle)),
            "heading": self._psi_m,
            "yaw_rate": self._r_m,
            "rudder_angle": float(x[self._idelta]),
            "rudder_command": self._delta_c,
            "position": (float(x[self._ix]), float(x[self._iy])),
            "waypoint_index": frame.leg,
        }
        if samples is not None:
            info["samples"] = samples
        return info

    def _non_finite_step(self, frame: Any, delta_c: float, compute_time: float):
        """The plant produced NaN/inf: keep the last finite state and terminate with a reason.

        The penalty is that of leaving the corridor; the step is logged like any other, so
        ``episode_metrics`` count it.  ``info`` has no ``samples`` (none are valid).
        """
        reward = -(self._e_max / self._L) * (self._max_steps - self._step_count + 1)
        x = self._state
        heading_error = float(wrap_angle(float(x[self._ipsi]) - frame.path_angle))
        self._record(
            frame.cross_track, heading_error, float(x[self._idelta]), delta_c, reward, compute_time
        )
        info = self._info(frame, None)
        info["termination_reason"] = "non_finite_state"
        info["episode_metrics"] = self.episode_metrics()
        self._last_return_time = time.perf_counter()
        return self._observation(frame), float(reward), True, False, info

    def _record(
        self,
        e: float,
        heading_error: float,
        delta: float,
        delta_c: float,
        reward: float,
        compute_time: float,
    ) -> None:
        """Append one control step to the episode log (columns in ARRAY_FIELDS order)."""
        for column, value in zip(
            self._log.values(),
            (self._t, e, heading_error, delta, delta_c, reward, compute_time),
            strict=True,
        ):
            column.append(value)

    def episode_log(self) -> EpisodeLog:
        """The control-step log of the current episode (true errors, for the metrics)."""
        return EpisodeLog(
            **{name: np.array(values) for name, values in self._log.items()},
            change_time=self.scenario.change_time,
            ship_length=self._L,
            reached_goal=self._reached_goal,
            dt=self._Ts,
        )

    def episode_metrics(self) -> dict[str, Any]:
        return compute_metrics(self.episode_log(), self._metric_settings)

    @property
    def track(self) -> np.ndarray:
        """Positions (x, y) [m] at the control steps so far, shape (k+1, 2)."""
        return np.array(self._track)

    # ------------------------------------------------------------------ rendering
    def render(self) -> np.ndarray | None:
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode to make()")
            return None
        from shipgym.rendering import render_frame

        self._fig, image = render_frame(self, self._fig, self.render_mode)
        return image

    def close(self) -> None:
        if self._fig is not None:
            import matplotlib.pyplot as plt

            plt.close(self._fig)
            self._fig = None

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["_fig"] = None
        return state
