"""Blanke's nonlinear 3-DOF manoeuvring model (second-order modulus terms), naval vessel.

Structure: Blanke (1981) as written by Fossen (2002) and used by Moreno-Salinas et al.
(2013) eq. (7) (data file ``ship_models.md`` §3.1): a decoupled speed equation and coupled
sway–yaw steering equations with modulus (|·|·) damping,

    (m − X_u̇) u̇ = X_|u|u u|u| + (m + X_vr) v r + m x_G r² + T + X_R              (speed)
    M_s [v̇; ṙ] = [F_Y; F_N]                                                       (steering)
    F_Y = Y_|u|v |u|v + (Y_ur − m) u r + Y_v|v| v|v| + Y_v|r| v|r| + Y_r|v| r|v|
          + Y_r|r| r|r| + Y_R
    F_N = N_|u|v |u|v + N_|u|r |u|r − m x_G u r + N_v|v| v|v| + N_v|r| v|r|
          + N_r|v| r|v| + N_r|r| r|r| + N_R
    M_s = [[m − Y_v̇, m x_G − Y_ṙ], [m x_G − N_v̇, I_z − N_ṙ]]

with the rigid-body Coriolis terms X_c = m(v r + x_G r²), Y_c = −m u r, N_c = −m x_G u r
(data file §3.3).  3-DOF: roll is dropped (φ = p = 0), so Y_ṗ, N_ṗ and the φ-terms vanish.

Coefficients (defaults): the multipurpose naval vessel of Blanke & Christensen (1993)
(data file §3.3, dimensional SI): L_pp = 51.5 m, U_nom = 8 m/s, ρ = 1014 kg/m³,
m = 357 m³ · ρ = 361,998 kg, I_z = 47.934e6 kg m², x_G = −3.38 m, X_vr = 0.33 m.  The scale
craft coefficients Moreno-Salinas et al. (2013) identified (eq. (16)) are not recoverable.

Rudder (our model; the source has none: "rudder forces enter through τ")
------------------------------------------------------------------------
From the vessel's rudder data (area A_R = 1.5 m², span 1.5 m, aspect ratio 3,
dC_L/dα_e = 0.054 /deg on the *effective* angle α_e, stall at 23°), in the normal-force form
of the MMG rudder model (Yasukawa & Yoshimura 2015) without hull interaction factors:

    F_N = ½ ρ A_R U_R² C_N(α),   C_N(α) = dC_L/dα · clip(α, −α_stall, α_stall)
    X_R = −F_N sin δ,   Y_R = −F_N cos δ,   N_R = x_R · Y_R

* ``"effective_angle"`` (default): u_R = u, v_R = v + x_R r (local flow at the rudder
  stock, no propeller slipstream and no flow straightening), U_R² = u_R² + v_R²,
  α = δ + atan2(v_R, u_R).  In a turn the stern swings out and the effective angle drops
  below δ, as on a real rudder; the inflow terms add sway damping and reduce the
  destabilising Munk moment (≈ −k u v and −k x_R u r in F_Y, k = ½ρA_R dC_L/dα).
* ``"linear"``: α = δ, U_R = u, X_R = −F_N δ, Y_R = −F_N: exactly Fossen's linear rudder
  terms Y_δ δ, N_δ δ, X_δδ δ² with speed-scaled coefficients Y_δ = −k u², N_δ = x_R Y_δ,
  X_δδ = −k u².  Below stall this plant lies exactly in the structure that
  :mod:`shipgym.identification.blanke` regresses on, so it is the one the
  parameter-recovery test uses.

The lift plateau beyond stall is our simplification (no post-stall drop).  x_R = −23.79 m:
the rudder stock is at the aft perpendicular and the centre of gravity LCG = 20.41 m
forward of it at x_G = −3.38 m in the body frame (navalvessel.m "LCG from AP considered at
the rudder stock"), so x_R = x_G − LCG.

Manoeuvring of the default ship (RK4, h = 0.05 s): 20/20 zig-zag overshoots 5.7° / 5.7°,
period 85 s; 10/10 overshoots 2.2° / 2.3°; turning circle at 20°: tactical diameter 613 m
(11.9 L), steady 1.40 °/s, speed loss 6.6 %; at 35°: 432 m (8.4 L), 1.79 °/s, 15.8 %.  A
single 1.5 m² rudder (1.3 % of L·T) makes a slow turner; the source does not say whether
the vessel has one rudder or two (A_R = 3.0 m² for two).  Straight running is stable
(sway–yaw time constants ≈ 2 s and 8.5 s, surge 12 s).

Sign convention (project-wide): δ > 0 pushes the stern to port (Y_R < 0) and turns the bow
to starboard, r > 0 (Fossen's δ has the opposite sign; manoeuvre figures compare by
magnitude).

Propulsion: a constant thrust T = −X_|u|u U0|U0| (the resistance at U0), so the ship holds
U0 = 8 m/s in a straight line and slows in turns (speed loss from X_vr, X_R).  This is the
paper's "(1 − t)T constant since the commanded surge speed is constant" (Moreno-Salinas
et al. 2013, after eq. (16)).  No surge controller (the identification treats the thrust as
the constant bias of the speed equation).

Rudder machinery (the source has none: "The model does not include rudder Machinery"):
δ̇ = clip((clip(δc, ±δ_max) − δ)/T_δ, ±δ̇_max) with δ_max = 35° (the usual hard-over
angle; C_N saturates at 23° anyway), δ̇_max = 5°/s and T_δ = 1 s — documented typical
values, not from the source.

Current: the states u, v are velocities *through the water* (u_r, v_r).  For a constant,
irrotational earth-frame current the rigid-body terms written with r only (above) satisfy
Fossen (2011) Property 10.1, so the whole model holds in relative velocities and the
current enters the kinematics: ẋ = u cos ψ − v sin ψ + V_cx, ẏ = u sin ψ + v cos ψ + V_cy.
With zero relative velocity the ship drifts exactly with the current.  ``yaw_disturbance``
[rad/s²] adds to ṙ.

Time steps: Ts = 0.2 s (the IMU sampling time of Moreno-Salinas et al. 2013 §4.1) and
h = 0.05 s (RK4; a twentieth of the 1 s rudder time constant; the hull's fastest time
constant is ≈ 2 s).

:class:`BlankeRegression` is the same ship written in the identified (regression) form of
Moreno-Salinas et al. (2013) eq. (11)–(13): the accelerations are linear in the regressors
of :func:`surge_regressors` / :func:`steering_regressors`, with coefficients that already
contain the inverse mass matrix.  It shares the servo, kinematics and current handling with
:class:`Blanke` (one ``rhs``); only the accelerations differ.
"""

