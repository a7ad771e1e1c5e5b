"""L1 adaptive backstepping heading control on time-varying vector-field guidance.

Xu, Oliveira & Guedes Soares (2021), §2–3 and §5.2, as two controllers:
``l1_backstepping`` (low-pass filter C(s) on, the paper's L1 controller) and
``adaptive_backstepping`` (filter off: "a typical adaptive backstepping controller", §5.2).

Design model (eqs. (15)–(17)): ψ̇ = r, T*ṙ + H*(r)·r = K*·δ + b* with H(r) = 1 + a2·r²,
T* = ηT, H* = σH, K* = ρK; divided by η: T·ṙ + σ_η·H(r)·r = ρ_η·K·δ + b*_η.  Pieces:

* state predictor, eq. (20):  ψ̂' = −Γ1·ψ̃ + r,
  r̂' = −Γ2·r̃ + T⁻¹(ρ̂·K·δ + b̂ − σ̂·H(r)·r), with ψ̃ = ψ̂ − ψ, r̃ = r̂ − r (eq. (18));
* adaptation with projection, eqs. (24)–(25):  ρ̂' = γρ·Proj(ρ̂, −r̃Kδ),
  σ̂' = γσ·Proj(σ̂, r̃·H(r)·r), b̂' = γb·Proj(b̂, −r̃) (the subscript η dropped);
* backstepping law, eqs. (27)–(35): z1 = ψ − ψd, α = ψ̇d − K1·z1, z2 = r − α,
  ρ̂Kδ = T·α̇ + σ̂H(r)α − b̂ − z1 + σ̂H(r)z2 − K2·z2, α̇ = ψ̈d − K1·ż1
  (:func:`backstepping_rudder`);
* low-pass filter, eq. (39): δ_ctrl = C(s)δ, C(s) = ω²/(s² + 2ζωs + ω²);
* guidance, eq. (48): ψd = γp − sgn(ye)·atan(|ye|^θ/Δ) − β, θ = 0.05|ye| + 1, Δ = 2L
  (:func:`shipgym.guidance.tvvf_heading`; Δ, θ and the error unit from the scenario's
  guidance settings, ``context.guidance.tvvf_*``, whose defaults are the paper's).

Gains (§5.2): K1 = 0.02, K2 = 15, Γ1 = 100·Iz, Γ2 = 10·Iz, γρ = γσ = 20, γb = 10,
ρ̂(0) = σ̂(0) = 1, b̂(0) = 0, ω = 0.25 rad/s, ζ = 1.

Choices where the paper is silent or ambiguous (options of :class:`L1BacksteppingSettings`):

* **Iz in Γ1 = 100·Iz, Γ2 = 10·Iz.**  The paper calls Iz "the inertia moment of the scaled
  ship model" without a value or unit; a Nomoto-model ship (nomoto2) has none, and the
  dimensional value (≈ 10² kg·m² for the 1:100 Esso Osaka) would put the predictor poles at
  10⁴ 1/s.  We read Iz as the unit factor of the scalar predictor (Γ·I in the L1
  literature): Γ1 = 100 1/s, Γ2 = 10 1/s (``gamma1``, ``gamma2``).
* **Nominal model.**  K and T from the identification pipeline,
  ``context.nominal_model.first_order_nomoto()`` (closed form T = T1 + T2 − T3 for nomoto2,
  else Nomoto's reduction of the 2nd-order model fitted to the ship's 20/20 zig-zag,
  :func:`shipgym.identification.zigzag.ship_nomoto`).  a2: for nomoto2 the model's own
  cubic-damping coefficient β (β·r³ = a2·r³ in the reduced model); on other ships a
  least-squares fit of T·ṙ + r + a2·r³ = K·δ + b to the same 20/20 zig-zag log with K, T
  fixed at the pipeline's values and a2 ≥ 0 (H(r) > 0, the paper's "positive nonlinear
  damping"); b is a nuisance bias (:func:`cubic_damping_from_zigzag`).  a2 is weakly
  identified by a zig-zag; σ̂ adapts the whole damping term online.
* **Projection.**  The smooth projection operator of Pomet & Praly (1992) in the form of
  Lavretsky & Wise (2013, *Robust and Adaptive Control*, §11.4): for each estimate a
  convex function f(θ) = ((θ − c)² − w0²)/(ε·w0²) with f = 0 on the inner interval
  [c ± w0] and f = 1 on the outer one [lo, hi] (w0 = (hi − lo)/(2√(1 + ε))), and
  Proj(θ, y) = y·(1 − f) when f > 0 and y points outwards, else y.  It is Lipschitz in θ,
  keeps [lo, hi] invariant and never increases the Lyapunov function (22) for true values
  in the inner interval.  Bounds (the paper gives none): ρ̂, σ̂ ∈ [0.1, 10] (positive, a
  factor of ten either way), |b̂| ≤ K·δmax (a larger bias cannot be held by the rudder);
  ε = 0.1.
* **Integration.**  Predictor and adaptation run at the env's fine step h on
  ``info["samples"]`` (measured ψ, r and rudder angle δ at t0, t0 + h, …, plus the
  measurement at t0 + Ts), linearly interpolated between samples: ψ̂ exactly (its
  equation is linear with affine forcing over a fine step), [r̂, ρ̂, σ̂, b̂] by classical RK4
  with ⌈Γ2·h/0.5⌉ substeps per fine step.  The predictor's δ is the *measured rudder
  angle* (the design model's input), so saturation, rate limits and servo lag do not
  corrupt the adaptation.  Without samples (a missing or diverged step) the period's two
  end measurements are interpolated instead.
* **Control law and filter at Ts.**  The law (35) is evaluated once per control period
  (the command is held over Ts anyway) and saturated at ±δmax; with the filter on, C(s) is
  driven by that zero-order-held law output and the command over [t_k, t_k + Ts) is the
  period average of C(s)'s exact continuous output, (1/Ts)∫y dt (exact ZOH discretisation
  of C(s) augmented with ∫y, :class:`SecondOrderLowPass`); the filter states at the
  sample instants equal C(s)'s continuous response exactly.
* **Filter placement** (``filter_placement``).  Eq. (39) writes δ_ctrl = C(s)δ with δ the
  whole law (35), and §3.2 motivates it by the adaptation: "the adaption of uncertainties of
  parameters may contain high-frequency signals"; Fig. 4 shows "control law with low-pass
  filter".  Default ``"command"``: C(s) on the whole (saturated) law, as eq. (39) is
  printed.  ``"adaptive"``: C(s) only on the estimates' share of the law,
  δ = δ_nom + C(s)(δ − δ_nom) with δ_nom the law (35) at the initial estimates ρ̂ = σ̂ = 1,
  b̂ = 0 (unsaturated, the sum saturated) — the standard L1 structure u = u_m + C(s)u_ad of
  Hovakimyan & Cao (2010), the paper's ref. [21].  With exact nominal estimates the filtered
  share is zero, so the linearised loop is that of ``adaptive_backstepping`` (stable); on
  ``osaka_stochastic_current`` the estimates stay within 0.5 % of nominal and this variant
  is indistinguishable from ``adaptive_backstepping`` (``shipgym reproduce xu2021``).
* **Reference derivatives.**  ψ̇d and ψ̈d from the guidance law's analytic derivatives in
  ye along the kinematics ẏe = U·sin(χ − γp) (eq. (8)), ÿe = U·cos(χ − γp)·r (constant
  U, χ̇ ≈ r, β̇ ≈ 0); the leg switches' steps in γp, and the tangent rate on a PCHIP path,
  are not differentiated.
* **Gain transfer** (``gain_transfer``).  The §5.2 gains were chosen for the 1:100 Esso
  Osaka model (L = 3.25 m, U0 = 0.41 m/s); nothing in the paper says how they carry to
  another ship, and used literally they fail on ships of another size (on nomoto2, whose
  L/U is 6.7 times shorter, the 4-s filter destabilises the loop; on the 172-m Mariner the
  TVVF in metres is a step at ±30 m and the −z1 term alone asks for 23 rad of rudder per
  rad of heading error).  Default ``"similarity"``: the paper's design scaled to the ship
  by its time scale τ = (L/U)/(L/U)_paper and length scale λ = L/L_paper (the prime
  system of the paper's model).  Divided by τ: K1, Γ1, Γ2, γb [1/s], ω and the weight c
  of the −c·z1 term of eq. (35) (c = 1 s⁻¹ implicitly in the paper: with
  V2 = ½z1² + ½T·z2²/c the law gives T·ż2 = −c·z1 − K2·z2 and cancels the cross term);
  multiplied by τ: γρ, γσ [s]; kept: K2 (dimensionless); the TVVF's metre becomes λ
  metres (ye/λ and Δ/λ in the law) unless the scenario measures ye in ship lengths.  On
  the paper's ship τ = 0.996 and λ = 1 (the printed gains within 0.4 %).  ``"literal"``
  uses the printed numbers on every ship.
* **Drift angle β** (eq. (48); the paper assumes it measured): course over ground from the
  last period's position change minus the period's mean measured heading
  (``drift_compensation``); β = 0 on the first step.  U is the speed over ground of the
  same period (nominal speed on the first step).

Behaviour (seed 0, tests/test_l1_backstepping.py).  Linearised on its design model, the
printed design is stable without C(s) and *unstable* with C(s) on the whole command on
every ship, the paper's own included (Esso Osaka: K2 = 15 makes the yaw-rate loop cross
over near 0.45 rad/s, above ω, with a phase margin of −26°; pole at +0.070 1/s,
:func:`linearised_closed_loop_poles`).  ``l1_backstepping`` therefore settles into an
oscillation bounded by the rudder limit (Esso Osaka, calm water: rudder ±30°, heading
±15°, period ≈ 33 s) instead of the smooth rudder the paper describes;
``adaptive_backstepping`` is stable, its saturated high-gain law switching at the control
rate.  Both reach the goal on nomoto2 ``nominal``, ``blanke_current_shift`` and
``osaka_stochastic_current``; on ``mariner_track`` (steering gear rate-limited to
3.8°/s) the adaptive controller converges on each leg and the L1 one oscillates with
hundreds of metres of cross-track error.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from typing import Any

import numpy as np
import scipy.linalg
import scipy.signal
from scipy.optimize import lsq_linear

from shipgym.envs.context import ControllerContext
from shipgym.guidance import TVVF_PAPER_SHIP_LENGTH, tvvf_heading
from shipgym.manoeuvres import zigzag
from shipgym.models.base import ShipModel
from shipgym.models.nomoto2 import Nomoto2
from shipgym.paths import wrap_angle

__all__ = [
    "AdaptiveBackstepping",
    "Gains",
    "L1Backstepping",
    "L1BacksteppingSettings",
    "NonlinearNomoto",
    "SecondOrderLowPass",
    "StatePredictor",
    "backstepping_rudder",
    "cubic_damping_from_zigzag",
    "high_frequency_power",
    "linearised_closed_loop_poles",
    "nominal_design_model",
    "projection",
    "tvvf_heading_derivatives",
]


# --------------------------------------------------------------------------------------------
# Design model
# --------------------------------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class NonlinearNomoto:
    """T·ṙ + H(r)·r = K·δ + b, H(r) = 1 + a2·r² — Xu et al. (2021) eq. (15)."""

    K: float  # Nomoto gain [1/s]
    T: float  # Nomoto time constant [s]
    a2: float  # cubic damping [s²] (r in rad/s)

    def __post_init__(self) -> None:
        if not (self.T > 0 and self.K != 0 and self.a2 >= 0):
            raise ValueError(f"need T > 0, K ≠ 0 and a2 ≥ 0, got {self}")

    def damping(self, r: float) -> float:
        """H(r) = 1 + a2·r² [-]."""
        return 1.0 + self.a2 * r * r


def cubic_damping_from_zigzag(model: ShipModel, K: float, T: float) -> float:
    """a2 [s²] of T·ṙ + r + a2·r³ = K·δ + b fitted to the ship's 20/20 zig-zag (a2 ≥ 0).

    K [1/s] and T [s] are held at the identification pipeline's values; a2 and the bias b
    are the bounded linear least-squares solution (scipy ``lsq_linear``) of
    a2·r³ − b = K·δ − T·ṙ − r over the log (ṙ by central differences).
    """
    return _cubic_damping_cached(
        type(model), model.variant, tuple(model.params.to_vector().tolist()), K, T
    )


@functools.lru_cache(maxsize=64)
def _cubic_damping_cached(
    cls: type, variant: str | None, params: tuple[float, ...], K: float, T: float
) -> float:
    model = cls(cls.params_type.from_vector(params), variant)
    log, _ = zigzag(model, 20.0)
    r_dot = np.gradient(log.r, log.h)
    regressors = np.column_stack([log.r**3, -np.ones_like(log.r)])
    target = K * log.delta - T * r_dot - log.r
    sol = lsq_linear(regressors, target, bounds=([0.0, -np.inf], [np.inf, np.inf]))
    return float(sol.x[0])


def nominal_design_model(model: ShipModel) -> NonlinearNomoto:
    """The design model (module doc, "Nominal model") for a ship's nominal model."""
    K, T = model.first_order_nomoto()
    if isinstance(model, Nomoto2):
        a2 = float(model.params.beta)
        if a2 < 0:
            raise ValueError(f"nomoto2 beta = {a2} < 0: H(r) = 1 + beta·r² must stay positive")
    else:
        a2 = cubic_damping_from_zigzag(model, K, T)
    return NonlinearNomoto(K=float(K), T=float(T), a2=a2)


