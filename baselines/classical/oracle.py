"""``oracle``: the privileged reference — NMPC on the true plant (issue 17).

What is achievable on a scenario when the plant is known.  At every control step the oracle
reads, through the evaluation loop's privileged channel (:mod:`baselines.privileged`; no
other controller can reach it), the true state, the true parameters acting now (after every
jump so far, never the future schedule) and the disturbance forecast of
:class:`shipgym.envs.truth.PlantTruth` (the deterministic current ahead, the present
stochastic deviation held).  It is a reference (``kind = "reference"``): shown on every
scenario, never ranked; its costs are the denominator of the leaderboard's cost ratio.

**Model.**  The env's own model: the ship's one right-hand side (:meth:`ShipModel.rhs`, its
CasADi form) with the true parameter vector and the disturbance inputs, integrated by RK4
at the prediction step h_p (below), rudder servo, rate and angle limits included.

**Objective.**  The env's own stage cost (:func:`shipgym.envs.core.step_reward`), summed
over the control steps of the horizon:

    Σ_k  |e_k|/L + w_ψ|ψ̃_k| + w_δ (δc_k/δmax)² + w_Δ ((δc_k − δc_{k−1})/δmax)²

with |·| smoothed as √(z² + ε²) (ε = ``smooth_abs``), e and ψ̃ measured as the env measures
them: to the active leg, which switches to the next at the along-track point ℓ − R0 of the
env's switching rule (smoothly, over ``switch_width_L``·L); a PCHIP route enters as its
chords ahead of the closest point.

**Horizon rule.**  H = 2(T + L/U) + δmax/δ̇max: two of the ship's yaw time constants T (its
first-order Nomoto T of the nominal model, the one the classical controllers use) to
settle a turn, two ship-length transit times L/U to come back to the path, plus the time
the rudder needs to travel its range at its rate limit (0 without a rate limit).  Per ship:
nomoto2 ≈ 5.3 s, Esso Osaka (1:100) ≈ 32 s, Mariner ≈ 140 s, Blanke ≈ 26 s.

**Decisions and grid.**  Move blocking: the first command acts for one control period Ts
(the one applied); the horizon's rest is split into ``blocks`` equal intervals of m·Ts
(m = ⌈(H/Ts − 1)/blocks⌉), one command each.  The stage cost is evaluated at every control
step end, as the env does.  Prediction step h_p = Ts/n with n the smallest integer such that
h_p·|λ_max| ≤ 1 (λ_max the fastest eigenvalue of the model linearised at cruise: RK4
accurate and stable), never finer than the env's own h.

**Solver.**  Generalised Gauss–Newton SQP (Messerer, Baumgärtner & Diehl 2021): the cost
is Σ φ_i(z_i(u)) with convex outer φ (smooth |·| or square) of a smooth inner z; each
iteration solves the box QP with H = Jᵀ diag(φ'') J, g = Jᵀ φ' (:class:`BoxQP`), then a
backtracking line search on the cost; warm-started from the shifted previous plan.  z and
J = ∂z/∂u are one CasADi function compiled to C (cached, :mod:`shipgym.codegen`).
"""

from __future__ import annotations

import dataclasses
import math
import time
from typing import Any, ClassVar

import casadi as ca
import numpy as np

from baselines.classical.box_qp import BoxQP
from baselines.errors import ControllerError
from baselines.registry import register_controller
from shipgym.codegen import compiled
from shipgym.envs.context import ControllerContext
from shipgym.envs.truth import PlantTruth
from shipgym.identification import first_order_nomoto
from shipgym.models.base import ShipModel


@dataclasses.dataclass(frozen=True)
class OracleSettings:
    """Numerical choices of the oracle (module doc); the objective is the env's."""

    horizon_factor: float = 2.0  # k in H = k(T + L/U) + δmax/δ̇max
    blocks: int = 20  # command intervals after the first (move blocking)
    legs: int = 4  # path segments ahead in the prediction
    smooth_abs: float = 1e-3  # ε of √(z² + ε²) on e/L and ψ̃ [rad]
    switch_width_L: float = 0.25  # width of the smooth leg switch [L]
    max_iter: int = 10  # generalised Gauss–Newton iterations per control step
    step_tolerance: float = 1e-4  # rad: stop when the accepted step is smaller
    cost_tolerance: float = 1e-3  # stop when an iteration lowers the cost by less (relative)
    compile: bool = True  # compile z and its Jacobian to C (cached); VM otherwise