from __future__ import annotations

import dataclasses
import math
from abc import abstractmethod
from types import SimpleNamespace
from typing import Any, ClassVar

import numpy as np

from shipgym.models.base import ParameterRecord, ShipModel
from shipgym.models.hull import Hull
from shipgym.models.ship import EnvId, Ship, hull_quantities

DEG = math.pi / 180.0

#: density and displaced volume of the naval vessel (navalvessel.m, data file §3.3)
RHO = 1014.0  # [kg/m³]
DISPLACEMENT = 357.0  # [m³]
MASS = DISPLACEMENT * RHO  # 361,998 kg

#: regressor names of the identified form (Moreno-Salinas et al. 2013 eq. (13)); "d" is the
#: rudder regressor (δ² / δ, or u²δ² / u²δ when speed-scaled)
SURGE_TERMS = ("uau", "vr", "rr", "dd")
STEERING_TERMS = ("auv", "ur", "vav", "var", "rav", "rar", "d")
#: the identified coefficients (biases u_0, v_0, r_0 first in each equation)
COEFFICIENT_NAMES = (
    "u_0",
    *(f"u_{t}" for t in SURGE_TERMS),
    "v_0",
    *(f"v_{t}" for t in STEERING_TERMS),
    "r_0",
    *(f"r_{t}" for t in STEERING_TERMS),
)


