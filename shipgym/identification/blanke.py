"""Semiphysical LS-SVM identification of Blanke's model (Moreno-Salinas et al., 2013).

Moreno-Salinas et al. (2013) §3: the speed and steering equations of Blanke's model
(eq. (7)) are solved for the accelerations, ν̇ = M⁻¹ f(ν, δ) (eq. (8)), and discretised with
Euler's forward difference at the IMU sampling time h (eq. (9)):

    ν_{k+1} − ν_k = h · (Θ φ(ν_k, δ_k) + b)                                       (9)–(11)

so each of u, v, r is a linear regression on the Blanke regressors at step k with the
increment to step k+1 as output (eq. (11)–(13)).  The coefficient vectors Θ (eq. (13))
contain the inverse mass matrix: the sway and yaw equations share one regressor set
[|u|v, u r, v|v|, v|r|, r|v|, r|r|, δ], each coefficient being a mix of Y- and N-derivatives
through M⁻¹.  As the paper says, these vectors *are* the model (the hydrodynamic
derivatives themselves would need the mass matrix from other tests), and they are what
this module returns, as the parameters of :class:`~shipgym.models.blanke.BlankeRegression`
(a ShipModel, so the identified ship runs through the same RK4 and manoeuvres as the
plant).

Regression (eq. (14)–(15)): LS-SVM with a linear kernel, w = Θ, solved in the primal
(:func:`~shipgym.identification.lssvm.lssvm_primal`, equal to the dual to rounding).  The
regressors are multiplied by h so the weights are the continuous-time coefficients.  The
bias of the speed equation is the constant thrust term (1 − t)T/(m − X_u̇) (the paper: "the
term (1 − t)T is constant since the commanded surge speed is constant"); the steering
biases should come out ≈ 0 and are kept (reported) as the paper does.  Following Blanke
(1981), as the paper does, the r² term of the speed equation is left out by default
(``include_rr``); the rudder regressors are δ² and δ (the paper's constant-speed form) or,
with ``rudder_regressors="speed_scaled"``, u²δ² and u²δ.

Choices where the paper is silent or not applicable
---------------------------------------------------
* The seed's text has lost its equations (symbols stripped).  The regressor sets are
  Fossen's (2002) Blanke terms (data file §3.1) united with the naval vessel's (§3.3); the
  term "considered to be zero since it will be very small for most ships" (after Blanke
  1981) is read as the r² term of the speed equation; "regressors at step k, increment to
  step k + 1" is our reading of eq. (9)–(12).
* γ: the paper tried several values and printed its choice only in an equation we do not
  have.  Default γ = 1e8: effectively ordinary least squares at these data scales (the
  smallest regressor column, h·r|r|, has a squared norm ≈ 1e-5 per sample).
* Rudder: the paper regresses on the *commanded* rudder angle (its scale ship's servo is
  fast).  The plant here has a 5°/s rate-limited servo, so the commanded angle would lead
  the real one by up to 8 s; the default uses the rudder angle δ (the model's state, as on
  a ship with a rudder-angle sensor); pass the command to reproduce the paper literally.
* Euler bias: the forward difference estimates ν̇ at t_k + h/2 while the regressors are
  taken at t_k, so each coefficient is biased by O(h/τ) (τ the time scale of the motion);
  with h = 0.2 s and the naval vessel's τ ≈ 5–20 s this is a few percent on the steering
  coefficients (tests/test_blanke.py states the tolerance).  Measurement noise on u, v, r
  enters both the output increments and the regressors (errors in variables): the noise
  of ν_k appears with opposite signs in ν_{k+1} − ν_k and in φ(ν_k), which biases the
  damping terms towards more damping.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from shipgym.identification.errors import IdentificationError, check_sampling_step
from shipgym.identification.lssvm import lssvm_dual, lssvm_primal
from shipgym.models.base import NUMPY, ShipModel
from shipgym.models.blanke import (
    COEFFICIENT_NAMES,
    STEERING_TERMS,
    SURGE_TERMS,
    BlankeParams,
    BlankeRegression,
    BlankeRegressionParams,
    steering_regressors,
    surge_regressors,
)
from shipgym.models.integrator import PeriodIntegrator

#: default LS-SVM regularisation (see the module docstring)
GAMMA_BLANKE = 1e8


@dataclasses.dataclass(frozen=True)
class BlankeFit:
    """Identified coefficient vectors (eq. (13)) and fit diagnostics.

    ``params`` holds the coefficients (u_*, v_*, r_*; u_0, v_0, r_0 from the biases);
    ``residual_std`` the one-step residual std of each equation [m/s, m/s, rad/s];
    ``rudder_regressors`` the BlankeRegression variant the coefficients belong to.
    """

    params: BlankeRegressionParams
    rudder_regressors: str
    residual_std: dict[str, float]
    n_samples: int

    def model(self) -> BlankeRegression:
        """The identified ship as a ShipModel (same servo, kinematics and current handling)."""
        return BlankeRegression(self.params, self.rudder_regressors)

    def coefficients(self) -> dict[str, float]:
        """The identified coefficients only (no servo / length / speed fields)."""
        values = self.params.as_dict()
        return {n: values[n] for n in COEFFICIENT_NAMES}


def regression_matrices(
    u: np.ndarray,
    v: np.ndarray,
    r: np.ndarray,
    delta: np.ndarray,
    scaled: bool,
) -> tuple[np.ndarray, np.ndarray]:
    """Regressor matrices (N, 4) for the speed and (N, 7) for the steering equations."""
    phi_u = surge_regressors(u, v, r, delta, NUMPY, scaled)
    phi_s = steering_regressors(u, v, r, delta, NUMPY, scaled)
    return np.column_stack(phi_u), np.column_stack(phi_s)


def fit_blanke(
    u: np.ndarray,
    v: np.ndarray,
    r: np.ndarray,
    delta: np.ndarray,
    h: float,
    gamma: float = GAMMA_BLANKE,
    rudder_regressors: str = "paper",
    include_rr: bool = False,
    base: BlankeParams | None = None,
    solver: str = "primal",
) -> BlankeFit:
    """Fit Blanke's model to samples of u, v [m/s], r [rad/s] and δ [rad] spaced h [s].

    Moreno-Salinas et al. (2013) eq. (9)–(15); see the module docstring.  ``base`` supplies
    the servo, length and nominal speed of the identified model (default: the naval
    vessel's).  ``solver``: ``"primal"`` (fast) or ``"dual"`` (the paper's (N+1)² system).
    """
    h = check_sampling_step(h)
    arrays = [np.asarray(a, dtype=float) for a in (u, v, r, delta)]
    n = arrays[0].shape[0]
    if any(a.ndim != 1 or a.shape[0] != n for a in arrays):
        raise IdentificationError("u, v, r and delta must be 1-D arrays of equal length")
    if n < 20:
        raise IdentificationError(f"too few samples for a Blanke fit: {n} < 20")
    if rudder_regressors not in BlankeRegression.variants:
        raise IdentificationError(
            f"rudder_regressors must be one of {BlankeRegression.variants}, "
            f"got {rudder_regressors!r}"
        )
    if solver not in ("primal", "dual"):
        raise IdentificationError(f"solver must be 'primal' or 'dual', got {solver!r}")
    u, v, r, delta = arrays
    if np.ptp(delta) == 0.0:
        raise IdentificationError("the rudder angle is constant: the data excite nothing")
    scaled = rudder_regressors == "speed_scaled"
    phi_u, phi_s = regression_matrices(u[:-1], v[:-1], r[:-1], delta[:-1], scaled)
    surge_columns = [0, 1, 2, 3] if include_rr else [0, 1, 3]
    solve = lssvm_primal if solver == "primal" else lssvm_dual
    values: dict[str, float] = {}
    residual_std: dict[str, float] = {}
    # eq. (11): speed equation, bias = h·(1 − t)T/(m − X_u̇)
    sol = solve(h * phi_u[:, surge_columns], np.diff(u), gamma)
    for j, c in enumerate(surge_columns):
        values[f"u_{SURGE_TERMS[c]}"] = float(sol.theta[j])
    values["u_0"] = sol.bias / h
    residual_std["u"] = float(np.std(sol.residuals))
    # eq. (11): steering equations, one shared regressor set
    for name, signal in (("v", v), ("r", r)):
        sol = solve(h * phi_s, np.diff(signal), gamma)
        for j, term in enumerate(STEERING_TERMS):
            values[f"{name}_{term}"] = float(sol.theta[j])
        values[f"{name}_0"] = sol.bias / h
        residual_std[name] = float(np.std(sol.residuals))
    b = base if base is not None else BlankeParams()
    params = BlankeRegressionParams(
        **values,
        L=b.L,
        U0=b.U0,
        T_delta=b.T_delta,
        delta_max=b.delta_max,
        delta_dot_max=b.delta_dot_max,
    )
    return BlankeFit(params, rudder_regressors, residual_std, n)


def simulate_commands(
    model: ShipModel,
    delta_c: np.ndarray,
    h: float,
    x0: np.ndarray | None = None,
    disturbance: np.ndarray | None = None,
) -> np.ndarray:
    """States (len(delta_c) + 1, n_x) of ``model`` under the command sequence δc [rad].

    δc[k] acts on [k h, (k+1) h) (one RK4 step of the model's CasADi graph per sample, as
    :mod:`shipgym.manoeuvres`); starts at ``x0`` (default: the model's cruise state).  Used to
    replay a manoeuvre's commands on the identified model ("the same commanded input data",
    Moreno-Salinas et al. 2013 §4).
    """
    integ = PeriodIntegrator(model, h, 1)
    p = model.params.to_vector()[None, :]
    w = (
        np.zeros((1, model.n_disturbances))
        if disturbance is None
        else np.asarray(disturbance, dtype=float).reshape(1, model.n_disturbances)
    )
    x = model.cruise_state() if x0 is None else np.asarray(x0, dtype=float)
    commands = np.asarray(delta_c, dtype=float)
    states = np.empty((commands.shape[0] + 1, model.n_states))
    states[0] = x
    for k, c in enumerate(commands):
        x = integ(x, c, w, p)[-1]
        if not np.all(np.isfinite(x)):
            states[k + 1 :] = np.nan
            break
        states[k + 1] = x
    return states
