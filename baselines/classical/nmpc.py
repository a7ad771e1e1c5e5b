"""Nonlinear MPC path following with LOS reference (Liu et al. 2019 §2.2.3, Algorithm 1).

On every ship: nomoto2 with the paper's numbers, every other ship with a Nomoto
prediction model from its own zig-zag and numbers from its own time scales
(:mod:`shipgym_baselines.classical.nmpc_ship`, where each rule is stated).

Prediction model: the nomoto2 model's right-hand side and RK4 step (the simulator's), in
CasADi SX, with the model parameters as solver parameters, so that an online identifier
can change them without rebuilding the solver.  States [x, y, ψ, r, ṙ, δ] are predicted
with ``prediction_substeps`` RK4 steps per prediction interval of ``interval`` control
periods (the paper: 1 period, 10 substeps; one step per Ts = 0.5 s is unstable for
T2 = 0.0247 s; with ``interval`` > 1 each planned command is held for that many periods,
move blocking, and the warm start is the previous plan unshifted); the error states of
eq. (14) are outputs of the prediction:

    e = −(x − x_n) sin ψp + (y − y_n) cos ψp,   ψ̃ = wrap(ψ − ψp)

which is eq. (14) exactly (ė = u0 sin ψ̃, ψ̃̇ = r) on the active leg.  Cost eq. (16) with
x_e = [e, ψ̃ − ψ̃_LOS, r, ṙ, δ], ψ̃_LOS(k+i) = −asin(e(k+i)/R_LOS) (eq. (9), evaluated along
the prediction, with eq. (12) in the continuous form R_LOS = max(nL, |e| + L) so that the
reference stays differentiable), Q = diag(1, 1, 0.01, 0.01, 0.001),
R = 0.01; input held after N_c (eq. (17)); |δc| ≤ 30°.

Solver: the cost is a sum of squares ‖ρ(u)‖², so the SQP uses the Gauss–Newton Hessian;
each QP (a box-constrained linear least-squares problem) is solved by CasADi's qrqp, with a
backtracking line search, warm-started from the shifted previous plan.  ρ and its (dense)
Jacobian are one CasADi function compiled to C once per machine (``shipgym.codegen``).  From
the warm start it typically converges in 1–3 iterations (``max_iter`` = 10 bounds the worst
case).  If the identified model makes the prediction diverge, the last model for which the
solve worked is used instead (counted as ``model_fallbacks``); if that fails too (non-finite
prediction or plan) the shifted last plan is applied and counted as ``solver_failures``.
On a PCHIP path the "leg" is the tangent at the closest point.

Adaptive variants update the model parameters from ``info["samples"]`` each step with the
weighted LS-SVM or λ-LS-SVM online identifier, with persistent excitation (eq. (45)).  The
``*_svf`` variants (``nmpc_wlssvm_svf``, ``nmpc_lambda_lssvm_svf``; an extension beyond the
paper) give the identifier the outlier + state-variable-filter front end
(``front_end="svf"``, :mod:`shipgym.identification.front_end`), which survives heading noise.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import time
import zlib
from typing import Any, ClassVar

import casadi as ca
import numpy as np

from shipgym.codegen import compiled_all
from shipgym.envs.context import ControllerContext
from shipgym.identification.online import LambdaLSSVM, PersistentExcitation, WeightedLSSVMOnline
from shipgym.models.base import ShipModel
from shipgym.models.nomoto2 import Nomoto2
from shipgym_baselines.classical.box_qp import BoxQP, bind, sqp
from shipgym_baselines.classical.drift import course_and_drift
from shipgym_baselines.classical.nmpc_ship import (
    PAPER_CONTROL_HORIZON,
    PAPER_HORIZON,
    PAPER_Q,
    ShipNMPCPlan,
    ship_plan,
)
from shipgym_baselines.policy import check_action_mode
from shipgym_baselines.records.chosen import tuned_settings


@dataclasses.dataclass(frozen=True)
class NMPCSettings:
    """Liu et al. (2019) §4 defaults, plus the numerical choices (documented in the module)."""

    horizon: int = PAPER_HORIZON  # N_p
    control_horizon: int = PAPER_CONTROL_HORIZON  # N_c
    Q: tuple[float, float, float, float, float] = PAPER_Q
    R: float = 0.01
    prediction_substeps: int = 10  # RK4 steps per prediction interval
    interval: int = 1  # control periods per prediction interval (move blocking; 1: the paper)
    max_iter: int = 10  # Gauss–Newton SQP iterations per control step (warm-started)
    step_tolerance: float = 1e-5  # rad: stop when the accepted step is smaller
    compile: bool = True  # compile residual + Jacobian to C (cached); VM otherwise


class NMPCSolver:
    """The NMPC problem for one model class, horizon and control period (built once).

    The cost (16) is a sum of squares ‖ρ(u; p)‖², so each SQP iteration is a Gauss–Newton
    step: the box-constrained linear least-squares problem min ‖ρ + J·Δ‖² with
    δmin ≤ u + Δ ≤ δmax (as a QP, CasADi's qrqp), then a backtracking line search on the cost.
    ρ and J = ∂ρ/∂u come from one CasADi function, compiled to C and cached on disk
    (``shipgym.codegen``).
    """

    def __init__(
        self, model: ShipModel, settings: NMPCSettings, control_period: float, rudder_limit: float
    ) -> None:
        s = settings
        if not 1 <= s.control_horizon <= s.horizon:
            raise ValueError("need 1 ≤ control_horizon ≤ horizon")
        if s.interval < 1 or s.prediction_substeps < 1:
            raise ValueError("need interval ≥ 1 and prediction_substeps ≥ 1")
        self.model, self.settings = model, settings
        self.rudder_limit = rudder_limit
        nx, npar = model.n_states, model.n_params
        h = control_period * s.interval / s.prediction_substeps
        step = model.casadi_step(h)
        ix, iy, ipsi = (model.state_index(k) for k in ("x", "y", "psi"))
        ir, irdot, idelta = (model.state_index(k) for k in ("r", "r_dot", "delta"))
        u = ca.SX.sym("u", s.control_horizon)
        # parameters: x0, leg start (x_n, y_n), path angle ψp, nL, model parameters, and the
        # cost weights √Q (5), √R: solver parameters, so that one compiled function serves
        # every weighting (a tuning study's trials) of a horizon
        p = ca.SX.sym("p", nx + 4 + npar + N_WEIGHTS)
        x = p[:nx]
        xn, yn, psip, radius = p[nx], p[nx + 1], p[nx + 2], p[nx + 3]
        length = model.length
        theta = p[nx + 4 : nx + 4 + npar]
        q = [p[nx + 4 + npar + k] for k in range(N_WEIGHTS)]
        w = ca.SX.zeros(model.n_disturbances)
        residuals, states = [], []
        for i in range(s.horizon):
            ui = u[min(i, s.control_horizon - 1)]  # eq. (17): held after N_c
            for _ in range(s.prediction_substeps):
                x = step(x, ui, w, theta)
            states.append(x)
            e = -(x[ix] - xn) * ca.sin(psip) + (x[iy] - yn) * ca.cos(psip)
            rel = ca.atan2(ca.sin(x[ipsi] - psip), ca.cos(x[ipsi] - psip))
            # eq. (9) along the prediction; eq. (12) made continuous, R = max(nL, |e| + L),
            # so that |e/R| < 1 and asin stays differentiable
            r_los = ca.fmax(radius, ca.fabs(e) + length)
            ref = -ca.asin(e / r_los)
            residuals += [
                q[0] * e,
                q[1] * (rel - ref),
                q[2] * x[ir],
                q[3] * x[irdot],
                q[4] * x[idelta],
            ]
        residuals += [q[5] * u[i] for i in range(s.control_horizon)]
        rho = ca.vertcat(*residuals)  # cost (16) = ‖ρ‖²
        self.n_residuals = rho.shape[0]
        self.predict_function = ca.Function("predict", [u, p], [ca.horzcat(*states)])
        tag = f"{model.name}_n{s.horizon}_c{s.control_horizon}_s{s.prediction_substeps}"
        if s.interval != 1:  # another ship's (the library's name; its hash is the code's)
            tag += f"_k{s.interval}_{zlib.crc32(repr(length).encode()):08x}"
        residual = ca.Function(f"nmpc_rho_{tag}", [u, p], [rho])
        # dense: the buffer interface writes only the structural nonzeros of an output
        jacobian = ca.Function(f"nmpc_jac_{tag}", [u, p], [rho, ca.densify(ca.jacobian(rho, u))])
        if s.compile:
            residual, jacobian = compiled_all(
                [residual, jacobian],
                what=f"the NMPC's solver ({s.horizon} intervals of {s.interval} periods)",
            )
        self._u = np.zeros(s.control_horizon)
        self._p = np.zeros(nx + 4 + npar + N_WEIGHTS)
        #: √Q, √R of the settings the solver was built with (what :meth:`parameters` uses
        #: when not given others)
        self.weights = weight_vector(s)
        self._rho = np.zeros(self.n_residuals)
        self._jac = np.zeros((s.control_horizon, self.n_residuals))  # column-major J
        self._rho_eval = self._bind(residual, [self._rho])
        self._jac_eval = self._bind(jacobian, [self._rho, self._jac])
        self._functions = (residual, jacobian)  # keep the buffers' owners alive
        self.lb = np.full(s.control_horizon, -rudder_limit)
        self.ub = np.full(s.control_horizon, rudder_limit)
        # the Gauss–Newton QP: min ½Δᵀ(JᵀJ)Δ + (Jᵀρ)ᵀΔ, lb − u ≤ Δ ≤ ub − u (CasADi qrqp)
        self._qp = BoxQP(s.control_horizon)

    def _gauss_newton_step(self, u: np.ndarray, rho: np.ndarray, jac: np.ndarray) -> np.ndarray:
        """Box-constrained Gauss–Newton step Δ (the SQP's QP), solved by qrqp."""
        return self._qp.solve_gauss_newton(jac, rho, u, self.lb, self.ub)

    def _bind(self, function: ca.Function, outputs: list[np.ndarray]):
        return bind(function, [self._u, self._p], outputs)

    def parameters(
        self,
        x0: np.ndarray,
        leg_start: tuple[float, float],
        path_angle: float,
        radius: float,
        params: np.ndarray,
        weights: np.ndarray | None = None,
    ) -> np.ndarray:
        """The solver's parameter vector; ``weights``: :func:`weight_vector` of the
        controller's settings (None: the solver's own)."""
        weights = self.weights if weights is None else weights
        return np.concatenate(
            [x0, [leg_start[0], leg_start[1], path_angle, radius], params, weights]
        )

    def cost(self, plan: np.ndarray, p: np.ndarray) -> float:
        """Cost (16) of a plan; inf when the prediction diverges (e.g. absurd parameters)."""
        self._p[:] = p
        with np.errstate(over="ignore", invalid="ignore"):
            return self._plan_cost(plan)

    def _plan_cost(self, plan: np.ndarray) -> float:
        """:meth:`cost` with the parameters already in the buffer, inside :meth:`solve`'s
        ``errstate`` (an overflowing ρ·ρ is inf, not a warning)."""
        self._u[:] = plan
        self._rho_eval[1]()
        value = float(self._rho @ self._rho)
        return value if math.isfinite(value) else math.inf

    def _direction(self, u: np.ndarray) -> np.ndarray | None:
        """The Gauss–Newton step at u (None: ρ or J not finite); parameters in the buffer."""
        self._u[:] = u
        self._jac_eval[1]()
        rho, jac = self._rho, self._jac.T  # used before the next evaluation overwrites them
        if not (np.isfinite(rho).all() and np.isfinite(jac).all()):
            return None
        return self._gauss_newton_step(u, rho, jac)

    def solve(self, p: np.ndarray, guess: np.ndarray) -> tuple[np.ndarray, bool, int]:
        """Optimal plan (N_c commands, rad), success flag, iterations (Gauss–Newton SQP)."""
        s = self.settings
        self._p[:] = p  # constant over the solve: written once, not per evaluation
        # a diverging prediction is handled, not warned about: inf cost, no direction
        with np.errstate(over="ignore", invalid="ignore"):
            return sqp(
                guess,
                self.lb,
                self.ub,
                self._plan_cost,
                self._direction,
                s.max_iter,
                s.step_tolerance,
            )

    def predict(self, plan: np.ndarray, p: np.ndarray) -> np.ndarray:
        """Predicted states (N_p, n_x) at the ends of the control periods."""
        return np.asarray(self.predict_function(plan, p)).T


_SOLVERS: dict[tuple, NMPCSolver] = {}


def get_solver(model: ShipModel, settings: NMPCSettings, ts: float, limit: float) -> NMPCSolver:
    """Solvers are built once per process for a model class, settings and timing; settings
    that differ only in the cost weights Q, R share one (the weights are parameters: pass
    :func:`weight_vector` of yours to :meth:`NMPCSolver.parameters`)."""
    structure = dataclasses.replace(settings, Q=NMPCSettings.Q, R=NMPCSettings.R)
    key = (type(model).__name__, model.length, structure, ts, limit)  # L is in the graph
    if key not in _SOLVERS:
        _SOLVERS[key] = NMPCSolver(model, structure, ts, limit)
    return _SOLVERS[key]


#: the cost weights in the solver's parameters: √Q (5) and √R
N_WEIGHTS = 6


def weight_vector(settings: NMPCSettings) -> np.ndarray:
    """[√Q₁ … √Q₅, √R] of ``settings`` (read-only): the residual weights of cost (16)."""
    if len(settings.Q) != N_WEIGHTS - 1 or not all(
        math.isfinite(v) and v >= 0 for v in (*settings.Q, settings.R)
    ):
        raise ValueError(
            f"need five finite Q ≥ 0 and a finite R ≥ 0, got Q={settings.Q}, R={settings.R}"
        )
    vector = np.array([math.sqrt(v) for v in (*settings.Q, settings.R)])
    vector.flags.writeable = False
    return vector


@functools.lru_cache(maxsize=64)
def _slope_times(h: float, n: int) -> tuple[np.ndarray, float]:
    """Centred sample times t − t̄ [s] of n samples at spacing h, and Σ(t − t̄)² (built once)."""
    t = h * np.arange(n)
    t -= t.mean()
    t.flags.writeable = False
    return t, float(t @ t)


def yaw_acceleration(samples: dict[str, np.ndarray], yaw_rate: float, h: float) -> float:
    """ṙ estimate [rad/s²]: least-squares slope of the last fine yaw-rate samples and r now."""
    r = np.asarray(samples.get("r", ()), dtype=float)
    if r.size == 0:
        return 0.0
    values = np.append(r[-5:], yaw_rate)
    t, tt = _slope_times(h, values.size)
    return float(t @ (values - values.mean()) / tt)


class NMPC:
    """``nmpc``: NMPC + LOS on the nominal model (no adaptation), Liu et al. (2019).

    ``settings`` None: the numbers of the ship (:func:`ship_plan`; the paper's on nomoto2),
    with the tuned factors below.  ``excitation_deg``: σ of eq. (45) [deg] (None: 0).

    ``preset``: "tuned" (the registry's default) reads the ship's section of the member's
    own chosen settings (``configs/tuning/chosen/<name>.yaml``, ``shipgym tune <name>``,
    docs/tuning.md), else of ``nmpc``'s (:attr:`tuning_name`: the members without a study of
    their own share the non-adaptive controller's), under the values given here; "paper"
    reads none (``shipgym reproduce liu2019``).  The tuned settings, each
    None for the chosen value (else the rule's: 1, and no compensation):

    * ``horizon_scale``: factor on the horizon time t_H of :func:`ship_plan`;
    * ``cross_track_weight``, ``heading_weight``, ``rudder_weight``: factors on Q_e, Q_ψ and
      R of cost (16) (the rule's ship-scaled weights);
    * ``drift_compensation``: predict and penalise the course ψ + β instead of the heading,
      with β the measured drift angle (:mod:`~shipgym_baselines.classical.drift`, as the
      PID family, LQR and L1 compensate it): the prediction starts from ψ₀ + β, held over
      the horizon, so that ψ̃ − ψ̃_LOS of eq. (16) is the course error (ψd = χd − β).

    An explicit ``settings`` object fixes the horizon and weights (the factors then must not
    be given).
    """

    name: ClassVar[str] = "nmpc"
    name: ClassVar[str]  # each subclass's own: its name in the registry
    kind: ClassVar[str] = "classical"
    identifier_type: ClassVar[type | None] = None
    #: options of the identifier (e.g. its front end)
    identifier_options: ClassVar[dict[str, Any]] = {}
    #: whose chosen settings a member without a study of its own reads
    tuning_name: ClassVar[str] = "nmpc"

    def __init__(
        self,
        settings: NMPCSettings | None = None,
        excitation_deg: float | None = None,
        preset: str = "tuned",
        horizon_scale: float | None = None,
        cross_track_weight: float | None = None,
        heading_weight: float | None = None,
        rudder_weight: float | None = None,
        drift_compensation: bool | None = None,
    ) -> None:
        if preset not in ("tuned", "paper"):
            raise ValueError(f"preset must be 'tuned' or 'paper', got {preset!r}")
        factors = {
            "horizon_scale": horizon_scale,
            "cross_track_weight": cross_track_weight,
            "heading_weight": heading_weight,
            "rudder_weight": rudder_weight,
        }
        for key, value in factors.items():
            if value is not None and not (math.isfinite(value) and value > 0):
                raise ValueError(f"{key} must be finite and > 0, got {value!r}")
        #: the settings given here (over the chosen ones at reset)
        self.explicit: dict[str, Any] = {k: float(v) for k, v in factors.items() if v is not None}
        if settings is not None and self.explicit:
            raise ValueError(f"give settings or the factors {sorted(self.explicit)}, not both")
        if drift_compensation is not None:
            self.explicit["drift_compensation"] = bool(drift_compensation)
        self.preset = preset
        self._given_settings = settings
        self.settings = settings if settings is not None else NMPCSettings()
        # eq. (45) excitation (σ not given by the paper; 0 by default: see the README)
        default = 0.0
        self.excitation = math.radians(excitation_deg if excitation_deg is not None else default)

    def _identifier(self, plan: ShipNMPCPlan) -> Any:
        """The online identifier with the ship's window, update period, thresholds, SVF λ."""
        if self.identifier_type is None:
            return None
        options = {
            **plan.identifier_options(issubclass(self.identifier_type, LambdaLSSVM)),
            **self.identifier_options,
        }
        if options.get("front_end") == "svf":
            options.setdefault("svf_bandwidth", plan.svf_bandwidth)
        return self.identifier_type(self.ctx.fine_step, plan.nominal, **options)

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        check_action_mode(self, context)
        self.ctx = context
        chosen: dict[str, Any] = {}
        if self.preset == "tuned":  # the member's own study if it has one, else nmpc's
            own = tuned_settings(type(self).name, context.ship)
            chosen = own or tuned_settings(self.tuning_name, context.ship)
        given = {**chosen, **self.explicit}
        if self._given_settings is not None:  # the settings object fixes horizon and weights
            given = {k: v for k, v in given.items() if k == "drift_compensation"}
        self.ship_plan = plan = ship_plan(context, float(given.get("horizon_scale", 1.0)))
        if self._given_settings is None:
            q = plan.Q
            self.settings = NMPCSettings(
                horizon=plan.horizon,
                control_horizon=plan.control_horizon,
                Q=(
                    q[0] * float(given.get("cross_track_weight", 1.0)),
                    q[1] * float(given.get("heading_weight", 1.0)),
                    *q[2:],
                ),
                R=NMPCSettings.R * float(given.get("rudder_weight", 1.0)),
                prediction_substeps=plan.substeps,
                interval=plan.interval,
            )
        self.drift_compensation = bool(given.get("drift_compensation", False))
        self._last: dict[str, Any] | None = None
        self.weights = weight_vector(self.settings)
        # nomoto2 predicts with its own model; another ship with its Nomoto model (module doc)
        self.model = context.nominal_model if not plan.reduce else Nomoto2(plan.nominal)
        self.solver = get_solver(
            self.model, self.settings, context.control_period, context.rudder_limit
        )
        self.params = plan.nominal
        self.identifier = self._identifier(plan)
        self.pe = PersistentExcitation(
            self.excitation, np.random.default_rng(seed), hold=plan.excitation_hold
        )
        self.tracker = context.new_tracker()
        self._started = False
        self.plan = np.zeros(self.settings.control_horizon)
        self.failures = 0
        self.model_fallbacks = 0
        self._good_params = plan.nominal
        self.solves = 0
        self.solve_times: list[float] = []  # wall clock [s]
        self.solve_cpu_times: list[float] = []  # this thread's CPU time [s] (load-proof)
        self.param_history: list[dict[str, float]] = []
        # per-step work hoisted: state indices, and what depends only on the parameters
        model = self.model
        self._index = tuple(model.state_index(k) for k in ("x", "y", "psi", "r", "r_dot", "delta"))
        self._identified: Any = None  # the identifier's last params object …
        self._estimate: Any = None  # … and its prediction-model parameters
        self._vectors: dict[int, tuple[Any, np.ndarray]] = {}
        self._dicts: dict[int, tuple[Any, dict[str, float]]] = {}

    def _state(self, info: dict[str, Any]) -> np.ndarray:
        ix, iy, ipsi, ir, irdot, idelta = self._index
        x0 = np.zeros(self.model.n_states)
        x0[ix], x0[iy] = info["position"]
        x0[ipsi] = info["heading"]
        x0[ir] = info["yaw_rate"]
        x0[irdot] = yaw_acceleration(info.get("samples", {}), info["yaw_rate"], self.ctx.fine_step)
        x0[idelta] = info["rudder_angle"]
        return x0

    def _vector(self, params: Any) -> np.ndarray:
        """``params.to_vector()``, computed once per parameters object (read-only)."""
        hit = self._vectors.get(id(params))
        if hit is None or hit[0] is not params:
            vector = params.to_vector()
            vector.flags.writeable = False
            hit = self._vectors[id(params)] = (params, vector)
            if len(self._vectors) > 8:  # only the current and the last good one are needed
                self._vectors = {id(params): hit}
        return hit[1]

    def _as_dict(self, params: Any) -> dict[str, float]:
        """``params.as_dict()``, computed once per parameters object (do not mutate)."""
        hit = self._dicts.get(id(params))
        if hit is None or hit[0] is not params:
            hit = self._dicts[id(params)] = (params, params.as_dict())
            if len(self._dicts) > 8:
                self._dicts = {id(params): hit}
        return hit[1]

    def _warm_start(self) -> np.ndarray:
        """The previous plan shifted by one control period: by one interval when an interval
        is one period, else unchanged (a period is a fraction of the first interval)."""
        if self.settings.interval == 1:
            return np.append(self.plan[1:], self.plan[-1])
        return self.plan.copy()

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        # prediction_params makes a new parameters object on a reduced ship each time it is
        # called: the model fallback below treats a step's cached estimate as new, as then
        fresh = False
        if self.identifier is not None and "samples" in info:
            self.identifier.update(info["samples"])
            identified = self.identifier.params
            if identified is not self._identified:  # re-identified: a new estimate
                self._identified = identified
                self._estimate = self.ship_plan.prediction_params(identified)
            estimate = self._estimate
            if estimate is not None:
                fresh = self.ship_plan.reduce
                self.params = estimate
        x, y = info["position"]
        frame = self.tracker.update(x, y) if self._started else self.tracker.reset(x, y)
        self._started = True
        leg_start = (
            tuple(self.tracker.path.point(frame.along_track))  # closest point; tangent line
            if self.tracker.is_curve
            else tuple(self.ctx.waypoints[frame.leg])
        )
        radius = self.ctx.guidance.los_radius_L * self.ctx.ship_length  # nL; |e| + L applied inside
        x0 = self._state(info)
        if self.drift_compensation:  # predict the course ψ + β (class doc)
            _, drift = course_and_drift(
                info, self._last, self.ctx.control_period, self.ctx.nominal_speed
            )
            self._last = {"position": (float(x), float(y)), "psi": float(info["heading"])}
            x0[self._index[2]] += drift
        guess = self._warm_start()
        start, start_cpu = time.perf_counter(), time.thread_time()
        plan, ok, _ = self.solver.solve(
            self.solver.parameters(
                x0, leg_start, frame.path_angle, radius, self._vector(self.params), self.weights
            ),
            guess,
        )
        used = self.params
        if ok:
            self._good_params = self.params
        elif fresh or self._good_params is not self.params:
            used = self._good_params
            # the identified model makes the prediction diverge: use the last one that worked
            self.model_fallbacks += 1
            plan, ok, _ = self.solver.solve(
                self.solver.parameters(
                    x0,
                    leg_start,
                    frame.path_angle,
                    radius,
                    self._vector(self._good_params),
                    self.weights,
                ),
                guess,
            )
        self.solve_times.append(time.perf_counter() - start)
        self.solve_cpu_times.append(time.thread_time() - start_cpu)
        self.solves += 1
        if ok:
            self.plan = plan
        else:  # fall back to the shifted last plan and count it
            self.failures += 1
            self.plan = guess
        self.param_history.append({"t": info["t"], **self._as_dict(used)})
        delta_c = self.pe(float(self.plan[0]))
        command = min(max(delta_c / self.ctx.rudder_limit, -1.0), 1.0)  # np.clip's value
        return np.array([command], dtype=np.float32)

    def episode_stats(self) -> dict[str, float]:
        times = np.array(self.solve_times) if self.solve_times else np.array([math.nan])
        return {
            "solver_failures": float(self.failures),
            "model_fallbacks": float(self.model_fallbacks),
            "solve_ms_median": 1e3 * float(np.median(times)),
            "solve_ms_p99": 1e3 * float(np.percentile(times, 99)),
        }


class NMPCWeightedLSSVM(NMPC):
    """``nmpc_wlssvm``: NMPC with the model updated online by weighted LS-SVM."""

    name: ClassVar[str] = "nmpc_wlssvm"
    identifier_type = WeightedLSSVMOnline


class NMPCLambdaLSSVM(NMPC):
    """``nmpc_lambda_lssvm``: NMPC with the model updated by λ-LS-SVM (Algorithm 2)."""

    name: ClassVar[str] = "nmpc_lambda_lssvm"
    identifier_type = LambdaLSSVM


class NMPCWeightedLSSVMSVF(NMPCWeightedLSSVM):
    """``nmpc_wlssvm_svf``: ``nmpc_wlssvm`` with the outlier + state-variable-filter front end
    (``front_end="svf"``, λ = 3 rad/s; an extension beyond Liu et al. 2019)."""

    name: ClassVar[str] = "nmpc_wlssvm_svf"
    identifier_options: ClassVar[dict[str, Any]] = {"front_end": "svf"}


class NMPCLambdaLSSVMSVF(NMPCLambdaLSSVM):
    """``nmpc_lambda_lssvm_svf``: ``nmpc_lambda_lssvm`` with the outlier + state-variable-filter
    front end (``front_end="svf"``, λ = 3 rad/s; an extension beyond Liu et al. 2019)."""

    name: ClassVar[str] = "nmpc_lambda_lssvm_svf"
    identifier_options: ClassVar[dict[str, Any]] = {"front_end": "svf"}