@dataclasses.dataclass(frozen=True)
class OracleGrid:
    """The time grid of one ship's prediction (module doc), all in control periods Ts."""

    horizon_s: float  # H [s]
    block: int  # m: control periods per interval after the first
    blocks: int  # intervals after the first
    substeps: int  # RK4 steps per control period (h_p = Ts / substeps)

    @property
    def steps(self) -> int:
        """Control steps in the horizon."""
        return 1 + self.block * self.blocks

    @property
    def lengths(self) -> list[int]:
        """Control periods of each command interval."""
        return [1] + [self.block] * self.blocks


def horizon_seconds(
    time_constant: float, length: float, speed: float, limit: float, rate: float, k: float = 2.0
) -> float:
    """H = k(T + L/U) + δmax/δ̇max [s] (module doc); T [s], L [m], U [m/s], δmax [rad],
    δ̇max [rad/s] (inf: no rate limit)."""
    travel = limit / rate if math.isfinite(rate) and rate > 0 else 0.0
    return k * (time_constant + length / speed) + travel


def prediction_substeps(model: ShipModel, control_period: float, fine_step: float) -> int:
    """n: RK4 steps per control period, the smallest with (Ts/n)·|λ_max| ≤ 2 at cruise (RK4
    is stable to 2.79 on the negative real axis), at most Ts/h (never finer than the env's
    own step)."""
    x = ca.SX.sym("x", model.n_states)
    jac = ca.Function("a", [x], [ca.jacobian(model.casadi_rhs(x, 0.0, 0.0, model.params.to_vector()), x)])
    a = np.array(jac(model.cruise_state()))
    fastest = float(np.max(np.abs(np.linalg.eigvals(a)))) if a.size else 0.0
    most = max(1, round(control_period / fine_step))
    return int(min(most, max(1, math.ceil(0.5 * control_period * fastest - 1e-9))))


def oracle_grid(context: ControllerContext, settings: OracleSettings) -> OracleGrid:
    """The grid of ``context``'s ship (module doc), from its nominal model."""
    model = context.nominal_model
    _, time_constant = first_order_nomoto(model, context.nominal_params)
    h = horizon_seconds(
        time_constant,
        context.ship_length,
        context.nominal_speed,
        context.rudder_limit,
        model.rudder_rate_limit,
        settings.horizon_factor,
    )
    ts = context.control_period
    block = max(1, math.ceil((h / ts - 1.0) / settings.blocks))
    substeps = prediction_substeps(model, ts, context.fine_step)
    return OracleGrid(horizon_s=h, block=block, blocks=settings.blocks, substeps=substeps)


def _smooth_step(z: Any) -> Any:
    return 0.5 * (1.0 + ca.tanh(z))


def _period_function(model: ShipModel, hp: float, substeps: int) -> ca.Function:
    """x(t + Ts) from x(t): ``substeps`` RK4 steps of h_p [s] with u, w, θ held (SX)."""
    step = model.casadi_step(hp)
    x = ca.SX.sym("x", model.n_states)
    u = ca.SX.sym("u")
    w = ca.SX.sym("w", model.n_disturbances)
    theta = ca.SX.sym("theta", model.n_params)
    xk = x
    for _ in range(substeps):
        xk = step(xk, u, w, theta)
    return ca.Function("oracle_period", [x, u, w, theta], [xk])