# --------------------------------------------------------------------------------------------
# Projection operator
# --------------------------------------------------------------------------------------------
def projection(theta: float, y: float, lower: float, upper: float, epsilon: float = 0.1) -> float:
    """Smooth projection Proj(θ, y) keeping θ in [lower, upper] (module doc).

    Pomet & Praly (1992); Lavretsky & Wise (2013) §11.4, for a scalar: with centre c,
    inner half-width w0 = (upper − lower)/(2√(1 + ε)) and f(θ) = ((θ − c)² − w0²)/(ε·w0²),
    returns y·(1 − f) if f > 0 and y·(θ − c) > 0 (pointing outwards in the boundary
    layer), else y.  f reaches 1 exactly at lower and upper.
    """
    centre = 0.5 * (lower + upper)
    w0_sq = (0.5 * (upper - lower)) ** 2 / (1.0 + epsilon)
    offset = theta - centre
    f = (offset * offset - w0_sq) / (epsilon * w0_sq)
    if f > 0.0 and y * offset > 0.0:
        return y * (1.0 - f)
    return y


# --------------------------------------------------------------------------------------------
# State predictor and adaptation
# --------------------------------------------------------------------------------------------
class StatePredictor:
    """State predictor (eq. (20)) with projection adaptation (eq. (25)) — Xu et al. (2021).

    State: ψ̂ [rad], r̂ [rad/s], ρ̂ [-], σ̂ [-], b̂ [rad/s].  :meth:`advance` integrates it
    over one period from measurements sampled at a uniform step (module doc,
    "Integration").
    """

    def __init__(
        self,
        model: NonlinearNomoto,
        gamma1: float,
        gamma2: float,
        gamma_rho: float,
        gamma_sigma: float,
        gamma_b: float,
        bounds: dict[str, tuple[float, float]],
        epsilon: float = 0.1,
        initial: tuple[float, float, float] = (1.0, 1.0, 0.0),
    ) -> None:
        if not (gamma1 > 0 and gamma2 > 0):
            raise ValueError(f"predictor gains Γ1, Γ2 must be > 0, got {gamma1}, {gamma2}")
        if min(gamma_rho, gamma_sigma, gamma_b) < 0:
            raise ValueError("adaptation gains must be ≥ 0")
        if not epsilon > 0:
            raise ValueError(f"projection epsilon must be > 0, got {epsilon}")
        for name, value in zip(("rho", "sigma", "b"), initial, strict=True):
            lo, hi = bounds[name]
            if not lo < hi:
                raise ValueError(f"{name} bounds must satisfy lower < upper, got {bounds[name]}")
            if not lo <= value <= hi:
                raise ValueError(f"initial {name} = {value} is outside its bounds {bounds[name]}")
        if bounds["rho"][0] <= 0 or bounds["sigma"][0] <= 0:
            raise ValueError("rho and sigma bounds must be positive (ρ, σ ∈ ℝ⁺, eq. (16))")
        self.model = model
        self.gamma1, self.gamma2 = gamma1, gamma2
        self.gammas = (gamma_rho, gamma_sigma, gamma_b)
        self.bounds = bounds
        self.epsilon = epsilon
        self.initial = initial
        self.psi_hat = 0.0
        self.r_hat = 0.0
        self.rho, self.sigma, self.b = initial

    def reset(self, psi: float, r: float) -> None:
        """Predictor at the measured state, estimates at their initial values (§5.2)."""
        self.psi_hat, self.r_hat = float(psi), float(r)
        self.rho, self.sigma, self.b = self.initial

    @property
    def estimates(self) -> tuple[float, float, float]:
        return self.rho, self.sigma, self.b

    def _rhs(self, s: list[float], r: float, delta: float) -> list[float]:
        """d/dt [r̂, ρ̂, σ̂, b̂] at measured r [rad/s], rudder δ [rad]."""
        r_hat, rho, sigma, b = s
        m = self.model
        h_r = m.damping(r)
        r_err = r_hat - r  # r̃, eq. (18)
        g_rho, g_sigma, g_b = self.gammas
        lo_hi, eps = self.bounds, self.epsilon
        return [
            -self.gamma2 * r_err + (rho * m.K * delta + b - sigma * h_r * r) / m.T,  # eq. (20)
            g_rho * projection(rho, -r_err * m.K * delta, *lo_hi["rho"], eps),  # eq. (25)
            g_sigma * projection(sigma, r_err * h_r * r, *lo_hi["sigma"], eps),
            g_b * projection(b, -r_err, *lo_hi["b"], eps),
        ]

    def advance(self, psi: np.ndarray, r: np.ndarray, delta: np.ndarray, step: float) -> None:
        """Integrate over the samples psi, r, delta [rad, rad/s, rad] at spacing step [s].

        The arrays hold n + 1 samples at t0, t0 + step, …, t0 + n·step; between samples the
        measurements are linearly interpolated.  ψ is unwrapped onto ψ̂'s branch.
        """
        psi = np.unwrap(np.asarray(psi, dtype=float))
        psi = psi + 2.0 * math.pi * round((self.psi_hat - psi[0]) / (2.0 * math.pi))
        n_sub = max(1, math.ceil(self.gamma2 * step / 0.5))
        dt = step / n_sub
        decay = math.exp(-self.gamma1 * step)
        phi1 = (1.0 - decay) / self.gamma1  # ∫0^h e^{−Γ1(h−s)} ds
        phi2 = (step - phi1) / self.gamma1  # ∫0^h e^{−Γ1(h−s)} s ds
        s = [self.r_hat, self.rho, self.sigma, self.b]
        psi_l = psi.tolist()
        r_l = np.asarray(r, dtype=float).tolist()
        d_l = np.asarray(delta, dtype=float).tolist()
        for j in range(len(psi_l) - 1):
            # ψ̂' = −Γ1·ψ̂ + (Γ1·ψ + r): exact for the affine interpolated forcing
            u0 = self.gamma1 * psi_l[j] + r_l[j]
            u1 = self.gamma1 * psi_l[j + 1] + r_l[j + 1]
            self.psi_hat = decay * self.psi_hat + u0 * phi1 + (u1 - u0) / step * phi2
            r0, dr = r_l[j], (r_l[j + 1] - r_l[j]) / n_sub
            e0, de = d_l[j], (d_l[j + 1] - d_l[j]) / n_sub
            for i in range(n_sub):
                ra, da = r0 + i * dr, e0 + i * de
                rm, dm = ra + 0.5 * dr, da + 0.5 * de
                k1 = self._rhs(s, ra, da)
                k2 = self._rhs([x + 0.5 * dt * k for x, k in zip(s, k1, strict=True)], rm, dm)
                k3 = self._rhs([x + 0.5 * dt * k for x, k in zip(s, k2, strict=True)], rm, dm)
                k4 = self._rhs([x + dt * k for x, k in zip(s, k3, strict=True)], ra + dr, da + de)
                s = [
                    x + dt / 6.0 * (a + 2.0 * b + 2.0 * c + d)
                    for x, a, b, c, d in zip(s, k1, k2, k3, k4, strict=True)
                ]
        self.r_hat, self.rho, self.sigma, self.b = s

    def lyapunov(self, psi: float, r: float, truth: tuple[float, float, float]) -> float:
        """V_pred of eq. (22) for true (ρ, σ, b) and measured ψ, r (γ = 0 terms omitted)."""
        v = 0.5 * (self.psi_hat - psi) ** 2 + 0.5 * self.model.T * (self.r_hat - r) ** 2
        for est, true, gain in zip(self.estimates, truth, self.gammas, strict=True):
            if gain > 0:
                v += 0.5 * (est - true) ** 2 / gain
        return v


