"""What an online estimator of a ship adapts: the few numbers its change families move.

A change family moves many model parameters at once (a loading change moves the mass and
eight hull derivatives), but through a handful of physical quantities.  An estimator that
adapts the ship's own model estimates those quantities, each as the natural logarithm η of
a factor on the nominal model (η = 0: the nominal ship), and maps them onto the model's
parameter vector with :meth:`Adaptation.params`.  Each ship's record declares its quantities
(``Ship.adapted``, :mod:`shipgym.models.ship`):

===============  ======================  =========================================
quantity         family it follows       parameters it moves (ship)
===============  ======================  =========================================
``servo``        rudder aging            servo time constant: Tc (nomoto2),
                                         T_servo (esso_osaka, kvlcc2), T_delta
                                         (mariner, blanke) × e^η
``rate``         rudder aging            rudder rate limit: rudder_rate
                                         (esso_osaka, kvlcc2), delta_dot_max
                                         (mariner, blanke) × e^η
``rudder``       steering effectiveness  Yd and Nd (esso_osaka), a3 (mariner), dCL
                                         (blanke), f_alpha (kvlcc2) × e^η
``draught``      loading change          every parameter
                                         :func:`shipgym.models.loading.loading_change`
                                         moves, at the draught × e^η (3-DOF ships)
``gain``         manoeuvrability         K × e^η (nomoto2)
``time``         manoeuvrability         T1 × e^η (nomoto2)
===============  ======================  =========================================

The current and the yaw bias are disturbances (the model's ``current_x``, ``current_y``,
``yaw_disturbance``), estimated beside these; nomoto2's current shift moves d0, which
enters its yaw equation exactly as the yaw bias does (eq. (4): K(δ + T3δ̇) + d0 + w_ψ).

Bounds keep an estimate physical: a factor in [1/2, 400] on a servo time constant (aging
only slows a servo; the catalogue's rudder aging is ×3–×60 on four ships and ×200 on the
KVLCC2), [1/10, 2] on a rate limit,
[1/3, 3] on rudder effectiveness and nomoto2's K (the catalogue's manoeuvrability change
is K × 12: [1/3, 20] there), [1/2, 3] on T1, and a draught of ×0.3–×1.6 (the catalogue's
loading changes are ×0.4 and ×1.35).
"""

from __future__ import annotations

import math

import numpy as np

from shipgym.models.base import ParameterRecord
from shipgym.models.loading import loading_change
from shipgym.models.ship import Quantity, ShipTable

#: model id -> the adapted quantities of the ship (each ship record's ``adapted``; the module
#: doc's table)
QUANTITIES: ShipTable[tuple[Quantity, ...]] = ShipTable(lambda ship: ((ship.name, ship.adapted),))


class Adaptation:
    """The map η ↦ the model's parameter vector for one ship around its nominal parameters
    (module doc)."""

    def __init__(self, ship: str, nominal: ParameterRecord) -> None:
        if ship not in QUANTITIES:
            raise ValueError(f"no adapted quantities for {ship!r}; known: {sorted(QUANTITIES)}")
        self.ship = ship
        self.nominal = nominal
        self.quantities = QUANTITIES[ship]
        names = type(nominal).names()
        missing = [p for q in self.quantities for p in q.params if p not in names]
        if missing:
            raise ValueError(f"{ship}: the adapted parameters {missing} are not in {names}")
        self.names = tuple(q.name for q in self.quantities)
        self._index = {name: names.index(name) for q in self.quantities for name in q.params}
        self.low = np.array([q.bounds[0] for q in self.quantities])
        self.high = np.array([q.bounds[1] for q in self.quantities])

    @property
    def size(self) -> int:
        """Number of adapted quantities."""
        return len(self.quantities)

    def clip(self, eta: np.ndarray) -> np.ndarray:
        """η inside its bounds."""
        return np.clip(eta, self.low, self.high)

    def params(self, eta: np.ndarray) -> np.ndarray:
        """The model's parameter vector at η (the nominal one at η = 0): the draught first
        (:func:`loading_change` of the nominal record), then each factor."""
        record = self.nominal
        for q, value in zip(self.quantities, eta, strict=True):
            if q.draught and value != 0.0:
                record = record.replace(**loading_change(self.ship, record, math.exp(value)))
        vector = record.to_vector().astype(float)
        for q, value in zip(self.quantities, eta, strict=True):
            for name in q.params:
                vector[self._index[name]] *= math.exp(value)
        return vector

    def jacobian(self, eta: np.ndarray, step: float = 1e-4) -> tuple[np.ndarray, np.ndarray]:
        """(θ(η), ∂θ/∂η [n_params × size]): the factors exactly (θ_j·e^η is its own
        derivative), the draught by a central difference of ``step``."""
        theta = self.params(eta)
        jac = np.zeros((theta.size, self.size))
        for i, q in enumerate(self.quantities):
            if q.draught:
                up, down = eta.copy(), eta.copy()
                up[i] += step
                down[i] -= step
                jac[:, i] = (self.params(up) - self.params(down)) / (2.0 * step)
            else:
                for name in q.params:
                    jac[self._index[name], i] = theta[self._index[name]]
        return theta, jac
