"""An extended Kalman filter on a ship's own model, its state augmented with what changes.

The filter runs once per control period Ts on what every controller receives: the measured
position, heading, yaw rate and rudder angle of ``info`` and the rudder command the env
applied (``info["rudder_command"]``).  Its state is

    z = (x, η, w):  x the model's state (SI, rad; the unmeasured surge and sway, and the
    model's internal states, included), η the adapted quantities of
    :mod:`shipgym.identification.adaptation` (ln factors on the nominal ship), w the
    current (earth frame, m/s) and the yaw bias (the model's ``yaw_disturbance``).

**Model** (Simon 2006, *Optimal State Estimation*, §13.2, the hybrid EKF in discrete
form):

    x⁺ = Φ(x, δc, w, θ(η))  (n RK4 steps of Ts/n of the model's one right-hand side),
    η⁺ = η + ν_η,  w⁺ = w + ν_w   (random walks),
    y = (x, y, ψ, r, δ) + ε,

with F = ∂z⁺/∂z from CasADi, chained over the substeps (∂x⁺/∂θ·∂θ/∂η as forward
directions, ∂θ/∂η by :meth:`Adaptation.jacobian`) and
P⁺ = F P Fᵀ + Q.  The update is the Joseph form with the heading's innovation wrapped to
(−π, π]; a heading whose innovation exceeds ``gate`` standard deviations is dropped (the
heading sensor's outliers of 5–15°; position and rudder angle are exact, the yaw rate has
noise but no outliers).  Estimates outside their bounds are clipped.

**Noise, in each quantity's own scale** (so that one setting serves every ship): the
random walks are per √T, T the nominal first-order Nomoto time constant (the ship's yaw
time scale): Var(ν) = σ²·Ts/T per period, σ = ``parameter_walk`` on every ln factor,
``current_walk``·U on each current component, ``bias_walk``·b on the yaw bias, b the yaw
bias equivalent to full rudder (|∂f/∂δ|·δmax/|∂f/∂w_ψ| on the state row the bias drives,
at cruise).  The model's own error is ``state_noise`` of each state's scale per period
(L for positions, U for speeds, U/L for the yaw rate, δmax for the rudder).

**Jumps.**  A change is a jump, which a random walk tuned for quiet tracking follows
slowly.  When the mean normalised innovation squared over the last ``jump_window_T``·T
exceeds ``jump_nis`` times its expectation (the measurements' count), the parameter and
disturbance covariance is reset to its initial value (covariance resetting, Goodwin & Sin
1984, §6.7): the filter believes the nominal ship no more than at the start and learns the
new one from the next measurements.  A prediction that leaves the finite numbers (an
estimate the model cannot integrate) restarts η and w from the nominal ship.

**Given quantities.**  A quantity estimated elsewhere (``given``: ``nmpc_ekf`` fits the servo
from the measured rudder, :mod:`shipgym.identification.servo`) is set before each
prediction (:meth:`ShipEKF.set_given`) and has no walk and no covariance: the filter
predicts with it and never updates it.
"""

from __future__ import annotations

import collections
import dataclasses
import math

import casadi as ca
import numpy as np

from shipgym.angles import wrap_angle
from shipgym.codegen import compiled_all
from shipgym.identification.adaptation import Adaptation
from shipgym.models.base import ShipModel

#: the measured entries of the state, in the order of a measurement vector
MEASURED = ("x", "y", "psi", "r", "delta")
#: the heading's place in a measurement vector
HEADING = MEASURED.index("psi")


@dataclasses.dataclass(frozen=True)
class FilterSettings:
    """The filter's noise model and its jump rule (module doc)."""

    parameter_walk: float = 0.05  # σ of each ln factor's walk per √T [-]
    current_walk: float = 0.02  # σ of each current component's walk per √T [U]
    bias_walk: float = 0.02  # σ of the yaw bias's walk per √T [full-rudder bias]
    state_noise: float = 1e-3  # σ of the model's error per period [each state's scale]
    position_noise_L: float = 1e-2  # σ of the measured position [L]
    heading_noise_deg: float = 0.5  # σ of the measured heading [deg]
    yaw_rate_noise_deg_s: float = 0.1  # σ of the measured yaw rate [deg/s]
    rudder_noise_deg: float = 0.05  # σ of the measured rudder angle [deg]
    gate: float = 4.0  # drop a measurement whose innovation exceeds gate·σ [-]
    initial_parameter: float = 0.5  # σ of each ln factor at the start [-]
    initial_current: float = 0.1  # σ of each current component at the start [U]
    initial_bias: float = 0.1  # σ of the yaw bias at the start [full-rudder bias]
    jump_window_T: float = 2.0  # window of the jump rule [T]
    jump_nis: float = 10.0  # reset when the window's mean NIS exceeds this × its expectation

    def __post_init__(self) -> None:
        for field in dataclasses.fields(self):
            value = getattr(self, field.name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"FilterSettings.{field.name} must be > 0, got {value}")