# --------------------------------------------------------------------------------------------
# Low-pass filter C(s)
# --------------------------------------------------------------------------------------------
class SecondOrderLowPass:
    """C(s) = ω²/(s² + 2ζωs + ω²) — Xu et al. (2021) eq. (39) — sampled at period Ts.

    The input is held over each period (ZOH); :meth:`step` returns the period average of
    C(s)'s exact continuous output, (1/Ts)∫y dt over [t_k, t_k + Ts), and advances the
    state to t_k + Ts.  Built by exact ZOH discretisation (matrix exponential) of C(s) in
    controllable form augmented with the integral of its output.
    """

    def __init__(self, frequency: float, damping: float, period: float) -> None:
        if not (frequency > 0 and damping > 0 and period > 0):
            raise ValueError(
                f"need frequency, damping, period > 0, got {frequency}, {damping}, {period}"
            )
        self.frequency, self.damping, self.period = frequency, damping, period
        w = frequency
        # states [y, ẏ, ∫y]; ÿ = −ω²y − 2ζωẏ + ω²u
        a = np.array([[0.0, 1.0, 0.0], [-w * w, -2.0 * damping * w, 0.0], [1.0, 0.0, 0.0]])
        b = np.array([[0.0], [w * w], [0.0]])
        m = np.zeros((4, 4))
        m[:3, :3], m[:3, 3:] = a, b
        e = scipy.linalg.expm(m * period)
        self._ad, self._bd = e[:3, :3], e[:3, 3]
        self.state = np.zeros(3)

    def transfer_function(self) -> tuple[np.ndarray, np.ndarray]:
        """(num, den) of C(s) for scipy.signal."""
        w = self.frequency
        return np.array([w * w]), np.array([1.0, 2.0 * self.damping * w, w * w])

    def reset(self, output: float = 0.0) -> None:
        """At rest at ``output`` (the steady state for a constant input of that value)."""
        self.state = np.array([output, 0.0, 0.0])

    @property
    def output(self) -> float:
        """y(t) at the current sample instant."""
        return float(self.state[0])

    def step(self, u: float) -> float:
        """Hold u over one period; return the period-average output."""
        nxt = self._ad @ np.array([self.state[0], self.state[1], 0.0]) + self._bd * u
        self.state = np.array([nxt[0], nxt[1], 0.0])
        return float(nxt[2]) / self.period


