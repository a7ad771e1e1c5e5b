"""State predictor with projection adaptation — Xu, Oliveira & Guedes Soares (2021)
eqs. (18)–(26).

On the design model T·ṙ + σ·H(r)·r = ρ·K·δ + b (:mod:`.design_model`, the subscript η
dropped):

* state predictor, eq. (20):  ψ̂' = −Γ1·ψ̃ + r,
  r̂' = −Γ2·r̃ + T⁻¹(ρ̂·K·δ + b̂ − σ̂·H(r)·r), with ψ̃ = ψ̂ − ψ, r̃ = r̂ − r (eq. (18));
* adaptation, eqs. (24)–(25):  ρ̂' = γρ·Proj(ρ̂, −r̃Kδ), σ̂' = γσ·Proj(σ̂, r̃·H(r)·r),
  b̂' = γb·Proj(b̂, −r̃) (:func:`.projection.projection`), which make the Lyapunov function
  (22) obey dV/dt = −Γ1·ψ̃² − T·Γ2·r̃² while the projection is inactive (eq. (26)).

Integration (the paper gives none): the predictor runs on measurements sampled at a
uniform step h (the env's ``info["samples"]``), linearly interpolated between samples:
ψ̂ exactly (its equation is linear with affine forcing over a step), [r̂, ρ̂, σ̂, b̂] by
classical RK4 with ⌈Γ2·h/0.5⌉ substeps per step.  Its δ is the *measured rudder angle*
(the design model's input), so saturation, rate limits and servo lag do not corrupt the
adaptation.
"""

from __future__ import annotations

import math

import numpy as np

from shipgym.angles import unwrap_floats
from shipgym_baselines.classical.adaptive.design_model import NonlinearNomoto
from shipgym_baselines.classical.adaptive.projection import projection

#: the adaptive parameters, in the order of :attr:`StatePredictor.estimates`
PARAMETERS = ("rho", "sigma", "b")


def _projection_constants(lower: float, upper: float, epsilon: float) -> tuple[float, float]:
    """(c, w0²) of :func:`.projection.projection` for the bounds [lower, upper]."""
    return 0.5 * (lower + upper), (0.5 * (upper - lower)) ** 2 / (1.0 + epsilon)