def state_scales(model: ShipModel, length: float, speed: float, rudder_limit: float) -> np.ndarray:
    """Each state's scale (module doc, "Noise"): L for x, y; 1 rad for ψ; U for u, v; U/L
    for r; (U/L)² for ṙ; δmax for δ; the cruise value (at least 1) for a model's internal
    states."""
    cruise = model.cruise_state()
    by_name = {
        "x": length,
        "y": length,
        "psi": 1.0,
        "u": speed,
        "v": speed,
        "r": speed / length,
        "r_dot": (speed / length) ** 2,
        "delta": rudder_limit,
    }
    return np.array(
        [
            by_name.get(name, max(1.0, abs(float(c))))
            for name, c in zip(model.state_names, cruise, strict=True)
        ]
    )


def measured_start(model: ShipModel, measurement: np.ndarray, speed: float) -> np.ndarray:
    """The state at a first measurement y = (x, y, ψ, r, δ): the ship at cruise, its surge
    at ``speed`` [m/s] where the model has one, the measured entries as measured."""
    x0 = np.array(model.cruise_state(), dtype=float)
    if "u" in model.state_names:
        x0[model.state_index("u")] = speed
    x0[[model.state_index(name) for name in MEASURED]] = measurement
    return x0


def full_rudder_bias(model: ShipModel, rudder_limit: float) -> float:
    """b: the yaw bias whose effect equals full rudder's on the state row the bias drives
    (|∂f/∂δ|·δmax/|∂f/∂w_ψ| at cruise; module doc)."""
    x = ca.SX.sym("x", model.n_states)
    w = ca.SX.sym("w", model.n_disturbances)
    p = model.params.to_vector()
    f = model.casadi_rhs(x, 0.0, w, p)
    jw = ca.Function("jw", [x, w], [ca.jacobian(f, w), ca.jacobian(f, x)])
    d_w, d_x = (np.array(m) for m in jw(model.cruise_state(), np.zeros(model.n_disturbances)))
    row = int(np.argmax(np.abs(d_w[:, model.disturbance_names.index("yaw_disturbance")])))
    per_bias = abs(d_w[row, model.disturbance_names.index("yaw_disturbance")])
    per_rudder = abs(d_x[row, model.state_index("delta")])
    return rudder_limit * per_rudder / per_bias if per_rudder > 0 else 1.0


def substep_function(model: ShipModel, step: float, adapted: int) -> ca.Function:
    """(x, δc, w, θ, G) -> (x⁺, ∂x⁺/∂x, ∂x⁺/∂θ·G, ∂x⁺/∂w): one RK4 step of ``step`` [s]
    with δc, w, θ held, and its Jacobians; G = ∂θ/∂η (n_θ × ``adapted``), so that the
    parameters enter as ``adapted`` forward directions, not one per parameter (the MMG
    model has 55)."""
    rk4 = model.casadi_step(step)
    x = ca.SX.sym("x", model.n_states)
    u = ca.SX.sym("u")
    w = ca.SX.sym("w", model.n_disturbances)
    theta = ca.SX.sym("theta", model.n_params)
    g = ca.SX.sym("G", model.n_params, adapted)
    xn = rk4(x, u, w, theta)
    return ca.Function(
        f"{model.name}_ekf_step_{adapted}",
        [x, u, w, theta, g],
        [xn, ca.jacobian(xn, x), ca.jtimes(xn, theta, g), ca.jacobian(xn, w)],
    )


_STEPS: dict[tuple, ca.Function] = {}