# --------------------------------------------------------------------------------------------
# Guidance derivatives
# --------------------------------------------------------------------------------------------
def tvvf_heading_derivatives(
    cross_track: float,
    delta: float,
    theta_slope: float = 0.05,
    theta_offset: float = 1.0,
    error_unit: float = 1.0,
) -> tuple[float, float]:
    """dψd/dye [rad/m] and d²ψd/dye² [rad/m²] of the TVVF law (eq. (48)).

    ψd = γp − sgn(ye)·atan(q(a)/D), a = |ye|/unit, D = Δ/unit, q(a) = a^θ(a),
    θ(a) = slope·a + offset.  With q' = q·(slope·ln a + θ/a) and
    q'' = q'·(slope·ln a + θ/a) + q·(2·slope/a − θ/a²), F = atan(q/D) has
    F' = (q'/D)/(1 + (q/D)²) and F'' = ((q''/D)(1 + (q/D)²) − 2(q/D)(q'/D)²)/(1 + (q/D)²)²;
    dψd/dye = −F'(a)/unit and d²ψd/dye² = −sgn(ye)·F''(a)/unit².  a is floored at 1e-9
    (the log singularity of q'' at ye = 0 has the small weight ``theta_slope``); far from the
    path (q/D > 1e12) both derivatives are 0.
    """
    unit = error_unit
    d = delta / unit
    a = max(abs(cross_track) / unit, 1e-9)
    th = theta_slope * a + theta_offset
    log_a = math.log(a)
    log_ratio = th * log_a - math.log(d)  # ln(q/D)
    if log_ratio > math.log(1e12):
        return 0.0, 0.0
    g = math.exp(log_ratio)  # q/D
    lam = theta_slope * log_a + th / a  # q'/q
    g1 = g * lam  # q'/D
    g2 = g1 * lam + g * (2.0 * theta_slope / a - th / (a * a))  # q''/D
    den = 1.0 + g * g
    f1 = g1 / den
    f2 = (g2 * den - 2.0 * g * g1 * g1) / (den * den)
    sign = 1.0 if cross_track > 0 else (-1.0 if cross_track < 0 else 0.0)
    return -f1 / unit, -sign * f2 / (unit * unit)