@dataclasses.dataclass(frozen=True)
class BlankeParams(ParameterRecord):
    """Naval vessel of Blanke & Christensen (1993), SI/rad (data file §3.3)."""

    rho: float = RHO  # water density [kg/m³]
    m: float = MASS  # mass [kg] (357 m³ · 1014 kg/m³)
    Iz: float = 47.934e6  # yaw moment of inertia [kg m²]
    xG: float = -3.38  # longitudinal centre of gravity [m]
    L: float = 51.5  # length between perpendiculars [m]
    U0: float = 8.0  # nominal speed [m/s] (≈ 15.5 kn); sets the constant thrust
    # speed equation
    X_udot: float = -17400.0  # [kg]
    X_uau: float = -1960.0  # X_|u|u [kg/m]
    X_vr: float = 0.33 * MASS  # [kg] (0.33 m)
    # sway equation
    Y_vdot: float = -393000.0  # [kg]
    Y_rdot: float = -1.4e6  # [kg m]
    Y_auv: float = -11800.0  # Y_|u|v [kg/m]
    Y_ur: float = 131000.0  # [kg]
    Y_vav: float = -3700.0  # Y_v|v| [kg/m]
    Y_rar: float = 0.0  # Y_r|r| [kg m]
    Y_var: float = -794000.0  # Y_v|r| [kg]
    Y_rav: float = -182000.0  # Y_r|v| [kg]
    # yaw equation
    N_vdot: float = 538000.0  # [kg m]
    N_rdot: float = -38.7e6  # [kg m²]
    N_auv: float = -92000.0  # N_|u|v [kg]
    N_aur: float = -4.71e6  # N_|u|r [kg m]
    N_vav: float = 0.0  # N_v|v| [kg]
    N_rar: float = -202e6  # N_r|r| [kg m²]
    N_var: float = 0.0  # N_v|r| [kg m]
    N_rav: float = -15.6e6  # N_r|v| [kg m]
    # rudder (our model from the vessel's rudder data, see the module docstring)
    A_R: float = 1.5  # rudder area [m²]
    dCL: float = 0.054 / DEG  # lift slope dC_L/dα_e [1/rad] (0.054 /deg)
    alpha_stall: float = 23.0 * DEG  # stall angle [rad]
    x_R: float = -23.79  # rudder stock position [m] (x_G − LCG = −3.38 − 20.41)
    # rudder machinery (documented typical values, not from the source)
    T_delta: float = 1.0  # servo time constant [s]
    delta_max: float = 35.0 * DEG  # rudder angle limit [rad]
    delta_dot_max: float = 5.0 * DEG  # rudder rate limit [rad/s]

    positive: ClassVar[tuple[str, ...]] = (
        "rho",
        "m",
        "Iz",
        "L",
        "U0",
        "A_R",
        "dCL",
        "alpha_stall",
        "T_delta",
        "delta_max",
        "delta_dot_max",
    )

    def problems(self) -> list[str]:
        """The signs and the mass matrix a real vessel has, besides :attr:`positive`."""
        out = super().problems()
        if out:
            return out
        cls = type(self).__name__
        if self.X_uau >= 0:  # the resistance that sets the thrust (thrust(p) > 0)
            out.append(f"{cls}.X_uau must be < 0 (a resistance), got {self.X_uau}")
        if self.m - self.X_udot <= 0:
            out.append(f"{cls}: m − X_udot must be > 0 (surge mass), got {self.m - self.X_udot}")
        m11, m12, m21, m22 = steering_mass_matrix(self)
        if m11 <= 0 or m22 <= 0 or m11 * m22 - m12 * m21 <= 0:
            out.append(
                f"{cls}: the sway–yaw mass matrix [[m − Y_vdot, m·xG − Y_rdot], "
                f"[m·xG − N_vdot, Iz − N_rdot]] = [[{m11:.4g}, {m12:.4g}], [{m21:.4g}, "
                f"{m22:.4g}]] must have positive diagonal and determinant"
            )
        return out


def surge_regressors(u: Any, v: Any, r: Any, delta: Any, ops: SimpleNamespace, scaled: bool):
    """Regressors of the speed equation [u|u|, v r, r², δ²] (u²δ² when ``scaled``)."""
    d2 = delta * delta
    return [u * ops.abs(u), v * r, r * r, u * u * d2 if scaled else d2]


def steering_regressors(u: Any, v: Any, r: Any, delta: Any, ops: SimpleNamespace, scaled: bool):
    """Regressors of the steering equations [|u|v, u r, v|v|, v|r|, r|v|, r|r|, δ] (u²δ when
    ``scaled``); Fossen's (2002) Blanke terms, with u r = |u| r for u ≥ 0."""
    av, ar = ops.abs(v), ops.abs(r)
    return [
        ops.abs(u) * v,
        u * r,
        v * av,
        v * ar,
        r * av,
        r * ar,
        u * u * delta if scaled else delta,
    ]


def steering_mass_matrix(p: Any) -> tuple[Any, Any, Any, Any]:
    """Entries (M11, M12, M21, M22) of the sway–yaw mass matrix M_s (data file §3.3)."""
    return (
        p.m - p.Y_vdot,
        p.m * p.xG - p.Y_rdot,
        p.m * p.xG - p.N_vdot,
        p.Iz - p.N_rdot,
    )


