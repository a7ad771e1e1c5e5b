"""Loading-condition changes of the 3-DOF ships: what a new draught does to the mass and
the linear hydrodynamic derivatives (the catalogue's ``{ship}_maneuverability_change``).

Clarke, Gedling & Hine (1983) regress the linear sway/yaw derivatives of merchant hulls on
the main ratios (:mod:`shipgym.models.hull`).  A ship's own derivatives are kept and
multiplied by the *ratio* of the regression at the new draught to that at the old one
(:func:`~shipgym.models.hull.draught_factors`): the regression supplies how a derivative
moves with draught, the ship's data where it starts.  The mass follows the displacement at
the same block coefficient (∝ T; an assumption: C_B falls a little with draught) and the
yaw inertia the mass at the same radius of gyration (an assumption).  The rudder and the
nonlinear derivatives are kept (rudder fully immersed in both conditions; Clarke et al. give
linear derivatives only), and so are the cross added masses Y'_ṙ, N'_v̇ (their regressions
change sign within the draughts used: a ratio means nothing there).

:func:`loading_change` maps the factors onto each model's parameters by the model's own
``loading_change`` and ``hull``, read off its record (:data:`HULLS`: the particulars the
regression is evaluated with):

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

from shipgym.models.hull import Hull, draught_factors
from shipgym.models.ship import SHIPS, ShipTable

#: the particulars each ship's regression is evaluated with: each record's ``hull`` (ships
#: without one have no loading change)
HULLS: ShipTable[Hull] = ShipTable(
    lambda ship: ((ship.name, ship.hull),) if ship.hull is not None else ()
)


def loading_change(model: str, params: object, draught_ratio: float) -> dict[str, float]:
    """The parameters of ``model`` (``params``: its record before the change, config units)
    that change when the draught becomes ``draught_ratio``·T (module doc)."""
    hull = HULLS.get(model)
    if hull is None:
        raise ValueError(f"no loading-condition model for {model!r}; valid: {sorted(HULLS)}")
    ship = SHIPS[model]
    if not isinstance(params, ship.params):
        raise TypeError(f"{model} needs {ship.params.__name__}, got {type(params).__name__}")
    return ship.loading_change(params, draught_factors(hull, draught_ratio), draught_ratio)
