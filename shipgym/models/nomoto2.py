"""Second-order nonlinear Nomoto ship with rudder servo (Liu et al., 2019).

Liu et al. (2019) eq. (1)–(4):

    T1·T2·r̈ + (T1 + T2)·ṙ + r + β·r³ = K·(δ + T3·δ̇) + d0          (1)
    Tc·δ̇ + δ = Kc·δc                                                 (2)

with kinematics ẋ = u0·cos ψ + Vcx, ẏ = u0·sin ψ + Vcy.  (Eq. (1) as printed has ψ where r
belongs; eq. (4) shows the intended form, used here.)  State
``[x, y, psi, r, r_dot, delta]``, input δc, disturbances ``[current_x, current_y,
yaw_disturbance]`` (current in m/s in the earth frame; ``yaw_disturbance`` adds to d0, rad/s).

Units
-----
Internally everything is SI with radians: K [1/s] maps rudder [rad] to yaw rate [rad/s],
d0 [rad/s], β [s²] multiplies r³ with r in rad/s.  The paper quotes d0 in °/s and does not
say in which unit β·r³ is evaluated; :func:`params_from_paper` converts the paper's numbers
under an explicit :class:`UnitReading` (see its docstring and the README).
"""

from __future__ import annotations

import dataclasses
import enum
import math
from types import SimpleNamespace
from typing import Any, ClassVar

from shipgym.models.base import ParameterError, ParameterRecord, ShipModel
from shipgym.models.ship import EnvId, Quantity, Ship, servo_quantity

DEG = math.pi / 180.0


@dataclasses.dataclass(frozen=True)
class Nomoto2Params(ParameterRecord):
    """Parameters of the nomoto2 ship, SI/radians (defaults: Liu et al. 2019 §4, SI reading)."""

    K: float = 0.5060  # Nomoto gain [1/s]
    T1: float = 1.2481  # first time constant [s]
    T2: float = 0.1245  # second time constant [s]
    T3: float = -0.0757  # rudder-rate time constant [s]
    d0: float = -1.2370 * DEG  # yaw bias from disturbances/unmodelled dynamics [rad/s]
    beta: float = 0.0081  # cubic yaw-damping coefficient [s²] (r in rad/s)
    Tc: float = 0.1  # rudder servo time constant [s]
    Kc: float = 1.0  # rudder servo gain [-]
    u0: float = 0.80  # constant surge speed [m/s]
    L: float = 0.95  # ship length [m]

    positive: ClassVar[tuple[str, ...]] = ("T1", "T2", "Tc", "u0", "L")
    #: a real plant also steers the documented way (K > 0: δ > 0 makes r > 0) and has a
    #: servo that follows its command (Kc > 0); an identifier's estimate may break these
    #: (the weighted LS-SVM keeps a K < 0, as in the paper's Figure 7), so only a ship built
    #: from a config is held to them.  β < 0 (cubic anti-damping) stays allowed: it is the
    #: documented way to make a test plant diverge.
    plant_positive: ClassVar[tuple[str, ...]] = ("K", "Kc")


class UnitReading(enum.StrEnum):
    """How the paper's numbers (d0 in °/s, β with r in unknown units) map to SI.

    * ``si`` — δ, ψ, r in rad, rad/s; d0 converted from °/s to rad/s; β applies to r in
      rad/s.  The default reading (radians inside, as everywhere in the package).
    * ``degrees`` — the whole equation in degrees (δ in °, r in °/s, d0 in °/s), as in
      ``data/ship_models.md`` §4.1.  Dividing (1) by 180/π gives the SI form with
      β_SI = β·(180/π)² and d0_SI = d0·π/180; K unchanged.
    * ``rudder_degrees`` — heading and yaw rate in rad, rudder in degrees: K_SI = K·180/π,
      d0_SI = d0·π/180, β unchanged.  A far more agile ship; kept as the option that the
      independent check of the paper's convergence times pointed to.
    """

    SI = "si"
    DEGREES = "degrees"
    RUDDER_DEGREES = "rudder_degrees"


#: The parameters whose unit depends on the reading.
_READING_FACTORS: dict[UnitReading, dict[str, float]] = {
    UnitReading.SI: {"K": 1.0, "d0": DEG, "beta": 1.0},
    UnitReading.DEGREES: {"K": 1.0, "d0": DEG, "beta": 1.0 / DEG**2},
    UnitReading.RUDDER_DEGREES: {"K": 1.0 / DEG, "d0": DEG, "beta": 1.0},
}