class StatePredictor:
    """State predictor (eq. (20)) with projection adaptation (eq. (25)) — Xu et al. (2021).

    State: ψ̂ [rad], r̂ [rad/s], ρ̂ [-], σ̂ [-], b̂ [rad/s].  :meth:`advance` integrates it
    over one period from measurements sampled at a uniform step (module doc).

    Args:
        model: the design model (K, T, H(r)).
        gamma1, gamma2: predictor gains Γ1, Γ2 [1/s], > 0.
        gamma_rho, gamma_sigma, gamma_b: adaptation gains γρ, γσ [s], γb [1/s], ≥ 0
            (0 freezes that estimate).
        bounds: ``{"rho": (lo, hi), "sigma": (lo, hi), "b": (lo, hi)}``, the projection's
            sets (ρ, σ positive).
        epsilon: the projection's boundary-layer width ε, > 0.
        initial: (ρ̂(0), σ̂(0), b̂(0)), inside the bounds.
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
        for name, value in zip(PARAMETERS, initial, strict=True):
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
        """(ρ̂, σ̂, b̂ [rad/s])."""
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
        measurements are linearly interpolated.  ψ is unwrapped onto ψ̂'s branch.  The RK4
        stages evaluate :meth:`_rhs` written out on local floats (the same operations in
        the same order, so the same bits; ≈ 4× faster than calling it, tested).
        """
        psi_l = unwrap_floats(np.asarray(psi, dtype=float).tolist())  # numpy.unwrap's bits
        shift = 2.0 * math.pi * round((self.psi_hat - psi_l[0]) / (2.0 * math.pi))
        psi_l = [value + shift for value in psi_l]
        n_sub = max(1, math.ceil(self.gamma2 * step / 0.5))
        dt = step / n_sub
        half_dt, sixth_dt = 0.5 * dt, dt / 6.0
        decay = math.exp(-self.gamma1 * step)
        phi1 = (1.0 - decay) / self.gamma1  # ∫0^h e^{−Γ1(h−s)} ds
        phi2 = (step - phi1) / self.gamma1  # ∫0^h e^{−Γ1(h−s)} s ds
        gamma1, gamma2 = self.gamma1, self.gamma2
        K, T, a2 = self.model.K, self.model.T, self.model.a2
        g_rho, g_sigma, g_b = self.gammas
        eps = self.epsilon
        # the projection's constants per estimate (projection.projection, precomputed)
        (c_rho, w_rho), (c_sig, w_sig), (c_b, w_b) = (
            _projection_constants(*self.bounds[name], eps) for name in PARAMETERS
        )
        ew_rho, ew_sig, ew_b = eps * w_rho, eps * w_sig, eps * w_b

        def rhs(
            r_hat: float, rho: float, sigma: float, b: float, r: float, delta: float
        ) -> tuple[float, float, float, float]:
            h_r = 1.0 + a2 * r * r  # NonlinearNomoto.damping
            r_err = r_hat - r  # r̃, eq. (18)
            d_r = -gamma2 * r_err + (rho * K * delta + b - sigma * h_r * r) / T  # eq. (20)
            y = -r_err * K * delta  # eq. (25), each through projection()
            off = rho - c_rho
            f = (off * off - w_rho) / ew_rho
            d_rho = g_rho * (y * (1.0 - f) if f > 0.0 and y * off > 0.0 else y)
            y = r_err * h_r * r
            off = sigma - c_sig
            f = (off * off - w_sig) / ew_sig
            d_sig = g_sigma * (y * (1.0 - f) if f > 0.0 and y * off > 0.0 else y)
            y = -r_err
            off = b - c_b
            f = (off * off - w_b) / ew_b
            d_b = g_b * (y * (1.0 - f) if f > 0.0 and y * off > 0.0 else y)
            return d_r, d_rho, d_sig, d_b

        x0, x1, x2, x3 = self.r_hat, self.rho, self.sigma, self.b
        psi_hat = self.psi_hat
        r_l = np.asarray(r, dtype=float).tolist()
        d_l = np.asarray(delta, dtype=float).tolist()
        for j in range(len(psi_l) - 1):
            # ψ̂' = −Γ1·ψ̂ + (Γ1·ψ + r): exact for the affine interpolated forcing
            u0 = gamma1 * psi_l[j] + r_l[j]
            u1 = gamma1 * psi_l[j + 1] + r_l[j + 1]
            psi_hat = decay * psi_hat + u0 * phi1 + (u1 - u0) / step * phi2
            r0, dr = r_l[j], (r_l[j + 1] - r_l[j]) / n_sub
            e0, de = d_l[j], (d_l[j + 1] - d_l[j]) / n_sub
            for i in range(n_sub):
                ra, da = r0 + i * dr, e0 + i * de
                rm, dm = ra + 0.5 * dr, da + 0.5 * de
                a0, a1, a2_, a3 = rhs(x0, x1, x2, x3, ra, da)
                b0, b1, b2, b3 = rhs(
                    x0 + half_dt * a0,
                    x1 + half_dt * a1,
                    x2 + half_dt * a2_,
                    x3 + half_dt * a3,
                    rm,
                    dm,
                )
                c0, c1, c2, c3 = rhs(
                    x0 + half_dt * b0,
                    x1 + half_dt * b1,
                    x2 + half_dt * b2,
                    x3 + half_dt * b3,
                    rm,
                    dm,
                )
                d0, d1, d2, d3 = rhs(
                    x0 + dt * c0, x1 + dt * c1, x2 + dt * c2, x3 + dt * c3, ra + dr, da + de
                )
                x0 = x0 + sixth_dt * (a0 + 2.0 * b0 + 2.0 * c0 + d0)
                x1 = x1 + sixth_dt * (a1 + 2.0 * b1 + 2.0 * c1 + d1)
                x2 = x2 + sixth_dt * (a2_ + 2.0 * b2 + 2.0 * c2 + d2)
                x3 = x3 + sixth_dt * (a3 + 2.0 * b3 + 2.0 * c3 + d3)
        self.psi_hat = psi_hat
        self.r_hat, self.rho, self.sigma, self.b = x0, x1, x2, x3

    def lyapunov(self, psi: float, r: float, truth: tuple[float, float, float]) -> float:
        """V_pred of eq. (22) for true (ρ, σ, b) and measured ψ, r (γ = 0 terms omitted)."""
        v = 0.5 * (self.psi_hat - psi) ** 2 + 0.5 * self.model.T * (self.r_hat - r) ** 2
        for est, true, gain in zip(self.estimates, truth, self.gammas, strict=True):
            if gain > 0:
                v += 0.5 * (est - true) ** 2 / gain
        return v
