"""The step core of ShipPathFollow: one definition for the single and the batched env.

In the spirit of Gymnasium's functional env (``gymnasium.experimental.functional``): one
control period is :func:`transition`, a function of the env's state (:class:`EnvState`) and
the action, written once over floats (one ship, ``xp = SCALAR``) or arrays (N ships,
``xp = ARRAY``) of :mod:`shipgym.numerics`: action → rudder command → plant over the period
→ sensors → path tracking → reward and termination (:class:`Period`); the env supplies the
parts that draw random numbers or hold buffers (the plant's inputs, the sensors, its path
tracker).  :class:`~shipgym.envs.path_follow.ShipPathFollowEnv` calls it for one ship,
:class:`~shipgym.envs.vector.ShipPathFollowVectorEnv` and
:class:`~shipgym.envs.trial_rows.TrialRowsVectorEnv` for N; they differ in how they reset
and batch, and build their parts from a scenario with :class:`EnvParts`.  The observation
and ``info`` are functions here too.  Tracking is :class:`shipgym.tracking.PathTracker`,
guidance :data:`shipgym.guidance.GUIDANCE_LAWS`, the autopilot
:func:`shipgym.autopilot.pid_step`: the same code for one ship and N.

Reward per step, from the *true* state (the score, the same for everyone):

    r = −( |e|/L + w_ψ·|ψ̃| + w_δ·(δc/δmax)² + w_Δ·(Δδc/δmax)² )

plus ``goal_bonus`` when the last waypoint is reached (terminated), and, when the ship
leaves the corridor |e| > e_max (terminated), a penalty equal to the cost of staying at the
corridor edge for the rest of the time limit, (e_max/L)·(steps left), so that leaving is
never cheaper than staying; a non-finite plant state terminates with the same penalty
counted from the step before.  The time limit truncates.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from collections.abc import Callable
from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding

from shipgym.angles import wrap_angle
from shipgym.autopilot import PIDGains, pid_step
from shipgym.disturbances import Disturbances
from shipgym.guidance import desired_heading
from shipgym.limits import MAX_HISTORY_STEPS
from shipgym.metrics import EpisodeLog, MetricSettings
from shipgym.models.integrator import PeriodIntegrator
from shipgym.numerics import ARRAY
from shipgym.scenarios.events import ParameterSchedule
from shipgym.scenarios.loader import Scenario, nominal_nomoto
from shipgym.tracking import PathTracker, TrackFrame

ACTION_MODES = ("rudder", "guidance")

#: revision of the step core's numbers (dynamics, reward, termination): reference data
#: computed with the env (the oracle's costs, ``shipgym_baselines.references``) is valid for one
#: revision; bump it whenever a change moves an episode's numbers
ENV_REVISION = 1

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
OBS_LOW = np.array([-1, -1, -1, -1, -1, -1, 0, -1, 0], dtype=np.float32)
OBS_HIGH = np.array([1, 1, 1, 1, 1, 1, 2, 1, 1], dtype=np.float32)

#: the optional controller-context features (``context_features=True``), appended after
#: :data:`OBS_NAMES`: what a classical controller is designed from (the nominal model's
#: first-order Nomoto K, T; L, U0, Ts, δmax), never the truth (docs/observation.md)
CONTEXT_NAMES = (
    "nominal_gain",
    "nominal_time_constant",
    "time_constant_steps",
    "ship_length",
    "nominal_speed",
    "control_period",
    "rudder_limit",
)
CONTEXT_LOW = np.zeros(len(CONTEXT_NAMES), dtype=np.float32)
CONTEXT_HIGH = np.full(len(CONTEXT_NAMES), 2.0, dtype=np.float32)

#: the optional history window (``history_steps=K``), appended after the observation
#: (and :data:`CONTEXT_NAMES`): per past control step, oldest first, these entries of the
#: observation at that step's start (the ship's measured quantities; not
#: ``last_rudder_command``, which the applied command repeats, nor the path geometry) …
HISTORY_MEASUREMENTS = (
    "cross_track",
    "sin_heading_error",
    "cos_heading_error",
    "yaw_rate",
    "rudder_angle",
    "speed",
)
#: … then the rudder command applied during that step, δc/δmax: the
#: ``last_rudder_command`` entry of the observation at the step's end
HISTORY_ACTION = "rudder_command"
HISTORY_STEP_NAMES = (*HISTORY_MEASUREMENTS, HISTORY_ACTION)
#: entries per history step
HISTORY_WIDTH = len(HISTORY_STEP_NAMES)
_HISTORY_MEASURED = np.array([OBS_NAMES.index(name) for name in HISTORY_MEASUREMENTS])
_APPLIED = OBS_NAMES.index("last_rudder_command")
_HISTORY_LOW = np.append(OBS_LOW[_HISTORY_MEASURED], OBS_LOW[_APPLIED]).astype(np.float32)
_HISTORY_HIGH = np.append(OBS_HIGH[_HISTORY_MEASURED], OBS_HIGH[_APPLIED]).astype(np.float32)

#: guidance action: a0 scales the law's length scale (LOS R_LOS = nL, look-ahead / TVVF Δ,
#: VF τ) by 2^a0 ∈ [½, 2]; a1 → course offset a1·30°.
GUIDANCE_OFFSET_MAX = math.radians(30.0)

#: the per-control-step columns both envs log for the episode metrics (true values)
LOG_FIELDS = ("t", "cross_track_error", "heading_error", "rudder_angle", "rudder_command", "reward")
#: an episode's trajectory as the evaluation keeps it: per control step (the reset's
#: included) these ``info`` values, ``position`` split into x and y [m]
TRAJECTORY_KEYS = (
    "t",
    "x",
    "y",
    "cross_track_error",
    "heading",
    "rudder_angle",
    "rudder_command",
)


@dataclasses.dataclass(frozen=True)
class StepConstants:
    """Numbers of a scenario that the step core reads (SI units)."""

    ship_length: float  # L [m]
    nominal_speed: float  # u0 [m/s]
    rudder_limit: float  # δmax [rad]
    control_period: float  # Ts [s]
    fine_step: float  # h [s]
    substeps: int  # Ts / h
    max_cross_track: float  # e_max [m], corridor half-width
    max_steps: int  # time limit in control periods
    heading_weight: float  # w_ψ
    rudder_weight: float  # w_δ
    rudder_rate_weight: float  # w_Δ
    goal_bonus: float
    ix: int  # state indices of x, y, ψ, r, δ
    iy: int
    ipsi: int
    ir: int
    idelta: int

    @classmethod
    def of(cls, sc: Scenario) -> StepConstants:
        model, w = sc.model, sc.config.reward
        return cls(
            ship_length=sc.ship_length,
            nominal_speed=model.nominal_speed,
            rudder_limit=model.rudder_limit,
            control_period=sc.control_period,
            fine_step=sc.fine_step,
            substeps=sc.substeps,
            max_cross_track=sc.max_cross_track,
            max_steps=math.ceil(sc.config.time_limit / sc.control_period - 1e-9),
            heading_weight=w.heading_weight,
            rudder_weight=w.rudder_weight,
            rudder_rate_weight=w.rudder_rate_weight,
            goal_bonus=w.goal_bonus,
            **{f"i{n}": model.state_index(n) for n in ("x", "y", "psi", "r", "delta")},
        )


def check_history_steps(history_steps: Any) -> int:
    """``history_steps`` (K, control steps of history in the observation) checked: an int
    from 0 to :data:`~shipgym.limits.MAX_HISTORY_STEPS` (not a bool), else a ValueError
    naming it.  Checked where K enters: :meth:`EnvParts.build` (every env's constructor);
    the observation's functions below and :class:`ObservationHistory` take a checked K."""
    if (
        isinstance(history_steps, bool)
        or not isinstance(history_steps, numbers.Integral)
        or not 0 <= history_steps <= MAX_HISTORY_STEPS
    ):
        raise ValueError(
            f"history_steps must be an int from 0 to {MAX_HISTORY_STEPS} (control steps of "
            f"history in the observation; 0: none), got {history_steps!r}"
        )
    return int(history_steps)


def history_bounds(history_steps: int) -> tuple[np.ndarray, np.ndarray]:
    """(low, high) of the history window of K = ``history_steps`` steps (checked,
    :func:`check_history_steps`): per step the bounds of :data:`HISTORY_MEASUREMENTS` and
    of the applied command, [-1, 1]."""
    return np.tile(_HISTORY_LOW, history_steps), np.tile(_HISTORY_HIGH, history_steps)


def history_names(history_steps: int) -> tuple[str, ...]:
    """The names of the history window's entries, oldest step first: ``<name>_lag<j>``
    with j the steps back (j = 1: the control step that just ended)."""
    lags = range(history_steps, 0, -1)
    return tuple(f"{name}_lag{lag}" for lag in lags for name in HISTORY_STEP_NAMES)


def observation_bounds(
    context_features: bool = False, history_steps: int = 0
) -> tuple[np.ndarray, np.ndarray]:
    """(low, high) of the observation: :data:`OBS_NAMES`, then :data:`CONTEXT_NAMES` when
    ``context_features``, then the history window of ``history_steps`` steps."""
    if not context_features and history_steps == 0:
        return OBS_LOW, OBS_HIGH
    lows, highs = [OBS_LOW], [OBS_HIGH]
    if context_features:
        lows.append(CONTEXT_LOW)
        highs.append(CONTEXT_HIGH)
    if history_steps:
        low, high = history_bounds(history_steps)
        lows.append(low)
        highs.append(high)
    return np.concatenate(lows), np.concatenate(highs)


def observation_space(context_features: bool = False, history_steps: int = 0) -> spaces.Box:
    """The envs' observation space: :data:`OBS_NAMES` (then :data:`CONTEXT_NAMES` when
    ``context_features``, then the history window of ``history_steps`` steps), scaled to
    their bounds."""
    low, high = observation_bounds(context_features, history_steps)
    return spaces.Box(low, high, dtype=np.float32)


def observation_names(context_features: bool = False, history_steps: int = 0) -> tuple[str, ...]:
    """The names of the observation's entries, in order."""
    return OBS_NAMES + (CONTEXT_NAMES if context_features else ()) + history_names(history_steps)


def observation_size(context_features: bool = False, history_steps: int = 0) -> int:
    """The number of entries of the observation."""
    return (
        len(OBS_NAMES)
        + (len(CONTEXT_NAMES) if context_features else 0)
        + HISTORY_WIDTH * history_steps
    )


def action_space(action_mode: str) -> spaces.Box:
    """The envs' action space: one rudder command, or the two guidance actions, in [-1, 1]."""
    n_act = 1 if action_mode == "rudder" else 2
    return spaces.Box(-1.0, 1.0, shape=(n_act,), dtype=np.float32)


@dataclasses.dataclass
class EnvParts:
    """Everything an env builds from its scenario, for one ship (``batch=None``) or N
    (the plant mapped over them on ``threads`` threads, :class:`PeriodIntegrator`)."""

    scenario: Scenario
    action_mode: str
    constants: StepConstants
    integrator: PeriodIntegrator
    disturbances: Disturbances
    tracker: PathTracker
    observation_space: spaces.Box
    action_space: spaces.Box
    #: the controller-context features (CONTEXT_NAMES, scaled), or an empty array when off
    context_row: np.ndarray
    #: K: control steps of history appended to the observation (0: none)
    history_steps: int
    metric_settings: MetricSettings
    autopilot_gains: PIDGains | None  # guidance mode: the heading PID's gains

    @classmethod
    def build(
        cls,
        scenario: Scenario,
        action_mode: str,
        compile: bool,
        batch: int | None = None,
        context_features: bool = False,
        threads: int = 2,
        history_steps: int = 0,
    ) -> EnvParts:
        if action_mode not in ACTION_MODES:
            raise ValueError(f"action_mode must be 'rudder' or 'guidance', got {action_mode!r}")
        history_steps = check_history_steps(history_steps)
        sc = scenario
        k = StepConstants.of(sc)
        model = sc.model
        integrator = PeriodIntegrator(
            model,
            k.fine_step,
            k.substeps,
            compile=compile,
            batch=1 if batch is None else batch,
            threads=threads,
        )
        disturbances = scenario_disturbances(sc, 1 if batch is None else batch)
        tracker = PathTracker(sc.path, sc.acceptance_radius, sc.config.path.switching, batch)
        gains = None
        if action_mode == "guidance":
            # pole placement on the nominal model's first-order Nomoto (K, T): never the truth
            gains = PIDGains.from_nomoto(*nominal_nomoto(sc))
        return cls(
            scenario=sc,
            action_mode=action_mode,
            constants=k,
            integrator=integrator,
            disturbances=disturbances,
            tracker=tracker,
            observation_space=observation_space(context_features, history_steps),
            action_space=action_space(action_mode),
            context_row=scenario_context_row(sc) if context_features else _NO_CONTEXT,
            history_steps=history_steps,
            metric_settings=metric_settings(sc),
            autopilot_gains=gains,
        )


def scenario_disturbances(scenario: Scenario, batch: int = 1) -> Disturbances:
    """The disturbance processes of ``scenario`` for ``batch`` ships."""
    return Disturbances(
        scenario.config.disturbances,
        scenario.model.disturbance_names,
        scenario.fine_step,
        scenario.substeps,
        batch=batch,
        time_limit=scenario.config.time_limit,
    )


# ---------------------------------------------------------------------------------- action
def guidance_command(
    a0: Any,
    a1: Any,
    frame: TrackFrame,
    heading: Any,
    yaw_rate: Any,
    integral: Any,
    parts: EnvParts,
    xp: Any,
) -> tuple[Any, Any]:
    """Guidance mode: ψd of the scenario's law with its length scale × 2^a0 plus a1·30°,
    then the heading PID (measured ψ [rad], r [rad/s]).  Returns (δc [rad], new integral)."""
    k = parts.constants
    desired = desired_heading(
        parts.scenario.config.guidance,
        frame.cross_track,
        frame.path_angle,
        k.ship_length,
        xp.exp2(a0),
        xp,
    )
    desired = desired + a1 * GUIDANCE_OFFSET_MAX
    return pid_step(
        parts.autopilot_gains,
        integral,
        desired,
        heading,
        yaw_rate,
        k.control_period,
        k.rudder_limit,
        xp,
    )


# ---------------------------------------------------------------------------------- plant inputs
def refresh_parameters(
    schedule: ParameterSchedule, t0: float, k: StepConstants, block: np.ndarray, dirty: bool
) -> bool:
    """Write one ship's true parameters of the period [t0, t0 + Ts] into ``block``
    (n_sub, n_p): row i at t0 + i·h while an event acts on the period, else the value at
    its end (only once after an event).  Returns the new ``dirty`` flag."""
    t1 = t0 + k.control_period
    if not schedule.is_constant_on(t0, t1):
        schedule.fill_matrix(t0, k.fine_step, block)
        return True
    if dirty:
        block[:] = schedule.vector_at(t1)
    return False


def speed_over_ground(dx: Any, dy: Any, k: StepConstants, xp: Any) -> Any:
    """U [m/s] from the displacement (dx, dy) [m] over the last substep h."""
    return xp.sqrt(dx * dx + dy * dy) / k.fine_step


# ---------------------------------------------------------------------------------- reward
def step_reward(
    cross_track: Any, heading_error: Any, delta_c: Any, prev_delta_c: Any, k: StepConstants, xp: Any
) -> Any:
    """The per-step reward from the true e [m] and ψ̃ [rad] (module doc), before bonuses."""
    q = delta_c / k.rudder_limit
    dd = (delta_c - prev_delta_c) / k.rudder_limit
    return -(
        xp.abs(cross_track) / k.ship_length
        + k.heading_weight * xp.abs(heading_error)
        + k.rudder_weight * q * q
        + k.rudder_rate_weight * dd * dd
    )


def terminate(
    reward: Any, frame: TrackFrame, steps: Any, k: StepConstants, xp: Any
) -> tuple[Any, Any, Any, Any]:
    """Goal, corridor and time limit after ``steps`` control periods (module doc).

    Returns (reward with bonus / penalty, goal, corridor, truncated).
    """
    goal = frame.at_goal
    corridor = xp.logical_not(goal) & (xp.abs(frame.cross_track) > k.max_cross_track)
    reward = xp.where(goal, reward + k.goal_bonus, reward)
    left = k.max_steps - steps
    reward = xp.where(corridor, reward - (k.max_cross_track / k.ship_length) * left, reward)
    truncated = xp.logical_not(goal | corridor) & (steps >= k.max_steps)
    return reward, goal, corridor, truncated


def diverged_reward(steps: Any, k: StepConstants) -> Any:
    """Reward of a step whose plant state went non-finite: the corridor penalty counted
    from before the step."""
    return -(k.max_cross_track / k.ship_length) * (k.max_steps - steps + 1)


# ---------------------------------------------------------------------------------- one period
@dataclasses.dataclass(slots=True)
class EnvState:
    """What an env carries from one control period to the next, besides its path tracker,
    its random streams and its plant's input blocks: one ship's (floats, ``x`` an (n_x,)
    array) or N ships' (arrays over the rows).  :func:`transition` returns a new one and
    never writes into the one it is given; a batched env's reset writes rows in place."""

    x: Any  # plant state, (n_x,) or (N, n_x) [SI]
    steps: Any  # control periods of the episode so far
    t: Any  # time [s]
    delta_c: Any  # rudder command of the last period [rad]
    psi_m: Any  # measured heading [rad]
    r_m: Any  # measured yaw rate [rad/s]
    speed: Any  # speed over ground U [m/s]
    integral: Any  # guidance mode: the heading PID's integral

    @classmethod
    def rows(cls, n: int, n_states: int, speed: float = 0.0) -> EnvState:
        """N ships' state before their first reset: zeros, each speed ``speed`` [m/s]."""
        zeros = [np.zeros(n) for _ in range(4)]
        return cls(
            np.zeros((n, n_states)),
            np.zeros(n, dtype=np.int64),
            *zeros,
            np.full(n, speed),
            np.zeros(n),
        )


@dataclasses.dataclass(slots=True)
class Period:
    """What one control period gave (:func:`transition`): one ship's floats and bools, or
    arrays over N rows (a row not stepped: reward 0, no end)."""

    frame: TrackFrame  # the path frame after the period
    heading_error: Any  # true ψ − path angle [rad]
    reward: Any
    goal: Any
    corridor: Any
    diverged: Any  # the plant state went non-finite
    truncated: Any

    @property
    def terminated(self) -> Any:
        return self.goal | self.corridor | self.diverged

    def reasons(self) -> Any:
        """The termination reason (None where the episode goes on): one ship's str or
        None, or an object array over the rows."""
        if not isinstance(self.reward, np.ndarray):
            return (
                "goal"
                if self.goal
                else "corridor"
                if self.corridor
                else "non_finite_state"
                if self.diverged
                else "time_limit"
                if self.truncated
                else None
            )
        ends = (
            ("goal", self.goal),
            ("corridor", self.corridor),
            ("non_finite_state", self.diverged),
            ("time_limit", self.truncated),
        )
        reasons = np.full(self.reward.shape, None, dtype=object)
        for reason, end in ends:
            reasons[end] = reason
        return reasons


def rudder_command(
    action: Any, state: EnvState, frame: TrackFrame, parts: EnvParts, xp: Any
) -> tuple[Any, Any]:
    """The rudder command δc [rad] of ``action`` and the heading PID's new integral: in
    rudder mode δc = a0·δmax (the integral unchanged), in guidance mode
    :func:`guidance_command` from the path ``frame`` at the period's start."""
    a0 = xp.column(action, 0)
    if parts.action_mode == "rudder":
        return a0 * parts.constants.rudder_limit, state.integral
    return guidance_command(
        a0, xp.column(action, 1), frame, state.psi_m, state.r_m, state.integral, parts, xp
    )


def transition(
    state: EnvState,
    action: Any,
    live: Any,
    k: StepConstants,
    xp: Any,
    command: Callable[[Any, EnvState, Any], tuple[Any, Any]],
    plant: Callable[[EnvState, Any, Any], np.ndarray],
    measure: Callable[[np.ndarray, EnvState, EnvState, Any], tuple[Any, Any]],
    tracker: Any,
) -> tuple[EnvState, Period]:
    """One control period of every env: the new state and what the period gave, for one
    ship (``xp = SCALAR``, ``live = True``) or the ``live`` rows of N (``xp = ARRAY``, a
    mask; the other rows keep their state and get reward 0).  ``action``: checked and
    clipped, one ship's floats or (N, n_act).  ``k.max_steps`` may be an array (each row's
    time limit).

    The env supplies what draws random numbers, holds buffers or follows a path, called in
    this order: ``command(action, state, live)`` → (δc [rad], PID integral), e.g.
    :func:`rudder_command`; ``plant(state, δc, live)`` sets the period's true parameters
    and disturbances and integrates the plant → the states at the substep ends, (...,
    n_sub, n_x) (one ship's may start with the period's start); ``measure(trajectory,
    state, new, advance)`` → the measured (ψ, r) of the ``advance`` rows, given the new
    state whose ``psi_m``, ``r_m`` hold their true values at the period's end (the other
    rows': their last measurement; never written into); ``tracker``
    (``frame``, ``update(x, y, mask=None)``) follows the path.  A row whose plant state
    ends non-finite keeps its state, measurements and frame, and ends with
    :func:`diverged_reward`.  While every row steps and stays finite no masked selection
    is made (a step's fixed cost is its numpy calls).
    """
    every = xp.all(live)
    delta_c, integral = command(action, state, live)
    if not every:
        delta_c = xp.where(live, delta_c, state.delta_c)
        integral = xp.where(live, integral, state.integral)
    trajectory = plant(state, delta_c, live)
    last = trajectory[..., -1, :]
    finite = xp.all_finite(last)
    moved = every and xp.all(finite)  # every row advances
    advance = live if moved else live & finite
    steps = state.steps + 1
    if every:
        t = steps * k.control_period
    else:
        steps = xp.where(live, steps, state.steps)
        t = xp.where(live, steps * k.control_period, state.t)
    x = last.copy() if moved else xp.where_rows(advance, last, state.x)
    px, py, heading, yaw_rate = xp.columns(x, (k.ix, k.iy, k.ipsi, k.ir))  # true, at the end
    speed = state.speed
    if k.substeps > 1:  # U over the last substep
        bx, by = xp.columns(trajectory[..., -2, :], (k.ix, k.iy))
        speed = speed_over_ground(px - bx, py - by, k, xp)
        if not moved:
            speed = xp.where(advance, speed, state.speed)
    if moved:
        psi, r = heading, yaw_rate
    else:  # the rows that do not advance keep their last measurement
        psi, r = xp.where(advance, heading, state.psi_m), xp.where(advance, yaw_rate, state.r_m)
    new = EnvState(x, steps, t, delta_c, psi, r, speed, integral)
    new.psi_m, new.r_m = measure(trajectory, state, new, advance)
    if moved:
        frame = tracker.update(px, py)
    else:
        frame = tracker.update(px, py, advance) if xp.any(advance) else tracker.frame
    heading_error = wrap_angle(heading - frame.path_angle)
    reward = step_reward(frame.cross_track, heading_error, delta_c, state.delta_c, k, xp)
    reward, goal, corridor, truncated = terminate(reward, frame, steps, k, xp)
    if moved:
        diverged = xp.logical_not(live)  # none
        return new, Period(frame, heading_error, reward, goal, corridor, diverged, truncated)
    diverged = live & xp.logical_not(finite)
    reward = xp.where(diverged, diverged_reward(steps, k), reward)
    return new, Period(
        frame=frame,
        heading_error=heading_error,
        reward=xp.where(live, reward, 0.0),
        goal=goal & advance,
        corridor=corridor & advance,
        diverged=diverged,
        truncated=truncated & advance,
    )


# ---------------------------------------------------------------------------------- observation
def observation_columns(
    frame: TrackFrame,
    heading: Any,
    yaw_rate: Any,
    rudder_angle: Any,
    rudder_command: Any,
    speed: Any,
    k: StepConstants,
    xp: Any,
) -> tuple[Any, ...]:
    """The 9 observation entries (OBS_NAMES) from measurements (ψ, r) and the frame.

    0 e/e_max, 1–2 sin/cos of ψ − ψp, 3 r/(2u0/L), 4 δ/δmax, 5 last δc/δmax, 6 U/u0,
    7 path-angle change to the next leg /π, 8 d_next/(d_next + 10L); clipped by the caller.
    """
    err = heading - frame.path_angle
    d = frame.distance_to_next
    return (
        frame.cross_track / k.max_cross_track,
        xp.sin(err),
        xp.cos(err),
        yaw_rate / (2.0 * k.nominal_speed / k.ship_length),
        rudder_angle / k.rudder_limit,
        rudder_command / k.rudder_limit,
        speed / k.nominal_speed,
        frame.angle_change_next / math.pi,
        d / (d + 10.0 * k.ship_length),
    )


def reseed_rows(
    rngs: list[np.random.Generator | None],
    seed: int | list[int | None] | None,
    options: dict | None,
) -> np.ndarray:
    """A batched env's ``reset(seed=…, options=…)`` arguments applied to its per-env
    generators ``rngs`` (in place), as SyncVectorEnv does: an int seeds env i with
    ``seed + i``, a list one seed per env, None keeps a seeded generator (and seeds a
    missing one from entropy); ``options["reset_mask"]`` resets only the masked envs.
    Returns the mask of the envs to reset."""
    n = len(rngs)
    if seed is None or isinstance(seed, int):
        seeds = [None if seed is None else seed + i for i in range(n)]
    else:
        if len(seed) != n:
            raise ValueError(f"need {n} seeds, got {len(seed)}")
        seeds = list(seed)
    mask = np.ones(n, dtype=bool)
    if options and "reset_mask" in options:  # as SyncVectorEnv: reset only these envs
        mask = np.asarray(options["reset_mask"], dtype=bool)
        if mask.shape != (n,):
            raise ValueError(f"reset_mask must have shape ({n},)")
    for i, s in enumerate(seeds):
        if mask[i] and (s is not None or rngs[i] is None):
            rngs[i], _ = seeding.np_random(s)
    return mask


def batch_observation(
    frame: TrackFrame,
    heading: np.ndarray,
    yaw_rate: np.ndarray,
    rudder_angle: np.ndarray,
    rudder_command: np.ndarray,
    speed: np.ndarray,
    k: StepConstants,
    context: np.ndarray | None = None,
) -> np.ndarray:
    """The (N, 9) float32 observations of N envs (:func:`observation_columns` on arrays,
    clipped to the observation bounds), with ``context`` ((N, C) or (C,): the
    controller-context features, float32) appended when given: the batched envs' one
    observation."""
    columns = observation_columns(
        frame, heading, yaw_rate, rudder_angle, rudder_command, speed, k, ARRAY
    )
    obs = np.stack(columns, axis=1).astype(np.float32)
    obs.clip(OBS_LOW, OBS_HIGH, out=obs)
    if context is None:
        return obs
    return np.concatenate(
        [obs, np.broadcast_to(context, (obs.shape[0], context.shape[-1]))], axis=1
    )


def history_window(window: np.ndarray, previous: np.ndarray, current: np.ndarray) -> np.ndarray:
    """The history window (..., K·HISTORY_WIDTH), oldest step first, advanced by the control
    step from the observation ``previous`` to ``current`` (..., ≥ 9; their first 9 entries
    are read): the oldest step dropped, the new step appended as the newest, its
    :data:`HISTORY_MEASUREMENTS` from ``previous`` (the step's start) and its applied
    command from ``current``'s ``last_rudder_command``.  The one definition of the window's
    layout (docs/observation.md)."""
    step = np.concatenate(
        [previous[..., _HISTORY_MEASURED], current[..., _APPLIED : _APPLIED + 1]], axis=-1
    )
    return np.concatenate([window[..., HISTORY_WIDTH:], step.astype(window.dtype)], axis=-1)


class ObservationHistory:
    """The history windows of N rows (episodes), float32 (N, K·HISTORY_WIDTH): what every
    env with ``history_steps=K > 0`` and the learned-policy adapter keep.

    A row marked by :meth:`restart` (its episode started) gets an all-zero window at its
    next :meth:`update`; a row marked by :meth:`stepped` (it advanced one control period)
    gets its window advanced by :func:`history_window` from its last seen observation to
    the new one.  An unmarked row keeps its window, so an update is idempotent.
    """

    def __init__(self, n_rows: int, history_steps: int) -> None:
        self.history_steps = history_steps
        self.window = np.zeros((n_rows, HISTORY_WIDTH * self.history_steps), dtype=np.float32)
        #: each row's observation at its last update (the start of its pending step)
        self._last = np.zeros((n_rows, len(OBS_NAMES)), dtype=np.float32)
        self._restart = np.ones(n_rows, dtype=bool)
        self._stepped = np.zeros(n_rows, dtype=bool)

    def restart(self, rows: Any = slice(None)) -> None:
        """Rows (mask, indices or slice) whose episode starts: zeros at the next update."""
        self._restart[rows] = True
        self._stepped[rows] = False

    def stepped(self, rows: Any = slice(None)) -> None:
        """Rows (mask, indices or slice) that advanced one control period."""
        self._stepped[rows] = True

    def update(self, obs: np.ndarray, rows: Any = None) -> np.ndarray:
        """The windows after the marked events, given the rows' new observations ``obs``
        (one row each, of ``rows``: indices, None for all); returns those rows' windows."""
        base = np.asarray(obs)[:, : len(OBS_NAMES)]
        if rows is None and self._stepped.all() and not self._restart.any():
            # every row stepped (a training env's usual step): no gathers
            self.window = history_window(self.window, self._last, base)
            self._last = base.astype(np.float32, copy=True)
            self._stepped[:] = False
            return self.window
        idx = np.arange(len(self.window)) if rows is None else np.asarray(rows, dtype=np.intp)
        start = self._restart[idx]
        step = self._stepped[idx] & ~start
        if step.any():
            moved = idx[step]
            self.window[moved] = history_window(self.window[moved], self._last[moved], base[step])
        if start.any():
            self.window[idx[start]] = 0.0
        seen = start | step
        self._last[idx[seen]] = base[seen]
        self._restart[idx] = False
        self._stepped[idx] = False
        return self.window[idx]

    def append(self, obs: np.ndarray, rows: Any = None) -> np.ndarray:
        """``obs`` (one row each of ``rows``) with the rows' updated windows after it."""
        return np.concatenate([obs, self.update(obs, rows)], axis=1)


def context_columns(
    gain: float,
    time_constant: float,
    ship_length: float,
    nominal_speed: float,
    control_period: float,
    rudder_limit: float,
) -> tuple[float, ...]:
    """The 7 context features (CONTEXT_NAMES) from the nominal first-order Nomoto model
    K [1/s], T [s], the ship length L [m], nominal speed U0 [m/s], control period Ts [s] and
    rudder limit δmax [rad]; each scaled into [0, 2] over the suite's ships (clipped by the
    caller; docs/observation.md):

    0 K'/2 = K·L/U0 / 2, 1 T'/2 = T·U0/L / 2 (Nomoto's non-dimensional gain and time
    constant), 2 log10(T/Ts)/2 (T in control periods), 3 log10(L / 0.1 m)/4,
    4 log10(U0 / 0.1 m/s)/2, 5 2·Ts·U0/L (ship lengths run per control period),
    6 δmax / (π/4).
    """
    length_time = ship_length / nominal_speed  # L/U0 [s]
    return (
        gain * length_time / 2.0,
        time_constant / length_time / 2.0,
        math.log10(max(time_constant / control_period, 1.0)) / 2.0,
        math.log10(max(ship_length / 0.1, 1.0)) / 4.0,
        math.log10(max(nominal_speed / 0.1, 1.0)) / 2.0,
        2.0 * control_period / length_time,
        rudder_limit / (math.pi / 4.0),
    )


def scenario_context_row(scenario: Scenario) -> np.ndarray:
    """The context features of a scenario (float32, clipped): from its *nominal* model and
    timing only (:func:`context_columns`), so that trials differing only in their true
    parameters or event schedule give the same row."""
    sc = scenario
    gain, time_constant = nominal_nomoto(sc)
    row = np.array(
        context_columns(
            gain,
            time_constant,
            sc.ship_length,
            sc.model.nominal_speed,
            sc.control_period,
            sc.model.rudder_limit,
        ),
        dtype=np.float32,
    )
    return np.clip(row, CONTEXT_LOW, CONTEXT_HIGH, out=row)


_NO_CONTEXT = np.zeros(0, dtype=np.float32)


def info_values(
    t: Any,
    frame: TrackFrame,
    heading: Any,
    yaw_rate: Any,
    rudder_angle: Any,
    rudder_command: Any,
    position: Any,
) -> dict[str, Any]:
    """The per-step ``info`` keys (measured ψ and r; e and the leg from the tracker)."""
    return {
        "t": t,
        "cross_track_error": frame.cross_track,
        "heading_error": wrap_angle(heading - frame.path_angle),
        "heading": heading,
        "yaw_rate": yaw_rate,
        "rudder_angle": rudder_angle,
        "rudder_command": rudder_command,
        "position": position,
        "waypoint_index": frame.leg,
    }


def episode_log(
    columns: dict[str, np.ndarray], scenario: Scenario, reached_goal: bool
) -> EpisodeLog:
    """The metrics' episode log from the LOG_FIELDS columns of one ship."""
    return EpisodeLog(
        **columns,
        change_time=scenario.change_time,
        ship_length=scenario.ship_length,
        reached_goal=reached_goal,
        goal_bonus=scenario.config.reward.goal_bonus,
        dt=scenario.control_period,
    )


def metric_settings(scenario: Scenario) -> MetricSettings:
    """The episode metrics' settings of ``scenario`` (its convergence threshold)."""
    return MetricSettings(convergence_threshold=scenario.config.convergence_threshold)


def check_action(action: Any, shape: tuple[int, ...]) -> np.ndarray:
    """One env's action as a float64 array of ``shape``, not clipped; ValueError naming
    what is wrong if it is not numbers of that shape or holds NaN or inf."""
    try:
        if action is None:  # numpy reads None as NaN
            raise TypeError("None is no number")
        values = np.asarray(action, dtype=np.float64).reshape(shape)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"action must be an array of shape {shape}, got {action!r}") from exc
    if not all(map(math.isfinite, values.ravel().tolist())):
        raise ValueError(f"action contains NaN or inf: {action!r}; the env state is unchanged")
    return values


def batch_actions(actions: Any, shape: tuple[int, ...]) -> np.ndarray:
    """A batched env's actions (n_envs, n_act) as float64, clipped to [-1, 1]; NaN or inf
    in any env's row is an error naming those envs (before anything steps)."""
    a = np.asarray(actions, dtype=np.float64).reshape(shape)
    finite = np.isfinite(a)
    if not finite.all():
        bad = ~finite.all(axis=1)
        raise ValueError(
            f"actions of envs {np.flatnonzero(bad).tolist()} contain NaN or inf; "
            "the env state is unchanged"
        )
    return np.clip(a, -1.0, 1.0)