# --------------------------------------------------------------------------------------------
# Backstepping law
# --------------------------------------------------------------------------------------------
def backstepping_rudder(
    model: NonlinearNomoto,
    gains: Gains,
    heading: float,
    yaw_rate: float,
    reference: tuple[float, float, float],
    estimates: tuple[float, float, float],
) -> tuple[float, float, float]:
    """Rudder angle δ [rad] of the backstepping law — Xu et al. (2021) eqs. (27)–(35).

    z1 = ψ − ψd (wrapped), α = ψ̇d − K1·z1, z2 = r − α, α̇ = ψ̈d − K1·(r − ψ̇d) and

        ρ̂Kδ = T·α̇ + σ̂H(r)α − b̂ − c·z1 + σ̂H(r)z2 − K2·z2                     (35)

    (c = 1 s⁻¹ in the paper; module doc, "Gain transfer"), unsaturated.  With exact
    estimates the error system is ż1 = −K1·z1 + z2, T·ż2 = −c·z1 − K2·z2.

    Args:
        heading, yaw_rate: ψ [rad], r [rad/s].
        reference: (ψd [rad], ψ̇d [rad/s], ψ̈d [rad/s²]).
        estimates: (ρ̂, σ̂, b̂ [rad/s]).

    Returns:
        (δ [rad], z1 [rad], z2 [rad/s]).
    """
    psi_d, psi_d_dot, psi_d_ddot = reference
    rho, sigma, b = estimates
    z1 = float(wrap_angle(heading - psi_d))
    alpha = psi_d_dot - gains.K1 * z1
    z2 = yaw_rate - alpha
    alpha_dot = psi_d_ddot - gains.K1 * (yaw_rate - psi_d_dot)
    h_r = model.damping(yaw_rate)
    rhs = (
        model.T * alpha_dot
        + sigma * h_r * alpha
        - b
        - gains.z1_weight * z1
        + sigma * h_r * z2
        - gains.K2 * z2
    )
    return rhs / (rho * model.K), z1, z2