def _stage_function(model: ShipModel, n_legs: int, width: float, length: float) -> ca.Function:
    """[e/L, ψ̃ [rad]] of a state to the active leg of ``n_legs`` (x0, y0, c, s, ℓ), switched
    smoothly at ℓ − R0 over ``width`` [m] (module doc)."""
    x = ca.SX.sym("x", model.n_states)
    legs = ca.SX.sym("legs", 5 * n_legs)
    switch_radius = ca.SX.sym("R0")
    px, py = x[model.state_index("x")], x[model.state_index("y")]
    psi = x[model.state_index("psi")]
    e_sum, h_sum = 0.0, 0.0
    reached = 1.0  # product of the earlier legs' switch indicators
    for j in range(n_legs):
        x0, y0, c, s, ell = (legs[5 * j + i] for i in range(5))
        rx, ry = px - x0, py - y0
        if j == n_legs - 1:
            weight = reached
        else:
            passed = _smooth_step((rx * c + ry * s - (ell - switch_radius)) / width)
            weight = reached * (1.0 - passed)
            reached = reached * passed
        e_sum += weight * (-rx * s + ry * c)
        h_sum += weight * ca.atan2(
            ca.sin(psi) * c - ca.cos(psi) * s, ca.cos(psi) * c + ca.sin(psi) * s
        )
    return ca.Function("oracle_stage", [x, legs, switch_radius], [ca.vertcat(e_sum / length, h_sum)])


def _sensitivity_function(period: ca.Function, n_u: int) -> ca.Function:
    """(x, S, u, w, θ, e) -> (x⁺, A·S + B·eᵀ): one period with the forward sensitivity
    S = ∂x/∂(plan) [nx × n_u]; A = ∂x⁺/∂x, B = ∂x⁺/∂u, e the one-hot of the step's interval."""
    x = ca.SX.sym("x", period.size1_in(0))
    sens = ca.SX.sym("S", period.size1_in(0), n_u)
    u = ca.SX.sym("u")
    w = ca.SX.sym("w", period.size1_in(2))
    theta = ca.SX.sym("theta", period.size1_in(3))
    onehot = ca.SX.sym("e", n_u)
    xn = period(x, u, w, theta)
    a, b = ca.jacobian(xn, x), ca.jacobian(xn, u)
    return ca.Function(
        "oracle_period_s", [x, sens, u, w, theta, onehot], [xn, a @ sens + b @ onehot.T]
    )


def _stage_jacobian_function(stage: ca.Function, n_u: int) -> ca.Function:
    """(x, S, legs, R0) -> (g(x), ∂g/∂x · S): the stage errors and their plan derivatives."""
    x = ca.SX.sym("x", stage.size1_in(0))
    sens = ca.SX.sym("S", stage.size1_in(0), n_u)
    legs = ca.SX.sym("legs", stage.size1_in(1))
    radius = ca.SX.sym("R0")
    g = stage(x, legs, radius)
    return ca.Function(
        "oracle_stage_s", [x, sens, legs, radius], [g, ca.jacobian(g, x) @ sens]
    )


