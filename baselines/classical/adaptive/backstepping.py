"""Backstepping heading law — Xu, Oliveira & Guedes Soares (2021) eqs. (27)–(35).

On the design model T·ṙ + σH(r)·r = ρK·δ + b (:mod:`.design_model`) with estimates
(ρ̂, σ̂, b̂): z1 = ψ − ψd, α = ψ̇d − K1·z1 (eq. (30)), z2 = r − α, and the rudder of
eq. (35) makes the error system ż1 = −K1·z1 + z2, T·ż2 = −c·z1 − K2·z2 when the estimates
are exact (c = 1 s⁻¹ in the paper; :mod:`.settings`, "Gain transfer").
"""

from __future__ import annotations

from shipgym.angles import wrap_angle
from shipgym_baselines.classical.adaptive.design_model import NonlinearNomoto
from shipgym_baselines.classical.adaptive.settings import Gains


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

    unsaturated.  Uses K1, K2 and c (``z1_weight``) of ``gains``.

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
