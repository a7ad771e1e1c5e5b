"""Design model of the adaptive backstepping controllers — Xu, Oliveira & Guedes Soares
(2021) eqs. (15)–(17).

ψ̇ = r, T*ṙ + H*(r)·r = K*·δ + b* with H(r) = 1 + a2·r², T* = ηT, H* = σH, K* = ρK; divided
by η: T·ṙ + σ_η·H(r)·r = ρ_η·K·δ + b*_η.  The nominal K, T, a2 of a ship (the paper gives
them for its ship only):

* K and T from the identification pipeline,
:func:`shipgym.identification.nominal.first_order_nomoto`
  (closed form T = T1 + T2 − T3 for nomoto2, else Nomoto's reduction of the 2nd-order model
  fitted to the ship's 20/20 zig-zag, :func:`shipgym.identification.zigzag.ship_nomoto`);
* a2: for nomoto2 the model's own cubic-damping coefficient β (β·r³ = a2·r³ in the reduced
  model); on other ships a least-squares fit of T·ṙ + r + a2·r³ = K·δ + b to the same 20/20
  zig-zag with K, T fixed and a2 ≥ 0 (H(r) > 0, the paper's "positive nonlinear damping"),
  :func:`shipgym.identification.cubic_damping.ship_cubic_damping`.  a2 is weakly identified
  by a zig-zag; σ̂ adapts the whole damping term online.
"""

from __future__ import annotations

import dataclasses

from shipgym.identification.cubic_damping import ship_cubic_damping
from shipgym.identification.nominal import first_order_nomoto
from shipgym.models.base import ShipModel
from shipgym.models.nomoto2 import Nomoto2


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


def nominal_design_model(model: ShipModel) -> NonlinearNomoto:
    """The design model (module doc) for a ship's nominal model."""
    K, T = first_order_nomoto(model)
    if isinstance(model, Nomoto2):
        a2 = float(model.params.beta)
        if a2 < 0:
            raise ValueError(f"nomoto2 beta = {a2} < 0: H(r) = 1 + beta·r² must stay positive")
    else:
        a2 = ship_cubic_damping(model, K, T)
    return NonlinearNomoto(K=float(K), T=float(T), a2=a2)
