"""Loading-condition changes of the 3-DOF ships: what a new draught does to the mass and
the linear hydrodynamic derivatives (the catalogue's ``{ship}_maneuverability_change``).

Clarke, Gedling & Hine (1983), "The application of manoeuvring criteria in hull design
using linear theory", Trans. RINA 125, 45–68, regress the linear sway/yaw derivatives of
merchant hulls on the main ratios (prime system on ½ρL²U, ½ρL³U, ½ρL³, ½ρL⁴; S = π(T/L)²)::

    Y'_v̇ = −S(1 + 0.16 C_B B/T − 5.1 (B/L)²)      Y'_v = −S(1 + 0.40 C_B B/T)
    Y'_ṙ = −S(0.67 B/L − 0.0033 (B/T)²)           Y'_r = −S(−1/2 + 2.2 B/L − 0.080 B/T)
    N'_v̇ = −S(1.1 B/L − 0.041 B/T)                N'_v = −S(1/2 + 2.4 T/L)
    N'_ṙ = −S(1/12 + 0.017 C_B B/T − 0.33 B/L)    N'_r = −S(1/4 + 0.039 B/T − 0.56 B/L)

(the form of Fossen's ``clarke83``, MSS / PythonVehicleSimulator).  A ship's own
derivatives are kept and multiplied by the *ratio* of the regression at the new draught to
that at the old one (:func:`draught_factors`): the regression supplies how a derivative
moves with draught, the ship's data where it starts.  The mass follows the displacement at
the same block coefficient (∝ T; an assumption: C_B falls a little with draught) and the
yaw inertia the mass at the same radius of gyration (an assumption).  The rudder and the
nonlinear derivatives are kept (rudder fully immersed in both conditions; Clarke et al. give
linear derivatives only), and so are the cross added masses Y'_ṙ, N'_v̇ (their regressions
change sign within the draughts used: a ratio means nothing there).

:func:`loading_change` maps the factors onto each model's parameters
(:data:`HULLS`: the particulars the regression is evaluated with):

* ``esso_osaka`` (prime): m' and (m − X_u̇)' × the mass factor; (m − Y_v̇)' =
  m'·f_m − Y'_v̇·f_Y'v̇ with Y'_v̇ = m' − (m − Y_v̇)'; (I_z − N_ṙ)' = I'_z·f_m − N'_ṙ·f_N'ṙ with
  I'_z = 0.0625 m' (radius of gyration 0.25 L, data file §1.2); Y'_v, Y'_r, N'_v, N'_r × their
  factors; the draught T itself (wetted surface).
* ``blanke`` (SI): m, I_z × f_m; Y_v̇, N_ṙ, Y_|u|v, Y_ur, N_|u|v, N_|u|r × the factors of
  Y'_v̇, N'_ṙ, Y'_v, Y'_r, N'_v, N'_r.
* ``kvlcc2`` (MMG standard method, prime on ½ρL²d at the reference draught d, which stays:
  the factors then scale the dimensional forces): the displacement volume ∇ and m'_x × the
  mass factor (I_zG follows ∇ at the same k_zz), m'_y and J'_z × the factors of Y'_v̇ and
  N'_ṙ (they are −Y'_v̇, −N'_ṙ), Y'_v, Y'_R, N'_v, N'_R × theirs; the resistance R'_0 is kept
  (the straight-run speed at the same revolutions stays: an assumption).
* ``mariner`` (de Wit–Oppe, ṙ = −a1·r − a2·r³ + a3·δ): read as the yaw row of the linear
  model without sway coupling, a1 = −N_r/(I_z − N_ṙ), a3 = N_δ/(I_z − N_ṙ), so a1 × f_Nr/f_I
  and a3 × 1/f_I with f_I the factor of (I_z − N_ṙ), split as Fossen's ``mariner.m``
  (Chislett & Strøm-Tejsen 1965: I'_z = 39.2e-5, N'_ṙ = −43.8e-5).
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


#: the particulars each ship's regression is evaluated with: Esso Osaka data file §1.2;
#: KVLCC2 full scale (Yasukawa & Yoshimura 2015, Table 1);
#: Mariner class after Chislett & Strøm-Tejsen (1965) (B, C_B as commonly quoted, T from
#: Fossen's m' = 798e-5 = C_B·B·T/(½L²): an assumption); Blanke & Christensen (1993) naval
#: vessel, C_B = ∇/(LBT) = 357/(51.5·8.6·2.3)
HULLS: dict[str, Hull] = {
    "esso_osaka": Hull(L=325.0, B=53.0, T=21.73, C_B=0.831),
    "mariner": Hull(L=160.93, B=23.17, T=7.47, C_B=0.6),
    "blanke": Hull(L=51.5, B=8.6, T=2.3, C_B=357.0 / (51.5 * 8.6 * 2.3)),
    "kvlcc2": Hull(L=320.0, B=58.0, T=20.8, C_B=0.810),
}

#: parameter -> the factor it is multiplied by, for the ships whose change is a product
SCALED_BY: dict[str, dict[str, str]] = {
    "blanke": {
        "m": "mass",
        "Iz": "mass",
        "Y_vdot": "Yvdot",
        "N_rdot": "Nrdot",
        "Y_auv": "Yv",
        "Y_ur": "Yr",
        "N_auv": "Nv",
        "N_aur": "Nr",
    },
    "kvlcc2": {
        "volume": "mass",
        "m_x": "mass",
        "m_y": "Yvdot",
        "J_z": "Nrdot",
        "Y_v": "Yv",
        "Y_R": "Yr",
        "N_v": "Nv",
        "N_R": "Nr",
    },
}

#: Mariner yaw inertia split (Fossen's mariner.m, prime ×1e-5 removed): I'_z, N'_ṙ
MARINER_IZ, MARINER_NRDOT = 39.2e-5, -43.8e-5


def _inertia(rigid: float, added: float, f: dict[str, float], key: str) -> float:
    """(rigid − added) after the change: the rigid part × the mass factor, the added part ×
    the factor of derivative ``key``."""
    return rigid * f["mass"] - added * f[key]


def loading_change(model: str, params: object, draught_ratio: float) -> dict[str, float]:
    """The parameters of ``model`` (``params``: its record before the change, config units)
    that change when the draught becomes ``draught_ratio``·T (module doc)."""
    if model not in HULLS:
        raise ValueError(f"no loading-condition model for {model!r}; valid: {sorted(HULLS)}")
    f = draught_factors(HULLS[model], draught_ratio)
    p = params
    if model == "esso_osaka":
        m = p.m  # type: ignore[attr-defined]
        iz = 0.0625 * m
        return {
            "m": m * f["mass"],
            "m_Xudot": p.m_Xudot * f["mass"],  # type: ignore[attr-defined]
            "m_Yvdot": _inertia(m, m - p.m_Yvdot, f, "Yvdot"),  # type: ignore[attr-defined]
            "Iz_Nrdot": _inertia(iz, iz - p.Iz_Nrdot, f, "Nrdot"),  # type: ignore[attr-defined]
            "Yv": p.Yv * f["Yv"],  # type: ignore[attr-defined]
            "Yr": p.Yr * f["Yr"],  # type: ignore[attr-defined]
            "Nv": p.Nv * f["Nv"],  # type: ignore[attr-defined]
            "Nr": p.Nr * f["Nr"],  # type: ignore[attr-defined]
            "T": p.T * draught_ratio,  # type: ignore[attr-defined]
        }
    if model in SCALED_BY:
        return {name: getattr(p, name) * f[key] for name, key in SCALED_BY[model].items()}
    f_inertia = _inertia(MARINER_IZ, MARINER_NRDOT, f, "Nrdot") / (MARINER_IZ - MARINER_NRDOT)
    return {
        "a1": p.a1 * f["Nr"] / f_inertia,  # type: ignore[attr-defined]
        "a3": p.a3 / f_inertia,  # type: ignore[attr-defined]
    }