def paper_to_si(values: dict[str, float], reading: UnitReading | str) -> dict[str, float]:
    """Convert paper-unit parameter values (d0 in °/s) to SI under ``reading``."""
    factors = _READING_FACTORS[UnitReading(reading)]
    return {k: v * factors.get(k, 1.0) for k, v in values.items()}


def si_to_paper(values: dict[str, float], reading: UnitReading | str) -> dict[str, float]:
    """Inverse of :func:`paper_to_si` (for reporting identified parameters in paper units)."""
    factors = _READING_FACTORS[UnitReading(reading)]
    return {k: v / factors.get(k, 1.0) for k, v in values.items()}


def params_from_paper(
    reading: UnitReading | str = UnitReading.SI, base: Nomoto2Params | None = None, **paper: float
) -> Nomoto2Params:
    """A :class:`Nomoto2Params` from values in the paper's units (d0 in °/s).

    Parameters not given keep their value in ``base`` (default: the paper's ship read in SI).
    """
    base = base if base is not None else Nomoto2Params()
    return base.replace(**paper_to_si(paper, reading))


def nomoto2_first_order(K: float, T1: float, T2: float, T3: float) -> tuple[float, float]:
    """Nomoto's first-order approximation (K [1/s], T = T1 + T2 − T3 [s]) of the 2nd-order
    model T1·T2·r̈ + (T1 + T2)·ṙ + r = K·(δ + T3·δ̇)."""
    T = T1 + T2 - T3
    if not math.isfinite(T) or T <= 0:
        raise ParameterError(f"first-order time constant T = T1 + T2 - T3 = {T} is not positive")
    return K, T


class Nomoto2(ShipModel):
    """nomoto2: 0.95 m scale ship of Liu et al. (2019), 2nd-order nonlinear Nomoto + servo."""

    name = "nomoto2"
    state_names = ("x", "y", "psi", "r", "r_dot", "delta")
    disturbance_names = ("current_x", "current_y", "yaw_disturbance")
    params_type = Nomoto2Params
    rudder_limit = 30.0 * DEG  # δc ∈ ±30° (Liu et al. 2019 §4)
    control_period = 0.5  # Ts [s] (Liu et al. 2019 §4)
    fine_step = 0.01  # h [s] (Liu et al. 2019 §4)
    unit_readings = tuple(r.value for r in UnitReading)

    @classmethod
    def config_to_si(cls, values: dict[str, float], unit_reading: str | None) -> dict[str, float]:
        """Paper units (d0 in °/s) to SI under the unit reading (default ``si``)."""
        checked = super().config_to_si(values, unit_reading)
        return paper_to_si(checked, unit_reading or UnitReading.SI)

    def rhs(self, x: Any, u: Any, w: Any, p: Any, ops: SimpleNamespace) -> Any:
        psi, r, r_dot, delta = x[2], x[3], x[4], x[5]
        delta_c = u[0]
        delta_dot = (p.Kc * delta_c - delta) / p.Tc  # eq. (2)
        # eq. (4) (with Kc kept general): g(x) = r̈
        r_ddot = (
            p.K * (delta + p.T3 * delta_dot)
            + p.d0
            + w[2]
            - (p.T1 + p.T2) * r_dot
            - r
            - p.beta * r * r * r
        ) / (p.T1 * p.T2)
        return ops.stack(
            [
                p.u0 * ops.cos(psi) + w[0],
                p.u0 * ops.sin(psi) + w[1],
                r,
                r_dot,
                r_ddot,
                delta_dot,
            ]
        )

    def closed_form_nomoto(self) -> tuple[float, float, float, float]:
        """The model's own K [1/s], T1, T2, T3 [s]: it *is* a 2nd-order Nomoto model."""
        p = self.params
        return p.K, p.T1, p.T2, p.T3


#: the nomoto2 ship: the manoeuvrability change moves its K (×12 in the catalogue) and T1
SHIP = Ship(
    model=Nomoto2,
    adapted=(
        servo_quantity("Tc"),
        Quantity("gain", ("K",), 1.0 / 3.0, 20.0),
        Quantity("time", ("T1",), 0.5, 3.0),
    ),
    env_ids=(EnvId("ShipPathFollow-v0", "rudder_aging", 180),),
)