def thrust(p: Any) -> Any:
    """Constant propeller thrust [N]: the straight-line resistance at U0."""
    return -p.X_uau * p.U0 * p.U0  # U0 > 0


class _Blanke3DOF(ShipModel):
    """Shared rhs of the Blanke plant and its identified form: servo, kinematics, current."""

    state_names = ("x", "y", "psi", "u", "v", "r", "delta")
    disturbance_names = ("current_x", "current_y", "yaw_disturbance")
    control_period = 0.2  # Ts [s]: IMU sampling of Moreno-Salinas et al. (2013) §4.1
    fine_step = 0.05  # h [s] (our choice)
    speed_parameter = "U0"

    def __init__(self, params: ParameterRecord | None = None, variant: str | None = None) -> None:
        super().__init__(params, variant)
        self.rudder_limit = float(self.params.delta_max)
        self.rudder_rate_limit = float(self.params.delta_dot_max)

    @abstractmethod
    def accelerations(
        self, u: Any, v: Any, r: Any, delta: Any, p: Any, ops: SimpleNamespace
    ) -> tuple[Any, Any, Any]:
        """(u̇, v̇, ṙ) [m/s², m/s², rad/s²] at water-relative u, v [m/s], r [rad/s], δ [rad]."""

    def rhs(self, x: Any, u: Any, w: Any, p: Any, ops: SimpleNamespace) -> Any:
        psi, surge, sway, r, delta = x[2], x[3], x[4], x[5], x[6]
        u_dot, v_dot, r_dot = self.accelerations(surge, sway, r, delta, p, ops)
        delta_c = ops.clip(u[0], -p.delta_max, p.delta_max)
        delta_dot = ops.clip((delta_c - delta) / p.T_delta, -p.delta_dot_max, p.delta_dot_max)
        cos_psi, sin_psi = ops.cos(psi), ops.sin(psi)
        return ops.stack(
            [
                surge * cos_psi - sway * sin_psi + w[0],  # relative velocities + current
                surge * sin_psi + sway * cos_psi + w[1],
                r,
                u_dot,
                v_dot,
                r_dot + w[2],  # yaw_disturbance: additive yaw acceleration
                delta_dot,
            ]
        )

    def cruise_state(self, **values: float) -> np.ndarray:
        """Straight ahead at u = U0 through the water (unless ``u`` is given)."""
        values = dict(values)
        values.setdefault("u", self.nominal_speed)
        return self.initial_state(**values)