class OracleSolver:
    """The oracle's problem for one model class, grid, timing and reward weights (built
    once per process): inner residuals z(u; p) and J = ∂z/∂u, the outer φ, the GGN SQP."""

    def __init__(
        self,
        model: ShipModel,
        grid: OracleGrid,
        settings: OracleSettings,
        control_period: float,
        rudder_limit: float,
        weights: tuple[float, float, float],
        length: float,
    ) -> None:
        s = settings
        self.grid, self.settings = grid, settings
        self.rudder_limit = rudder_limit
        nx, npar, nw = model.n_states, model.n_params, model.n_disturbances
        n_u = 1 + grid.blocks
        n_legs = s.legs
        hp = control_period / grid.substeps
        period = _period_function(model, hp, grid.substeps)
        stage = _stage_function(model, n_legs, s.switch_width_L * length, length)
        steps = grid.steps
        interval = [j for j, n in enumerate(grid.lengths) for _ in range(n)]  # per step
        u = ca.MX.sym("u", n_u)
        # parameters: x0, δc_prev, switch radius R0, legs (x0, y0, c, s, ℓ) each, θ, w per interval
        n_p = nx + 2 + 5 * n_legs + npar + nw * n_u
        p = ca.MX.sym("p", n_p)
        x0, u_prev, switch_radius = p[:nx], p[nx], p[nx + 1]
        legs = p[nx + 2 : nx + 2 + 5 * n_legs]
        theta = p[nx + 2 + 5 * n_legs : nx + 2 + 5 * n_legs + npar]
        w_all = ca.reshape(p[nx + 2 + 5 * n_legs + npar :], nw, n_u)
        # the control steps of the horizon in one C loop (mapaccum), their errors mapped;
        # J by forward sensitivities S = ∂x/∂u carried along (S⁺ = A·S + B·e_jᵀ)
        inputs = (u[interval].T, w_all[:, interval], ca.repmat(theta, 1, steps))
        onehot = ca.DM.zeros(n_u, steps)
        for k, j in enumerate(interval):
            onehot[j, k] = 1.0
        states = period.mapaccum("roll", steps)(x0, *inputs)
        errors = stage.map(steps)(
            states, ca.repmat(legs, 1, steps), ca.repmat(switch_radius, 1, steps)
        )
        sens_period = _sensitivity_function(period, n_u)
        sens_stage = _stage_jacobian_function(stage, n_u)
        states_s, sens = sens_period.mapaccum("roll_s", steps, 2)(
            x0, ca.DM.zeros(nx, n_u), *inputs, onehot
        )
        errors_s, d_errors = sens_stage.map(steps)(
            states_s, sens, ca.repmat(legs, 1, steps), ca.repmat(switch_radius, 1, steps)
        )
        z_u = u / rudder_limit
        z_du = ca.vertcat(u[0] - u_prev, u[1:] - u[:-1]) / rudder_limit
        z = ca.vertcat(errors[0, :].T, errors[1, :].T, z_u, z_du)
        z_s = ca.vertcat(errors_s[0, :].T, errors_s[1, :].T, z_u, z_du)
        eye = np.eye(n_u) / rudder_limit
        diff = (np.eye(n_u) - np.eye(n_u, k=-1)) / rudder_limit
        jac = ca.vertcat(
            ca.reshape(d_errors[0, :], n_u, steps).T,
            ca.reshape(d_errors[1, :], n_u, steps).T,
            eye,
            diff,
        )
        w_psi, w_delta, w_rate = weights
        # outer weights and kinds: smooth |·| for e/L and ψ̃, squares for the rudder terms
        self.weight = np.concatenate(
            [
                np.ones(steps),
                np.full(steps, w_psi),
                w_delta * np.array(grid.lengths, dtype=float),
                np.full(n_u, w_rate),
            ]
        )
        self.is_abs = np.concatenate([np.ones(2 * steps, bool), np.zeros(2 * n_u, bool)])
        self.n_z, self.n_u, self.n_p = z.shape[0], n_u, n_p
        self.layout = (nx, n_legs, npar, nw)
        tag = (
            f"{model.name}_b{grid.blocks}x{grid.block}_s{grid.substeps}_l{n_legs}"
            f"_{abs(hash((control_period, rudder_limit, weights, length, s))) % 10**8}"
        )
        value = ca.Function(f"oracle_z_{tag}", [u, p], [z])
        both = ca.Function(f"oracle_zj_{tag}", [u, p], [z_s, ca.densify(jac)])
        if s.compile:
            value, both = compiled(value), compiled(both)
        self._u = np.zeros(n_u)
        self._p = np.zeros(n_p)
        self._z = np.zeros(self.n_z)
        self._j = np.zeros((n_u, self.n_z))  # column-major J
        self._value = _bind(value, self._u, self._p, [self._z])
        self._both = _bind(both, self._u, self._p, [self._z, self._j])
        self._keep = (value, both)
        self.lb = np.full(n_u, -rudder_limit)
        self.ub = np.full(n_u, rudder_limit)
        self._qp = BoxQP(n_u)

    # ---------------------------------------------------------------- cost and SQP
    def _outer(self, z: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
        """Σφ(z), φ'(z), φ''(z) (weighted)."""
        eps = self.settings.smooth_abs
        root = np.sqrt(z * z + eps * eps)
        value = np.where(self.is_abs, root, z * z)
        d1 = np.where(self.is_abs, z / root, 2.0 * z)
        # |·| terms: the curvature of the quadratic majoriser at z (IRLS), 1/√(z² + ε²), not
        # φ'' = ε²/(z² + ε²)^{3/2}, which vanishes away from 0 (the steps would overshoot)
        d2 = np.where(self.is_abs, 1.0 / root, 2.0)
        w = self.weight
        with np.errstate(over="ignore", invalid="ignore"):
            total = float(w @ value)
        return (total if math.isfinite(total) else math.inf), w * d1, w * d2

    def cost(self, plan: np.ndarray, p: np.ndarray) -> float:
        """The predicted objective of ``plan`` (inf if the prediction diverges)."""
        self._u[:], self._p[:] = plan, p
        self._value[1]()
        return self._outer(self._z)[0]

    def solve(self, p: np.ndarray, guess: np.ndarray) -> tuple[np.ndarray, bool, int]:
        """Plan (one command per interval, rad), success flag, iterations."""
        self.iterations = getattr(self, "iterations", [])
        u = np.clip(guess, self.lb, self.ub)
        self._p[:] = p
        cost = self.cost(u, p)
        if not math.isfinite(cost):
            return u, False, 0
        iterations = 0
        for iterations in range(1, self.settings.max_iter + 1):
            self._u[:] = u
            self._both[1]()
            z, jac = self._z, self._j.T
            if not (np.all(np.isfinite(z)) and np.all(np.isfinite(jac))):
                return u, False, iterations
            _, d1, d2 = self._outer(z)
            step = self._qp.solve((jac.T * d2) @ jac, jac.T @ d1, self.lb - u, self.ub - u)
            alpha = 1.0
            while alpha > 1e-3:  # backtracking on the cost
                trial = np.clip(u + alpha * step, self.lb, self.ub)
                trial_cost = self.cost(trial, p)
                if trial_cost <= cost:
                    break
                alpha *= 0.5
            else:
                break  # no descent along the GGN step: converged as far as it goes
            moved = float(np.max(np.abs(trial - u)))
            gain = cost - trial_cost
            u, cost = trial, trial_cost
            if moved < self.settings.step_tolerance or gain <= self.settings.cost_tolerance * cost:
                break
        self.iterations.append(iterations)
        return u, math.isfinite(cost), iterations

    def parameters(
        self,
        state: np.ndarray,
        previous_command: float,
        switch_radius: float,
        legs: np.ndarray,
        theta: np.ndarray,
        disturbances: np.ndarray,
    ) -> np.ndarray:
        """The solver's parameter vector; ``legs`` (legs, 5) rows (x0, y0, c, s, ℓ),
        ``disturbances`` (intervals, n_w)."""
        return np.concatenate(
            [state, [previous_command, switch_radius], legs.ravel(), theta, disturbances.ravel()]
        )


def _bind(function: ca.Function, u: np.ndarray, p: np.ndarray, outputs: list[np.ndarray]):
    buffer, evaluate = function.buffer()
    buffer.set_arg(0, memoryview(u))
    buffer.set_arg(1, memoryview(p))
    for i, out in enumerate(outputs):
        buffer.set_res(i, memoryview(out))
    return buffer, evaluate


_SOLVERS: dict[tuple, OracleSolver] = {}


def get_solver(context: ControllerContext, settings: OracleSettings, weights) -> OracleSolver:
    """One solver per process for a ship class, grid, timing and reward weights."""
    grid = oracle_grid(context, settings)
    model = context.nominal_model
    key = (type(model).__name__, model.variant, context.ship_length, grid, settings,
           context.control_period, context.rudder_limit, weights)
    if key not in _SOLVERS:
        _SOLVERS[key] = OracleSolver(
            model, grid, settings, context.control_period, context.rudder_limit, weights,
            context.ship_length,
        )
    return _SOLVERS[key]


def legs_ahead(context: ControllerContext, tracker: Any, frame: Any, horizon_m: float, n: int):
    """(n, 5) legs (x0, y0, c, s, ℓ) from the active one on: the waypoint legs (the last one
    extended past the goal), or the chords of a PCHIP route ahead of the closest point."""
    rows = []
    if tracker.is_curve:
        path = tracker.path
        ds = 1.3 * horizon_m / n
        s0 = float(frame.along_track)
        points = [np.asarray(path.point(min(s0 + i * ds, path.length))) for i in range(n + 1)]
        if s0 + n * ds > path.length:  # past the end: continue along the final tangent
            angle = float(path.angle(path.length))
            end = np.asarray(path.point(path.length))
            points = [
                p if s0 + i * ds <= path.length
                else end + (s0 + i * ds - path.length) * np.array([math.cos(angle), math.sin(angle)])
                for i, p in enumerate(points)
            ]
        for a, b in zip(points[:-1], points[1:], strict=True):
            d = b - a
            ell = float(np.hypot(*d))
            if ell < 1e-9:
                angle = float(path.angle(path.length))
                d, ell = np.array([math.cos(angle), math.sin(angle)]), 1.0
            rows.append([a[0], a[1], d[0] / ell, d[1] / ell, ell])
        return np.array(rows), 0.0
    wp = context.waypoints
    last = len(wp) - 2  # the env never leaves the last leg
    for j in range(int(frame.leg), int(frame.leg) + n):
        i = min(j, last)
        d = wp[i + 1] - wp[i]
        ell = float(np.hypot(*d))
        rows.append([wp[i][0], wp[i][1], d[0] / ell, d[1] / ell, 1e6 if i == last else ell])
    return np.array(rows), context.acceptance_radius


@register_controller("oracle")
class Oracle:
    """``oracle``: NMPC on the true plant through the privileged channel (module doc)."""

    name: ClassVar[str]  # set by the registration
    kind: ClassVar[str] = "reference"

    def __init__(self, settings: OracleSettings | None = None) -> None:
        self.settings = settings if settings is not None else OracleSettings()
        self._truth = None

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        raise ControllerError(
            "oracle reads the true plant through the evaluation loop's privileged channel, "
            "which only the built-in oracle run by its name 'oracle' receives; it cannot run "
            "as an instance, a spec or under another name"
        )

    def reset_privileged(
        self, context: ControllerContext, truth: Any, seed: int | None = None
    ) -> None:
        """Start an episode; ``truth()`` returns the :class:`PlantTruth` now."""
        self.ctx = context
        self._truth = truth
        reward = context.reward
        self.weights = (reward.heading_weight, reward.rudder_weight, reward.rudder_rate_weight)
        self.solver = get_solver(context, self.settings, self.weights)
        self.tracker = context.new_tracker()
        self._started = False
        self.plan = np.zeros(self.solver.n_u)
        self.command = 0.0
        self.failures = 0
        self.solve_times: list[float] = []

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        if self._truth is None:
            raise ControllerError("oracle: reset_privileged() first (the privileged channel)")
        truth: PlantTruth = self._truth()
        ctx, grid = self.ctx, self.solver.grid
        model = ctx.nominal_model
        px = float(truth.state[model.state_index("x")])
        py = float(truth.state[model.state_index("y")])
        frame = self.tracker.update(px, py) if self._started else self.tracker.reset(px, py)
        self._started = True
        legs, radius = legs_ahead(
            ctx, self.tracker, frame, grid.horizon_s * ctx.nominal_speed, self.settings.legs
        )
        starts = np.cumsum([0] + grid.lengths[:-1]) * ctx.control_period
        mids = truth.t + starts + 0.5 * np.array(grid.lengths) * ctx.control_period
        p = self.solver.parameters(
            truth.state,
            self.command,
            radius,
            legs,
            truth.params.to_vector(),
            truth.disturbance_forecast(mids),
        )
        guess = np.concatenate([[self.plan[1]], self.plan[1:]])  # shifted by one period
        start = time.perf_counter()
        plan, ok, _ = self.solver.solve(p, guess)
        self.solve_times.append(time.perf_counter() - start)
        if ok:
            self.plan = plan
        else:
            self.failures += 1
            self.plan = np.clip(guess, self.solver.lb, self.solver.ub)
        self.command = float(self.plan[0])
        return np.array([np.clip(self.command / ctx.rudder_limit, -1.0, 1.0)], dtype=np.float32)

    def episode_stats(self) -> dict[str, float]:
        times = np.array(self.solve_times) if self.solve_times else np.array([math.nan])
        return {
            "solver_failures": float(self.failures),
            "solve_ms_median": 1e3 * float(np.median(times)),
            "solve_ms_p99": 1e3 * float(np.percentile(times, 99)),
        }