def linearised_closed_loop_poles(
    model: NonlinearNomoto,
    gains: Gains,
    filter_frequency: float | None = None,
    filter_damping: float = 1.0,
) -> np.ndarray:
    """Closed-loop poles [1/s] of the law (35) on its design model, linearised at r = 0.

    With exact estimates, a constant reference and H ≈ 1, eq. (35) is the PD law
    δ = −(Kp·z1 + Kd·r), Kp = (c + K1K2)/K, Kd = (K2 + T·K1 − 1)/K, and the loop
    T·ψ̈ + ψ̇ = K·C(s)δ has the characteristic polynomial
    s(Ts + 1)·D(s) + K·N(s)(Kd·s + Kp) with C = N/D (C ≡ 1 without the filter, when the
    poles are those of the designed error system ż1 = −K1z1 + z2, Tż2 = −c·z1 − K2z2).
    """
    K, T = model.K, model.T
    kp = (gains.z1_weight + gains.K1 * gains.K2) / K
    kd = (gains.K2 + T * gains.K1 - 1.0) / K
    num, den = np.array([1.0]), np.array([1.0])
    if filter_frequency is not None:
        w = filter_frequency
        num, den = np.array([w * w]), np.array([1.0, 2.0 * filter_damping * w, w * w])
    poly = np.polyadd(np.polymul([T, 1.0, 0.0], den), K * np.polymul(num, [kd, kp]))
    return np.roots(poly)


# --------------------------------------------------------------------------------------------
# Rudder activity figure
# --------------------------------------------------------------------------------------------
def high_frequency_power(signal: np.ndarray, period: float, cutoff: float) -> float:
    """Power of a signal above ``cutoff`` [rad/s]: ∫ PSD over f ≥ cutoff/2π [signal²].

    Welch's one-sided power spectral density (scipy.signal.welch, Hann segments of up to
    256 samples, mean removed) of ``signal`` sampled at ``period`` [s], integrated by the
    trapezoid rule; √ of the result is the RMS of the signal's content above the cutoff.
    """
    x = np.asarray(signal, dtype=float)
    if x.ndim != 1 or x.size < 8:
        raise ValueError(f"need a 1-D signal of at least 8 samples, got shape {x.shape}")
    if not (period > 0 and cutoff >= 0):
        raise ValueError(f"need period > 0 and cutoff ≥ 0, got {period}, {cutoff}")
    freq, psd = scipy.signal.welch(x, fs=1.0 / period, nperseg=min(256, x.size))
    high = freq >= cutoff / (2.0 * math.pi)
    if high.sum() < 2:
        return 0.0
    return float(np.trapezoid(psd[high], freq[high]))


# --------------------------------------------------------------------------------------------
# The controllers
# --------------------------------------------------------------------------------------------
#: where the low-pass filter C(s) acts (module doc, "Filter placement")
FILTER_PLACEMENTS = ("command", "adaptive")
#: the paper's ship: Esso Osaka 1:100 model, L = 325 m / 100, U0 = 0.41 m/s (§5.2)
PAPER_SHIP_LENGTH = TVVF_PAPER_SHIP_LENGTH  # [m], the 1:100 Esso Osaka model
PAPER_SHIP_SPEED = 0.41  # [m/s]


@dataclasses.dataclass(frozen=True)
class L1BacksteppingSettings:
    """Xu, Oliveira & Guedes Soares (2021) §5.2 values plus the choices of the module doc.

    The gains are the paper's, for the paper's ship; ``gain_transfer`` says how they are
    carried to the ship at hand (module doc, "Gain transfer").
    """

    K1: float = 0.02  # [1/s]
    K2: float = 15.0  # [-]
    z1_weight: float = 1.0  # c [1/s] of the −c·z1 term of eq. (35) (1 in the paper)
    gamma1: float = 100.0  # Γ1 = 100·Iz [1/s], Iz read as 1 (module doc)
    gamma2: float = 10.0  # Γ2 = 10·Iz [1/s]
    gamma_rho: float = 20.0  # γρ [s]
    gamma_sigma: float = 20.0  # γσ [s]
    gamma_b: float = 10.0  # γb [1/s]
    rho0: float = 1.0
    sigma0: float = 1.0
    b0: float = 0.0  # [rad/s]
    rho_bounds: tuple[float, float] = (0.1, 10.0)
    sigma_bounds: tuple[float, float] = (0.1, 10.0)
    b_bound_rudder: float = 1.0  # |b̂| ≤ b_bound_rudder·|K|·δmax
    projection_epsilon: float = 0.1
    filter_frequency: float = 0.25  # ω [rad/s]
    filter_damping: float = 1.0  # ζ
    #: where C(s) acts (module doc, "Filter placement"): "command" (eq. (39) as printed: the
    #: whole law) or "adaptive" (only the estimates' share of it, the standard L1 structure)
    filter_placement: str = "command"
    drift_compensation: bool = True  # subtract the measured drift angle β (eq. (48))
    #: unit of ye and Δ in the TVVF law: None = the scenario's (context.guidance), "m", "L"
    error_unit: str | None = None
    #: "similarity": time- and length-scale the gains from the paper's ship; "literal": as is
    gain_transfer: str = "similarity"
    paper_ship_length: float = PAPER_SHIP_LENGTH  # [m]
    paper_ship_speed: float = PAPER_SHIP_SPEED  # [m/s]