class Blanke(_Blanke3DOF):
    """blanke: Blanke & Christensen (1993) naval vessel in Blanke's 3-DOF model (Fossen 2002)."""

    name = "blanke"
    params_type = BlankeParams
    rudder_limit = 35.0 * DEG  # per instance: params.delta_max
    rudder_rate_limit = 5.0 * DEG  # per instance: params.delta_dot_max
    #: rudder-force model, see the module docstring
    variants = ("effective_angle", "linear")
    #: Blanke & Christensen (1993) naval vessel, C_B = ∇/(LBT) = 357/(51.5·8.6·2.3), for a
    #: loading change (SI): m, I_z × f_m; Y_v̇, N_ṙ, Y_|u|v, Y_ur, N_|u|v, N_|u|r × the factors
    #: of Y'_v̇, N'_ṙ, Y'_v, Y'_r, N'_v, N'_r
    hull = Hull(L=51.5, B=8.6, T=2.3, C_B=357.0 / (51.5 * 8.6 * 2.3))
    scaled_by: ClassVar[dict[str, str]] = {
        "m": "mass",
        "Iz": "mass",
        "Y_vdot": "Yvdot",
        "N_rdot": "Nrdot",
        "Y_auv": "Yv",
        "Y_ur": "Yr",
        "N_auv": "Nv",
        "N_aur": "Nr",
    }

    def rudder_forces(
        self, u: Any, v: Any, r: Any, delta: Any, p: Any, ops: SimpleNamespace
    ) -> tuple[Any, Any, Any]:
        """(X_R, Y_R, N_R) [N, N, N m] of the rudder (module docstring)."""
        k = 0.5 * p.rho * p.A_R * p.dCL
        if self.variant == "linear":
            force = k * u * u * ops.clip(delta, -p.alpha_stall, p.alpha_stall)
            y_r = -force
            return -force * delta, y_r, p.x_R * y_r
        v_rudder = v + p.x_R * r
        alpha = delta + ops.atan2(v_rudder, u)
        force = k * (u * u + v_rudder * v_rudder) * ops.clip(alpha, -p.alpha_stall, p.alpha_stall)
        y_r = -force * ops.cos(delta)
        return -force * ops.sin(delta), y_r, p.x_R * y_r

    def accelerations(
        self, u: Any, v: Any, r: Any, delta: Any, p: Any, ops: SimpleNamespace
    ) -> tuple[Any, Any, Any]:
        x_r, y_r, n_r = self.rudder_forces(u, v, r, delta, p, ops)
        # speed equation: Fossen (2002) Blanke model, navalvessel X terms + X_c
        uau, vr, rr, _ = surge_regressors(u, v, r, delta, ops, False)
        force_x = p.X_uau * uau + (p.m + p.X_vr) * vr + p.m * p.xG * rr + thrust(p) + x_r
        # steering equations (Y_ur u r and N_|u|r |u| r as in navalvessel; Coriolis −m u r)
        auv, ur, vav, var, rav, rar, _ = steering_regressors(u, v, r, delta, ops, False)
        force_y = (
            p.Y_auv * auv
            + (p.Y_ur - p.m) * ur
            + p.Y_vav * vav
            + p.Y_var * var
            + p.Y_rav * rav
            + p.Y_rar * rar
            + y_r
        )
        force_n = (
            p.N_auv * auv
            + p.N_aur * ops.abs(u) * r
            - p.m * p.xG * ur
            + p.N_vav * vav
            + p.N_var * var
            + p.N_rav * rav
            + p.N_rar * rar
            + n_r
        )
        m11, m12, m21, m22 = steering_mass_matrix(p)
        det = m11 * m22 - m12 * m21
        return (
            force_x / (p.m - p.X_udot),
            (m22 * force_y - m12 * force_n) / det,
            (m11 * force_n - m21 * force_y) / det,
        )


@dataclasses.dataclass(frozen=True)
class BlankeRegressionParams(ParameterRecord):
    """Coefficients of the identified form (Moreno-Salinas et al. 2013 eq. (13)), SI.

    u̇ = u_0 + Σ u_<term>·φ_u,  v̇ = v_0 + Σ v_<term>·φ_s,  ṙ = r_0 + Σ r_<term>·φ_s, with the
    regressors φ_u of :func:`surge_regressors` and φ_s of :func:`steering_regressors`; each
    coefficient already contains the inverse mass matrix.  Servo, length and speed as the
    plant's.  Defaults: all zero (a ship that keeps its speed and does not turn).
    """

    u_0: float = 0.0  # thrust / (m − X_u̇) [m/s²]
    u_uau: float = 0.0
    u_vr: float = 0.0
    u_rr: float = 0.0
    u_dd: float = 0.0
    v_0: float = 0.0  # [m/s²]
    v_auv: float = 0.0
    v_ur: float = 0.0
    v_vav: float = 0.0
    v_var: float = 0.0
    v_rav: float = 0.0
    v_rar: float = 0.0
    v_d: float = 0.0
    r_0: float = 0.0  # [rad/s²]
    r_auv: float = 0.0
    r_ur: float = 0.0
    r_vav: float = 0.0
    r_var: float = 0.0
    r_rav: float = 0.0
    r_rar: float = 0.0
    r_d: float = 0.0
    L: float = 51.5  # ship length [m]
    U0: float = 8.0  # nominal speed (start of manoeuvres) [m/s]
    T_delta: float = 1.0  # servo time constant [s]
    delta_max: float = 35.0 * DEG  # rudder angle limit [rad]
    delta_dot_max: float = 5.0 * DEG  # rudder rate limit [rad/s]

    positive: ClassVar[tuple[str, ...]] = ("L", "U0", "T_delta", "delta_max", "delta_dot_max")


