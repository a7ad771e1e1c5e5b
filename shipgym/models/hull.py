"""A hull's main particulars and what a new draught does to its linear derivatives.

Clarke, Gedling & Hine (1983), "The application of manoeuvring criteria in hull design
using linear theory", Trans. RINA 125, 45–68, regress the linear sway/yaw derivatives of
merchant hulls on the main ratios (prime system on ½ρL²U, ½ρL³U, ½ρL³, ½ρL⁴; S = π(T/L)²)::

    Y'_v̇ = −S(1 + 0.16 C_B B/T − 5.1 (B/L)²)      Y'_v = −S(1 + 0.40 C_B B/T)
    Y'_ṙ = −S(0.67 B/L − 0.0033 (B/T)²)           Y'_r = −S(−1/2 + 2.2 B/L − 0.080 B/T)
    N'_v̇ = −S(1.1 B/L − 0.041 B/T)                N'_v = −S(1/2 + 2.4 T/L)
    N'_ṙ = −S(1/12 + 0.017 C_B B/T − 0.33 B/L)    N'_r = −S(1/4 + 0.039 B/T − 0.56 B/L)

(the form of Fossen's ``clarke83``, MSS / PythonVehicleSimulator).  :func:`draught_factors`
gives the ratio of each regression at the new draught to that at the old one; each ship's
model maps the factors onto its own parameters (``ShipModel.loading_change``,
:mod:`shipgym.models.loading`).
"""

from __future__ import annotations

import dataclasses
import math

#: the derivatives :func:`clarke_derivatives` returns
DERIVATIVES = ("Yvdot", "Yrdot", "Nvdot", "Nrdot", "Yv", "Yr", "Nv", "Nr")


@dataclasses.dataclass(frozen=True)
class Hull:
    """Main particulars [m] and block coefficient [-] of a hull at its reference draught."""

    L: float  # length between perpendiculars [m]
    B: float  # breadth [m]
    T: float  # draught [m]
    C_B: float  # block coefficient [-]


def clarke_derivatives(L: float, B: float, T: float, C_B: float) -> dict[str, float]:
    """Clarke et al. (1983) linear derivatives (prime, module doc) of a hull [-]."""
    s = math.pi * (T / L) ** 2
    b_l, b_t = B / L, B / T
    return {
        "Yvdot": -s * (1.0 + 0.16 * C_B * b_t - 5.1 * b_l**2),
        "Yrdot": -s * (0.67 * b_l - 0.0033 * b_t**2),
        "Nvdot": -s * (1.1 * b_l - 0.041 * b_t),
        "Nrdot": -s * (1.0 / 12.0 + 0.017 * C_B * b_t - 0.33 * b_l),
        "Yv": -s * (1.0 + 0.40 * C_B * b_t),
        "Yr": -s * (-0.5 + 2.2 * b_l - 0.080 * b_t),
        "Nv": -s * (0.5 + 2.4 * T / L),
        "Nr": -s * (0.25 + 0.039 * b_t - 0.56 * b_l),
    }


def draught_factors(hull: Hull, draught_ratio: float) -> dict[str, float]:
    """Factors new/old of the mass (``mass``) and of each derivative in
    :data:`DERIVATIVES` when the draught becomes ``draught_ratio``·T [-]."""
    if draught_ratio <= 0.0:
        raise ValueError(f"draught_ratio must be > 0, got {draught_ratio}")
    old = clarke_derivatives(hull.L, hull.B, hull.T, hull.C_B)
    new = clarke_derivatives(hull.L, hull.B, hull.T * draught_ratio, hull.C_B)
    return {"mass": draught_ratio, **{k: new[k] / old[k] for k in DERIVATIVES}}


def inertia_after(rigid: float, added: float, factors: dict[str, float], key: str) -> float:
    """(rigid − added) after the change: the rigid part × the mass factor, the added part ×
    the factor of derivative ``key``."""
    return rigid * factors["mass"] - added * factors[key]
