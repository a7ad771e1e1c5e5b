"""ShipPathFollow: one ship follows a path while its dynamics change (docs/environment.md).

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

With ``context_features=True`` (a ``gym.make`` argument, default off) 7 entries follow: the
controller context a classical controller is designed from (the nominal model's first-order
Nomoto K and T, L, U0, Ts, δmax; :func:`shipgym.envs.core.context_columns`, table in
docs/observation.md), constant over an episode, never the true parameters or the schedule.
With ``history_steps=K`` (default 0: none) 7·K entries follow last: the last K control
steps, oldest first, each the measured entries 0–4 and 6 at the step's start and the
rudder command applied during it, δc/δmax; zeros before the episode's start
(:class:`shipgym.envs.core.ObservationHistory`, table in docs/observation.md).

Reward, termination, observation and info are the step core of :mod:`shipgym.envs.core`
(the same functions as the batched env); its docstring gives the reward.

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

import dataclasses
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np

from shipgym.angles import wrap_angle
from shipgym.disturbances import SensorModel
from shipgym.envs import core
from shipgym.envs.context import ControllerContext
from shipgym.envs.core import LOG_FIELDS, OBS_HIGH, OBS_LOW
from shipgym.envs.truth import PlantTruth
from shipgym.metrics import EpisodeLog, compute_metrics
from shipgym.numerics import SCALAR
from shipgym.scenarios.loader import Scenario, load_scenario
from shipgym.scenarios.trials import apply_trial, draw_trial, env_randomization
from shipgym.tracking import TrackFrame

__all__ = [
    "ShipPathFollowEnv",
]


class ShipPathFollowEnv(gym.Env):
    """Path following of one ship under scheduled parameter changes.

    The single source of every ``ShipPathFollow-*`` env id's documentation page (the docs
    add each id's numbers: ship, default scenario, Ts, h, δmax, L, U0, e_max).

    .. rubric:: Description

    One ship (a 2nd-order Nomoto model or a 3-DOF manoeuvring model, :mod:`shipgym.models`)
    follows a reference path (waypoints with leg switching, or a PCHIP curve) while its
    dynamics change at scheduled times (rudder aging, a current shift, a manoeuvrability
    change: the scenario's ``events``).  One ``step`` is one control period Ts; inside it the
    plant is integrated with RK4 at the fine step h, with the servo and rudder limits, the
    disturbances and the true parameters acting now.  The agent sees measurements only; the
    reward is computed from the true state.

    .. rubric:: Action space

    ``action_mode="rudder"`` (default): ``Box(-1, 1, (1,), float32)``; the rudder command is
    δc = a·δmax [rad].

    ``action_mode="guidance"``: ``Box(-1, 1, (2,), float32)``; a0 scales the guidance law's
    length scale (LOS radius R_LOS = n·L, look-ahead / TVVF Δ, VF τ) by 2^a0 ∈ [½, 2], a1 adds
    a course offset a1·30°; the heading loop is closed inside the env by the PID autopilot
    of :mod:`shipgym.autopilot`, pole-placed (ωn = 1 rad/s, ζ = 1) on the nominal model's
    first-order Nomoto approximation.  With a = 0 and the LOS law it is the ``pid_los``
    baseline.

    .. rubric:: Observation space

    ``Box(low, high, (9,), float32)``, from measurements (sensor noise included) only; ψ̃ is
    the heading error, the path angle minus the measured heading:

    .. list-table::
       :header-rows: 1

       * - index
         - name
         - quantity and scaling
         - unit before scaling
         - bounds
       * - 0
         - ``cross_track``
         - ``e / e_max``
         - m
         - [-1, 1]
       * - 1
         - ``sin_heading_error``
         - ``sin ψ̃``
         - rad
         - [-1, 1]
       * - 2
         - ``cos_heading_error``
         - ``cos ψ̃``
         - rad
         - [-1, 1]
       * - 3
         - ``yaw_rate``
         - ``r / (2 u0 / L)``, clipped
         - rad/s
         - [-1, 1]
       * - 4
         - ``rudder_angle``
         - ``δ / δmax``
         - rad
         - [-1, 1]
       * - 5
         - ``last_rudder_command``
         - ``δc_prev / δmax``
         - rad
         - [-1, 1]
       * - 6
         - ``speed``
         - ``U / U0``, clipped
         - m/s
         - [0, 2]
       * - 7
         - ``next_angle_change``
         - ``Δψ_next / π``, path-angle change to the next leg
         - rad
         - [-1, 1]
       * - 8
         - ``next_distance``
         - ``d_next / (d_next + 10 L)``, distance to the next waypoint
         - m
         - [0, 1)

    .. rubric:: Reward

    Per step, from the true state (the score, the same for every controller)::

        r = −(|e|/L + w_ψ·|ψ̃| + w_δ·(δc/δmax)² + w_Δ·(Δδc/δmax)²)

    with defaults w_ψ = 0.1, w_δ = 0.01, w_Δ = 0.05 (the scenario's ``reward:``).  While the
    ship is inside the corridor each term is bounded: ``0 ≤ |e|/L ≤ e_max/L`` (10 by
    default), ``0 ≤ w_ψ·|ψ̃| ≤ w_ψ·π``, ``0 ≤ w_δ·(δc/δmax)² ≤ w_δ``,
    ``0 ≤ w_Δ·(Δδc/δmax)² ≤ 4·w_Δ``, so ``r ∈ [−(e_max/L + w_ψ·π + w_δ + 4·w_Δ), 0]``.
    Reaching the last waypoint adds ``goal_bonus`` (+10).  Leaving the corridor adds a
    penalty equal to staying at its edge for the rest of the time limit,
    ``−(e_max/L)·(steps left)``, so that leaving is never cheaper than staying; a
    non-finite plant state is charged the same from the step before.

    .. rubric:: Starting state

    The scenario's ``initial_state`` (x, y [m], heading [deg], other states SI; default: the
    origin, heading 0°), cruising at the nominal speed with zero yaw rate and rudder.

    With ``randomize=True`` (what ``gym.make(ENV_ID)`` passes) every reset first draws a
    trial of the scenario from the env's ``np_random``, with the default suite's
    ``randomize:`` ranges (:func:`shipgym.scenarios.trials.env_randomization`): the start
    moved off the first leg and turned, the jump times shifted, the current scaled and
    turned.  ``reset(seed=s)`` gives one trial per seed; ``reset()`` goes on with the
    env's stream (a new trial).  ``scenario`` is the episode's trial, ``base_scenario`` the
    scenario given.  ``randomize=False`` (the class's default) runs the scenario itself,
    as the leaderboard plays the trials it draws from its evaluation seeds.  The env's seed
    also draws the sensor noise and the stochastic currents and waves.

    .. rubric:: Episode end

    Terminated: the last waypoint is reached (``termination_reason = "goal"``), the ship
    leaves the corridor ``|e| > e_max`` (``"corridor"``, e_max = 10 L by default), or the
    plant state is not finite (``"non_finite_state"``).  Truncated: the scenario's
    ``time_limit`` (``"time_limit"``; in control periods: ceil(time_limit/Ts)).  At the last
    step ``info`` also holds ``termination_reason`` and ``episode_metrics`` (ACE, t_c, J, …).
    Each id's spec states its default scenario's ceil(time_limit/Ts) as
    ``max_episode_steps`` (:data:`shipgym.MAX_EPISODE_STEPS`); ``gym.make`` wraps the env in
    a ``TimeLimit`` of that many steps, which ends the episode at the same step as the
    env.  With a longer ``scenario`` pass ``max_episode_steps=-1`` (the env's own limit).

    .. rubric:: Arguments

    ``gym.make(ENV_ID, scenario=..., action_mode="rudder", render_mode=None, compile=True,
    randomize=True)``

    * ``scenario``: a catalogue name (``shipgym scenarios``), a held-out test scenario
      (``"heldout:3"``), a path to a YAML file or a :class:`shipgym.scenarios.loader.Scenario`;
      default: the id's scenario.
    * ``action_mode``: ``"rudder"`` or ``"guidance"``.
    * ``render_mode``: None, ``"rgb_array"`` or ``"human"``.
    * ``compile``: compile the CasADi period function to C (cached per machine); False
      uses CasADi's VM (the same bits, slower).
    * ``context_features``: append the 7 controller-context features (default False).
    * ``history_steps``: K ≥ 0, append the last K control steps of (measurements, applied
      rudder command), 7 entries each, oldest first, zeros before the episode's start
      (default 0: the observation above, unchanged; docs/observation.md).
    * ``randomize``: draw a trial of ``scenario`` at every reset (see Starting state); True
      in every id's registration, False in the class.

    ``gym.make_vec(ENV_ID, num_envs=N)`` returns the batched
    :class:`~shipgym.envs.vector.ShipPathFollowVectorEnv` (N single envs bit for bit, env i
    seeded ``seed + i``: N different trials).
    Processes that have not imported ``shipgym`` use ``gym.make("shipgym:ENV_ID")``.

    .. rubric:: Version history

    What ``gym.make(id)`` returns never changes under an id; a new default is a new version.

    * ``-v0``: ``ShipPathFollow-v0`` (nomoto2, ``rudder_aging``);
      ``ShipPathFollow-EssoOsaka-v0``, ``-Mariner-v0``, ``-Blanke-v0`` (defaults
      ``osaka_stochastic_current``, ``mariner_track``, ``blanke_current_shift``:
      disturbances only, no change of dynamics; kept, Gymnasium warns that a ``-v1``
      exists).
    * ``-v1`` (EssoOsaka, Mariner, Blanke): the same env, defaulting to the ship's
      ``{ship}_rudder_aging`` (a changing plant).
    * Every id, in place: ``randomize=True`` (a trial per reset) and ``max_episode_steps``
      in the spec.  Before, ``gym.make(id)`` ran the scenario itself whatever the seed;
      ``gym.make(id, randomize=False)`` is that env.
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["human", "rgb_array"], "render_fps": 10}

    def __init__(
        self,
        scenario: Any = "rudder_aging",
        action_mode: str = "rudder",
        render_mode: str | None = None,
        compile: bool = True,
        context_features: bool = False,
        history_steps: int = 0,
        randomize: bool = False,
    ) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode must be None or one of {self.metadata['render_modes']}, "
                f"got {render_mode!r}"
            )
        if not isinstance(randomize, bool):
            raise ValueError(f"randomize must be True or False, got {randomize!r}")
        #: the scenario as given; with ``randomize`` each reset draws a trial of it
        self.base_scenario: Scenario = load_scenario(scenario)
        #: draw a trial of ``base_scenario`` at every reset (the default suite's ranges)
        self.randomize = randomize
        self._randomization = env_randomization() if randomize else None
        #: the observation ends with the controller-context features (core.CONTEXT_NAMES)
        self.context_features = context_features
        self.history_steps = history_steps  # checked by the parts' build, then read back
        self.action_mode = action_mode
        self.render_mode = render_mode
        self._compile = compile
        self._fig = None
        self.use_scenario(self.base_scenario)
        #: K: the observation ends with the last K control steps (core.ObservationHistory)
        self.history_steps = k = self._parts.history_steps
        self._history = core.ObservationHistory(1, k) if k else None
        self.action_space = self._parts.action_space
        self.observation_space = self._parts.observation_space

    def use_scenario(self, scenario: Scenario) -> None:
        """Run ``scenario`` from the next reset on (its model, integrator, disturbances,
        path tracker and sensors); the observation and action spaces do not depend on it.
        The trial of a ``randomize`` reset and the randomised env's drawn scenarios come in
        through here."""
        parts = core.EnvParts.build(
            scenario,
            self.action_mode,
            self._compile,
            context_features=self.context_features,
            history_steps=self.history_steps,
        )
        #: the scenario of the episode (with ``randomize``: the trial drawn at reset)
        self.scenario: Scenario = scenario
        self._parts = parts
        self.model = scenario.model
        self._k = k = parts.constants
        self._integrator = parts.integrator
        self._disturbances = parts.disturbances
        self._tracker = parts.tracker
        self._sensor = SensorModel(scenario.config.sensors)
        # per-substep disturbance and parameter blocks (rows = substeps); disturbances: the
        # mean current, refilled every period when time-varying
        self._w_block = np.zeros((k.substeps, self.model.n_disturbances))
        self._w_block[:] = self._disturbances.constant_row()
        self._p_block = np.zeros((k.substeps, self.model.n_params))
        self._sample_offsets = k.fine_step * np.arange(k.substeps)
        #: the period state (None until reset)
        self._state: core.EnvState | None = None
        #: the last period's ``info["samples"]`` (module doc)
        self._samples: dict[str, np.ndarray] = {}

    # ------------------------------------------------------------------ public helpers
    @property
    def controller_context(self) -> ControllerContext:
        """What a controller may know (nominal model, path, timing); never the truth."""
        return ControllerContext.of(self.scenario, self.action_mode)

    # ------------------------------------------------------------------ gym API
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        if self._randomization is not None:  # the trial first, from the env's own stream
            draws = draw_trial(self._randomization, self.np_random)
            self.use_scenario(apply_trial(self.base_scenario, draws))
        sc, k = self.scenario, self._k
        x = sc.initial_state()
        self._p_block[:] = sc.schedule.vector_at(0.0)
        self._p_block_dirty = False
        self._disturbances.reset(0, self.np_random)  # before the sensor's draws
        self._sensor.reset()
        psi_m, r_m = self._sensor.measure(
            x[k.ipsi : k.ipsi + 1], x[k.ir : k.ir + 1], self.np_random
        )
        self._state = core.EnvState(
            x=x,
            steps=0,
            t=0.0,
            delta_c=0.0,
            psi_m=float(psi_m[0]),
            r_m=float(r_m[0]),
            speed=k.nominal_speed,
            integral=0.0,  # guidance mode: the heading PID's integral
        )
        frame = self._tracker.reset(float(x[k.ix]), float(x[k.iy]))
        self._track = [(float(x[k.ix]), float(x[k.iy]))]
        #: per control step the LOG_FIELDS values (true errors, for the metrics)
        self._log: list[tuple[float, ...]] = []
        self._w_log: list[np.ndarray] = []
        self._reached_goal = False
        if self._history is not None:
            self._history.restart()
        return self._observation(frame), self._info(frame)  # no period yet: no samples

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        if self._state is None:
            raise RuntimeError("call reset() before step()")
        a, s = self._check_action(action), self._state
        self._state, period = core.transition(
            s, a, True, self._k, SCALAR, self._command, self._plant, self._measure, self._tracker
        )
        if self._history is not None:
            self._history.stepped()
        return self._end_step(period)

    # ------------------------------------------------------------------ pieces
    def _check_action(self, action: Any) -> list[float]:
        """The action as floats clipped to [-1, 1]; ValueError (state untouched) if malformed."""
        values = core.check_action(action, self.action_space.shape).tolist()
        return [min(1.0, max(-1.0, v)) for v in values]

    def _command(self, a: list[float], s: core.EnvState, live: bool) -> tuple[float, float]:
        """The period's rudder command [rad] and PID integral (core.transition's command)."""
        return core.rudder_command(a, s, self._tracker.frame, self._parts, SCALAR)

    def _plant(self, s: core.EnvState, delta_c: float, live: bool) -> np.ndarray:
        """The period's true parameters and disturbances, then the plant: the (n_sub + 1,
        n_x) states at t0, t0 + h, …, t0 + Ts, a fresh array (core.transition's plant)."""
        self._p_block_dirty = core.refresh_parameters(
            self.scenario.schedule, s.t, self._k, self._p_block, self._p_block_dirty
        )
        if self._disturbances.time_varying:
            self._disturbances.fill_one(self._w_block, s.t, self.np_random)
            self._w_log.append(self._w_block.copy())
        else:
            self._w_log.append(self._w_block)  # the constant block, never written again
        return self._integrator(s.x, delta_c, self._w_block, self._p_block)

    def _measure(
        self, trajectory: np.ndarray, s: core.EnvState, new: core.EnvState, advance: bool
    ) -> tuple[float, float]:
        """The sensors over the period's substeps (core.transition's measure), and the
        period's ``samples`` at the substep starts t0, t0+h, …, t0+Ts−h (module doc)."""
        if not advance:
            return new.psi_m, new.r_m
        k = self._k
        start, states = trajectory[:-1], trajectory[1:]
        psi_m, r_m = self._sensor.measure(states[:, k.ipsi], states[:, k.ir], self.np_random)
        self._samples = {
            "t": s.t + self._sample_offsets,
            "psi": np.concatenate(([s.psi_m], psi_m[:-1])),
            "r": np.concatenate(([s.r_m], r_m[:-1])),
            "delta": start[:, k.idelta],  # a view into this step's fresh trajectory
            "delta_c": np.full(k.substeps, new.delta_c),
            "e": self._tracker.cross_track_of(start[:, k.ix], start[:, k.iy]),
        }
        return float(psi_m[-1]), float(r_m[-1])

    def _observation(self, frame: Any) -> np.ndarray:
        s, k = self._state, self._k
        obs = np.array(
            core.observation_columns(
                frame,
                s.psi_m,
                s.r_m,
                float(s.x[k.idelta]),
                s.delta_c,
                s.speed,
                k,
                SCALAR,
            ),
            dtype=np.float32,
        )
        obs.clip(OBS_LOW, OBS_HIGH, out=obs)
        if self.context_features:
            obs = np.concatenate([obs, self._parts.context_row])
        if self._history is not None:
            obs = self._history.append(obs[None])[0]
        return obs

    def _info(self, frame: Any) -> dict[str, Any]:
        s, k = self._state, self._k
        x = s.x
        return core.info_values(
            s.t,
            frame,
            s.psi_m,
            s.r_m,
            float(x[k.idelta]),
            s.delta_c,
            (float(x[k.ix]), float(x[k.iy])),
        )

    def _end_step(
        self, period: core.Period, reason: str | None = None
    ) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """The step's log entry and return values after ``period``; ``reason``: the end of
        an abandoned episode.  A non-finite plant state (or an abandoned episode) is
        charged the corridor penalty from the step before and logged like any other step,
        so ``episode_metrics`` count it; its ``info`` has no ``samples`` (none are valid)."""
        s, k, frame = self._state, self._k, period.frame
        x = s.x
        reward = period.reward
        self._record(frame.cross_track, period.heading_error, float(x[k.idelta]), s.delta_c, reward)
        info = self._info(frame)
        moved = not period.diverged
        if moved:
            self._track.append((float(x[k.ix]), float(x[k.iy])))
            self._reached_goal = period.goal
            info["samples"] = self._samples
        reason = reason or period.reasons()
        if reason is not None:
            info["termination_reason"] = reason
            info["episode_metrics"] = self.episode_metrics()
        if moved and self.render_mode == "human":
            self.render()
        obs = self._observation(frame)
        return obs, float(reward), period.terminated, period.truncated, info

    def abandon(self, reason: str) -> dict[str, Any]:
        """End the episode now, for a cause outside the plant (e.g. its controller gave no
        usable action): one more control step is logged with the plant not moved and the
        last rudder command, charged as a non-finite state is (the corridor penalty
        counted from this step on).  Returns that step's ``info``: ``termination_reason``
        = ``reason`` and ``episode_metrics``, no ``samples``.  Reset before stepping again.
        """
        if self._state is None:
            raise RuntimeError("call reset() before abandon()")
        s, k = self._state, self._k
        steps = s.steps + 1
        self._state = dataclasses.replace(s, steps=steps, t=steps * k.control_period)
        if self._history is not None:
            self._history.stepped()
        frame = self._tracker.frame
        heading_error = wrap_angle(float(s.x[k.ipsi]) - frame.path_angle)
        reward = core.diverged_reward(steps, k)
        period = core.Period(frame, heading_error, reward, False, False, True, False)
        return self._end_step(period, reason)[4]

    def _record(
        self, e: float, heading_error: float, delta: float, delta_c: float, reward: float
    ) -> None:
        """Append one control step to the episode log (LOG_FIELDS order)."""
        self._log.append((self._state.t, e, heading_error, delta, delta_c, reward))

    def episode_log(self) -> EpisodeLog:
        """The control-step log of the current episode (true errors, for the metrics)."""
        table = np.array(self._log, dtype=float).reshape(-1, len(LOG_FIELDS))
        columns = {name: table[:, j].copy() for j, name in enumerate(LOG_FIELDS)}
        return core.episode_log(columns, self.scenario, self._reached_goal)

    def episode_metrics(self) -> dict[str, Any]:
        return compute_metrics(self.episode_log(), self._parts.metric_settings)

    def episode_disturbances(self) -> dict[str, np.ndarray]:
        """The true disturbances of the episode so far, for analysis after the episode
        (never in ``info``: controllers do not see them): ``"t"`` the fine sample times
        [s] (the grid of ``info["samples"]["t"]``) and one (k·n_sub,) array per name of
        ``model.disturbance_names`` (e.g. current_x, current_y [m/s])."""
        n = len(self._w_log)
        k = self._k
        t = (np.arange(n)[:, None] * k.control_period + self._sample_offsets[None, :]).ravel()
        blocks = np.concatenate(self._w_log) if n else np.zeros((0, self.model.n_disturbances))
        out = {"t": t}
        for j, name in enumerate(self.model.disturbance_names):
            out[name] = blocks[:, j].copy()
        return out

    def plant_truth(self) -> PlantTruth:
        """The true plant now (:mod:`shipgym.envs.truth`): privileged.  Never in ``info`` or
        the controller context; the evaluation loop passes it to the built-in references
        ``oracle`` and ``oracle_frozen`` only."""
        if self._state is None:
            raise RuntimeError("call reset() before plant_truth()")
        sc, s = self.scenario, self._state
        if self._disturbances.time_varying and s.steps > 0:
            now = self._w_block[-1].copy()  # the last substep's disturbances
            waves = self._disturbances.wave_row()
        else:
            now = self._disturbances.mean_rows(np.array([s.t]))[0]
            waves = np.zeros_like(now)
        return PlantTruth(
            t=s.t,
            state=s.x.copy(),
            params=sc.schedule.record_at(s.t),
            disturbance_now=now,
            wave_now=waves,
        )

    @property
    def pose(self) -> tuple[float, float, float]:
        """True position x, y [m] and heading ψ [rad] now (for rendering and analysis)."""
        x, k = self._state.x, self._k
        return float(x[k.ix]), float(x[k.iy]), float(x[k.ipsi])

    @property
    def time(self) -> float:
        """Simulation time [s] now."""
        return self._state.t

    @property
    def frame(self) -> TrackFrame | None:
        """The ship's frame on the path now (the tracker's)."""
        return self._tracker.frame

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