class BlankeRegression(_Blanke3DOF):
    """The Blanke ship in identified form, ν̇ = Θ·φ(ν, δ) + b (Moreno-Salinas et al. 2013).

    Variant ``"paper"``: rudder regressors δ² and δ (the paper's constant-speed form);
    ``"speed_scaled"``: u²δ² and u²δ (exact for the plant's ``"linear"`` rudder).
    """

    name = "blanke_regression"
    params_type = BlankeRegressionParams
    rudder_limit = 35.0 * DEG
    rudder_rate_limit = 5.0 * DEG
    variants = ("paper", "speed_scaled")

    def accelerations(
        self, u: Any, v: Any, r: Any, delta: Any, p: Any, ops: SimpleNamespace
    ) -> tuple[Any, Any, Any]:
        scaled = self.variant == "speed_scaled"
        phi_u = surge_regressors(u, v, r, delta, ops, scaled)
        phi_s = steering_regressors(u, v, r, delta, ops, scaled)
        return (
            _linear_form(p, "u", SURGE_TERMS, phi_u),
            _linear_form(p, "v", STEERING_TERMS, phi_s),
            _linear_form(p, "r", STEERING_TERMS, phi_s),
        )


def _linear_form(p: Any, equation: str, terms: tuple[str, ...], regressors: list[Any]) -> Any:
    """b + Σ θ_i φ_i of one equation of the identified form (eq. (11))."""
    total = getattr(p, f"{equation}_0")
    for term, phi in zip(terms, regressors, strict=True):
        total = total + getattr(p, f"{equation}_{term}") * phi
    return total


def regression_coefficients(
    params: BlankeParams | None = None,
    rudder: str = "linear",
    rudder_regressors: str = "speed_scaled",
    speed: float | None = None,
) -> BlankeRegressionParams:
    """The plant's coefficients in identified form (the truth an identification should find).

    Exact for the ``"linear"`` rudder with ``"speed_scaled"`` regressors (u ≥ 0, |δ| below
    stall).  For ``rudder="effective_angle"`` the inflow terms are linearised (atan x ≈ x,
    U_R² ≈ u², cos δ ≈ 1, sin δ ≈ δ; the cross terms −k u v δ, −k x_R u r δ of X_R are
    dropped).  With ``"paper"`` regressors the rudder terms are evaluated at ``speed``
    (default U0).
    """
    p = params if params is not None else BlankeParams()
    if rudder not in Blanke.variants:
        raise ValueError(f"rudder must be one of {Blanke.variants}, got {rudder!r}")
    if rudder_regressors not in BlankeRegression.variants:
        raise ValueError(
            f"rudder_regressors must be one of {BlankeRegression.variants}, "
            f"got {rudder_regressors!r}"
        )
    k = 0.5 * p.rho * p.A_R * p.dCL
    scale = 1.0 if rudder_regressors == "speed_scaled" else (speed or p.U0) ** 2
    mu = p.m - p.X_udot
    values = {
        "u_0": thrust(p) / mu,
        "u_uau": p.X_uau / mu,
        "u_vr": (p.m + p.X_vr) / mu,
        "u_rr": p.m * p.xG / mu,
        "u_dd": -k * scale / mu,
    }
    y = np.array(
        [p.Y_auv, p.Y_ur - p.m, p.Y_vav, p.Y_var, p.Y_rav, p.Y_rar, -k * scale], dtype=float
    )
    n = np.array(
        [p.N_auv, p.N_aur - p.m * p.xG, p.N_vav, p.N_var, p.N_rav, p.N_rar, -p.x_R * k * scale],
        dtype=float,
    )
    if rudder == "effective_angle":  # α ≈ δ + (v + x_R r)/u: −k u v − k x_R u r in Y_R
        y[0] -= k
        y[1] -= k * p.x_R
        n[0] -= p.x_R * k
        n[1] -= p.x_R * p.x_R * k
    m11, m12, m21, m22 = steering_mass_matrix(p)
    inverse = np.linalg.inv(np.array([[m11, m12], [m21, m22]]))
    accel = inverse @ np.vstack([y, n])
    for i, term in enumerate(STEERING_TERMS):
        values[f"v_{term}"] = float(accel[0, i])
        values[f"r_{term}"] = float(accel[1, i])
    return BlankeRegressionParams(
        **values,
        L=p.L,
        U0=p.U0,
        T_delta=p.T_delta,
        delta_max=p.delta_max,
        delta_dot_max=p.delta_dot_max,
    )


#: the blanke ship
SHIP = Ship(
    model=Blanke,
    adapted=hull_quantities("T_delta", "delta_dot_max", "dCL"),
    env_ids=(
        EnvId("ShipPathFollow-Blanke-v0", "blanke_current_shift", 3500),
        EnvId("ShipPathFollow-Blanke-v1", "blanke_rudder_aging", 1290),
    ),
)