@dataclasses.dataclass(frozen=True)
class Gains:
    """The gains in use on one ship (after the gain transfer), SI."""

    K1: float  # [1/s]
    K2: float  # [-]
    z1_weight: float  # [1/s]
    gamma1: float  # [1/s]
    gamma2: float  # [1/s]
    gamma_rho: float  # [s]
    gamma_sigma: float  # [s]
    gamma_b: float  # [1/s]
    filter_frequency: float  # [rad/s]
    error_unit: float  # [m], unit of ye and Δ in the TVVF law
    time_scale: float  # τ [-], ship time over paper-ship time (1: literal)

    @classmethod
    def transfer(
        cls, s: L1BacksteppingSettings, ship_length: float, ship_speed: float, unit: str
    ) -> Gains:
        """Gains for a ship of length L [m] at speed U [m/s] (module doc, "Gain transfer").

        ``unit`` is the TVVF error unit asked for ("m" or "L").
        """
        if s.gain_transfer == "literal":
            tau, length_scale = 1.0, 1.0
        elif s.gain_transfer == "similarity":
            if not (s.paper_ship_length > 0 and s.paper_ship_speed > 0):
                raise ValueError("paper_ship_length and paper_ship_speed must be > 0")
            tau = (ship_length / ship_speed) / (s.paper_ship_length / s.paper_ship_speed)
            length_scale = ship_length / s.paper_ship_length
        else:
            raise ValueError(
                f"gain_transfer must be 'similarity' or 'literal', got {s.gain_transfer!r}"
            )
        return cls(
            K1=s.K1 / tau,
            K2=s.K2,
            z1_weight=s.z1_weight / tau,
            gamma1=s.gamma1 / tau,
            gamma2=s.gamma2 / tau,
            gamma_rho=s.gamma_rho * tau,
            gamma_sigma=s.gamma_sigma * tau,
            gamma_b=s.gamma_b / tau,
            filter_frequency=s.filter_frequency / tau,
            error_unit=ship_length if unit == "L" else length_scale,
            time_scale=tau,
        )