def compiled_substep(model: ShipModel, step: float, adapted: int) -> ca.Function:
    """:func:`substep_function`, compiled to C once per process (cached on disk)."""
    key = (type(model).__name__, model.variant, step, adapted)
    if key not in _STEPS:
        (_STEPS[key],) = compiled_all(
            [substep_function(model, step, adapted)], what="the EKF's model"
        )
    return _STEPS[key]


class ShipEKF:
    """The augmented filter of one ship (module doc); :meth:`start` at the first
    measurement, then :meth:`step` once per control period."""

    def __init__(
        self,
        model: ShipModel,
        adaptation: Adaptation,
        control_period: float,
        substeps: int,
        time_constant: float,
        length: float,
        speed: float,
        rudder_limit: float,
        settings: FilterSettings | None = None,
        given: tuple[str, ...] = (),
    ) -> None:
        s = self.settings = settings if settings is not None else FilterSettings()
        self.model, self.adaptation = model, adaptation
        self.ts = control_period
        self.substeps = substeps
        self.substep = compiled_substep(model, control_period / substeps, adaptation.size)
        nx, m, nw = model.n_states, adaptation.size, model.n_disturbances
        self.nx, self.m, self.nw = nx, m, nw
        self.n = nx + m + nw
        self.measured = np.array([model.state_index(name) for name in MEASURED])
        scale = state_scales(model, length, speed, rudder_limit)
        bias = full_rudder_bias(model, rudder_limit)
        i_bias = model.disturbance_names.index("yaw_disturbance")
        w_scale = np.full(nw, speed)
        w_scale[i_bias] = bias
        per_period = control_period / time_constant  # Var of a walk per period / σ² (per √T)
        unknown = sorted(set(given) - set(adaptation.names))
        if unknown:
            raise ValueError(f"{unknown} are not adapted quantities of {adaptation.names}")
        #: the quantities set from outside (:meth:`set_given`), not filtered
        self.given = np.array([name in given for name in adaptation.names])
        walks = np.concatenate([np.full(m, s.parameter_walk), s.current_walk * w_scale])
        walks[m + i_bias] = s.bias_walk * bias
        walks[:m][self.given] = 0.0
        self.q = np.concatenate([(s.state_noise * scale) ** 2, walks**2 * per_period])
        self.p0_extra = np.concatenate(
            [np.full(m, s.initial_parameter), s.initial_current * w_scale]
        )
        self.p0_extra[m + i_bias] = s.initial_bias * bias
        self.p0_extra[:m][self.given] = 0.0
        self.p0_extra = self.p0_extra**2
        self.r = np.array(
            [
                (s.position_noise_L * length) ** 2,
                (s.position_noise_L * length) ** 2,
                math.radians(s.heading_noise_deg) ** 2,
                math.radians(s.yaw_rate_noise_deg_s) ** 2,
                math.radians(s.rudder_noise_deg) ** 2,
            ]
        )
        self.window = max(1, round(s.jump_window_T * time_constant / control_period))
        self.z = np.zeros(self.n)
        self.cov = np.zeros((self.n, self.n))
        self.resets = 0
        self.divergences = 0
        self._nis: collections.deque[tuple[float, int]] = collections.deque()

    # ------------------------------------------------------------------ estimates
    @property
    def state(self) -> np.ndarray:
        """(n_x,) the model state's estimate (SI, rad)."""
        return self.z[: self.nx]

    @property
    def eta(self) -> np.ndarray:
        """(m,) the adapted quantities' estimate (ln factors)."""
        return self.z[self.nx : self.nx + self.m]

    @property
    def disturbances(self) -> np.ndarray:
        """(n_w,) the current [m/s] and yaw bias estimate."""
        return self.z[self.nx + self.m :]

    def params(self) -> np.ndarray:
        """The model's parameter vector at the estimate."""
        return self.adaptation.params(self.eta)

    def set_given(self, values: dict[str, float]) -> None:
        """Set quantities given from outside (``given``; ln factors): the filter predicts
        with them and never updates them (zero covariance)."""
        for name, value in values.items():
            i = self.adaptation.names.index(name)
            if not self.given[i]:
                raise ValueError(f"{name!r} is estimated by the filter, not given")
            self.z[self.nx + i] = value

    # ------------------------------------------------------------------ the filter
    def start(self, measurement: np.ndarray, speed: float) -> None:
        """The estimate at the first measurement y = (x, y, ψ, r, δ): the ship at cruise
        with the measured entries, the nominal ship and no disturbance; covariance from
        the measurement noise and the initial σ's (module doc)."""
        x0 = measured_start(self.model, measurement, speed)
        self.z = np.concatenate([x0, np.zeros(self.m + self.nw)])
        diag = np.concatenate([self.q[: self.nx] * 100.0, self.p0_extra])
        diag[self.measured] = self.r
        self.cov = np.diag(diag)
        self.resets = 0
        self.divergences = 0
        self._nis.clear()

    def predict(self, command: float) -> None:
        """One control period with the rudder command ``command`` [rad] acting: the
        substeps' Jacobians chained (S⁺ = A·S + B)."""
        nx, m = self.nx, self.m
        theta, d_theta = self.adaptation.jacobian(self.eta)
        w = self.disturbances
        x = self.state
        a_all = np.eye(nx)
        s_eta = np.zeros((nx, m))
        s_w = np.zeros((nx, self.nw))
        for _ in range(self.substeps):
            x, a, b_eta, b_w = (np.asarray(v) for v in self.substep(x, command, w, theta, d_theta))
            a_all = a @ a_all
            s_eta = a @ s_eta + b_eta
            s_w = a @ s_w + b_w
        if not (np.isfinite(x).all() and np.isfinite(a_all).all() and np.isfinite(s_eta).all()):
            self._restart()
            return
        f = np.eye(self.n)
        f[:nx, :nx] = a_all
        f[:nx, nx : nx + m] = s_eta
        f[:nx, nx + m :] = s_w
        self.z[:nx] = x.ravel()
        self.cov = f @ self.cov @ f.T + np.diag(self.q)

    def _restart(self) -> None:
        """The prediction left the finite numbers (an estimate the model cannot integrate):
        back to the nominal ship and the initial covariance of η and w, the state kept."""
        self.z[self.nx :] = 0.0
        self._reset_covariance()
        self.divergences += 1

    def update(self, measurement: np.ndarray) -> None:
        """The measurement y = (x, y, ψ, r, δ) [m, m, rad, rad/s, rad]; a heading beyond
        ``gate``·σ of its innovation is dropped (module doc)."""
        innovation = measurement - self.z[self.measured]
        innovation[HEADING] = wrap_angle(innovation[HEADING])
        spread = self.cov[np.ix_(self.measured, self.measured)] + np.diag(self.r)
        kept = np.ones(innovation.size, dtype=bool)  # the heading alone has outliers
        kept[HEADING] = abs(innovation[HEADING]) <= self.settings.gate * math.sqrt(
            spread[HEADING, HEADING]
        )
        rows = self.measured[kept]
        h = np.zeros((rows.size, self.n))
        h[np.arange(rows.size), rows] = 1.0
        s = spread[np.ix_(kept, kept)]
        nu = innovation[kept]
        gain = np.linalg.solve(s, h @ self.cov).T
        self.z += gain @ nu
        joseph = np.eye(self.n) - gain @ h
        self.cov = joseph @ self.cov @ joseph.T + (gain * self.r[kept]) @ gain.T
        self.cov = 0.5 * (self.cov + self.cov.T)
        i = slice(self.nx, self.nx + self.m)
        self.z[i] = self.adaptation.clip(self.z[i])
        self._watch_jumps(float(nu @ np.linalg.solve(s, nu)), int(rows.size))

    def step(self, command: float, measurement: np.ndarray) -> None:
        """:meth:`predict` with the command applied over the period just ended, then
        :meth:`update` with the measurement at its end."""
        self.predict(command)
        self.update(measurement)

    def _watch_jumps(self, nis: float, count: int) -> None:
        """The jump rule (module doc): covariance reset of η and w."""
        self._nis.append((nis, count))
        if len(self._nis) > self.window:
            self._nis.popleft()
        if len(self._nis) < self.window:
            return
        total = sum(v for v, _ in self._nis)
        expected = sum(c for _, c in self._nis)
        if total > self.settings.jump_nis * expected:
            self._reset_covariance()
            self.resets += 1

    def _reset_covariance(self) -> None:
        """η and w believed no more than at the start (covariance resetting)."""
        block = slice(self.nx, self.n)
        self.cov[block, :] = 0.0
        self.cov[:, block] = 0.0
        self.cov[block, block] = np.diag(self.p0_extra)
        self._nis.clear()