class L1Backstepping:
    """L1 adaptive backstepping heading control on TVVF guidance (``l1_backstepping``)."""

    name = "l1_backstepping"
    kind = "classical"
    #: C(s) of eq. (39) on the command (off: plain adaptive backstepping)
    low_pass = True

    def __init__(self, settings: L1BacksteppingSettings | None = None, **overrides: Any) -> None:
        base = settings if settings is not None else L1BacksteppingSettings()
        self.settings = dataclasses.replace(base, **overrides) if overrides else base
        s = self.settings
        if not (s.K1 > 0 and s.K2 > 0 and s.z1_weight >= 0):
            raise ValueError(
                f"need K1, K2 > 0 and z1_weight ≥ 0, got {s.K1}, {s.K2}, {s.z1_weight}"
            )
        if s.error_unit not in (None, "m", "L"):
            raise ValueError(f"error_unit must be 'm', 'L' or None, got {s.error_unit!r}")
        if s.gain_transfer not in ("similarity", "literal"):
            raise ValueError(
                f"gain_transfer must be 'similarity' or 'literal', got {s.gain_transfer!r}"
            )
        if s.filter_placement not in FILTER_PLACEMENTS:
            raise ValueError(
                f"filter_placement must be one of {FILTER_PLACEMENTS}, got {s.filter_placement!r}"
            )

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        if context.action_mode != "rudder":
            raise ValueError(
                f"{self.name} drives the rudder; make the env with action_mode='rudder'"
            )
        s = self.settings
        self.ctx = context
        self.model = nominal_design_model(context.nominal_model)
        g = context.guidance
        unit = s.error_unit if s.error_unit is not None else g.tvvf_error_unit
        self.gains = k = Gains.transfer(s, context.ship_length, context.nominal_speed, unit)
        b_max = s.b_bound_rudder * abs(self.model.K) * context.rudder_limit
        self.predictor = StatePredictor(
            self.model,
            k.gamma1,
            k.gamma2,
            k.gamma_rho,
            k.gamma_sigma,
            k.gamma_b,
            {"rho": s.rho_bounds, "sigma": s.sigma_bounds, "b": (-b_max, b_max)},
            s.projection_epsilon,
            (s.rho0, s.sigma0, s.b0),
        )
        self.filter = (
            SecondOrderLowPass(k.filter_frequency, s.filter_damping, context.control_period)
            if self.low_pass
            else None
        )
        self.delta = g.tvvf_delta_L * context.ship_length  # Δ = 2L
        self.tracker = context.new_tracker()
        self._started = False
        self._last: dict[str, Any] = {}
        self.history: dict[str, list[float]] = {
            k: []
            for k in ("t", "psi_err", "r_err", "rho", "sigma", "b", "law", "command", "z1", "z2")
        }

    # -- pieces ---------------------------------------------------------------------------
    def _update_predictor(self, info: dict[str, Any]) -> None:
        psi, r, delta = info["heading"], info["yaw_rate"], info["rudder_angle"]
        samples = info.get("samples")
        if samples is not None and len(samples["psi"]) > 0:
            step = self.ctx.fine_step
            psis = np.append(samples["psi"], psi)
            rs = np.append(samples["r"], r)
            deltas = np.append(samples["delta"], delta)
        else:  # no valid samples: the period's end points (module doc)
            last = self._last
            n = max(1, round(self.ctx.control_period / self.ctx.fine_step))
            step = self.ctx.control_period / n
            psis = np.linspace(last["psi"], last["psi"] + wrap_angle(psi - last["psi"]), n + 1)
            rs = np.linspace(last["r"], r, n + 1)
            deltas = np.linspace(last["delta"], delta, n + 1)
        self.predictor.advance(psis, rs, deltas, step)

    def _course(self, info: dict[str, Any]) -> tuple[float, float]:
        """(speed over ground U [m/s], drift angle β [rad]) over the last period."""
        if not self._started:
            return self.ctx.nominal_speed, 0.0
        x, y = info["position"]
        x0, y0 = self._last["position"]
        dx, dy = x - x0, y - y0
        speed = math.hypot(dx, dy) / self.ctx.control_period
        if not self.settings.drift_compensation or speed < 0.1 * self.ctx.nominal_speed:
            return max(speed, 0.1 * self.ctx.nominal_speed), 0.0
        samples = info.get("samples")
        if samples is not None and len(samples["psi"]) > 0:
            headings = np.unwrap(np.append(samples["psi"], info["heading"]))
            mean_heading = float(np.mean(headings))
        else:
            h0 = self._last["psi"]
            mean_heading = h0 + 0.5 * wrap_angle(info["heading"] - h0)
        return speed, float(wrap_angle(math.atan2(dy, dx) - mean_heading))

    # -- policy API -----------------------------------------------------------------------
    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        k, m, ctx = self.gains, self.model, self.ctx
        psi, r = float(info["heading"]), float(info["yaw_rate"])
        x, y = info["position"]
        if self._started:
            self._update_predictor(info)
            frame = self.tracker.update(x, y)
        else:
            self.predictor.reset(psi, r)
            frame = self.tracker.reset(x, y)
        speed, drift = self._course(info)
        # guidance, eq. (48), and its derivatives along the kinematics, eq. (8)
        ye, path_angle = frame.cross_track, frame.path_angle
        g = ctx.guidance
        psi_d = tvvf_heading(
            ye,
            path_angle,
            self.delta,
            sideslip=drift,
            theta_slope=g.tvvf_theta_slope,
            theta_offset=g.tvvf_theta_offset,
            error_unit=self.gains.error_unit,
        )
        d1, d2 = tvvf_heading_derivatives(
            ye, self.delta, g.tvvf_theta_slope, g.tvvf_theta_offset, self.gains.error_unit
        )
        rel_course = psi + drift - path_angle
        ye_dot = speed * math.sin(rel_course)
        ye_ddot = speed * math.cos(rel_course) * r
        psi_d_dot = d1 * ye_dot
        psi_d_ddot = d2 * ye_dot * ye_dot + d1 * ye_ddot
        # backstepping, eqs. (27)–(35)
        rho, sigma, b = self.predictor.estimates
        law, z1, z2 = backstepping_rudder(
            m, k, psi, r, (psi_d, psi_d_dot, psi_d_ddot), (rho, sigma, b)
        )
        limit = ctx.rudder_limit
        if self.filter is not None and self.settings.filter_placement == "adaptive":
            # δ = δ_nom + C(s)(δ − δ_nom), δ_nom the law at the initial (nominal) estimates
            s = self.settings
            nominal, _, _ = backstepping_rudder(
                m, k, psi, r, (psi_d, psi_d_dot, psi_d_ddot), (s.rho0, s.sigma0, s.b0)
            )
            command = nominal + self.filter.step(law - nominal)
            law = min(limit, max(-limit, law))
        else:
            law = min(limit, max(-limit, law))
            command = self.filter.step(law) if self.filter is not None else law
        command = min(limit, max(-limit, command))
        self._record(
            t=float(info["t"]),
            psi_err=float(wrap_angle(self.predictor.psi_hat - psi)),
            r_err=self.predictor.r_hat - r,
            rho=rho,
            sigma=sigma,
            b=b,
            law=law,
            command=command,
            z1=z1,
            z2=z2,
        )
        self._last = {
            "psi": psi,
            "r": r,
            "delta": float(info["rudder_angle"]),
            "position": (float(x), float(y)),
        }
        self._started = True
        return np.array([command / limit], dtype=np.float32)

    def _record(self, **values: float) -> None:
        for key, value in values.items():
            self.history[key].append(value)

    def episode_stats(self) -> dict[str, float]:
        """Final estimates, mean |r̃| and the command's RMS above the filter frequency."""
        h = self.history
        stats = {
            "rho_hat": h["rho"][-1],
            "sigma_hat": h["sigma"][-1],
            "b_hat": h["b"][-1],
            "mean_abs_r_prediction_error": float(np.mean(np.abs(h["r_err"]))),
        }
        if len(h["command"]) >= 8:
            power = high_frequency_power(
                np.array(h["command"]), self.ctx.control_period, self.gains.filter_frequency
            )
            stats["rudder_command_hf_rms_deg"] = math.degrees(math.sqrt(power))
        return stats


class AdaptiveBackstepping(L1Backstepping):
    """The same controller with C(s) off (``adaptive_backstepping``; Xu et al. 2021 §5.2)."""

    name = "adaptive_backstepping"
    low_pass = False
