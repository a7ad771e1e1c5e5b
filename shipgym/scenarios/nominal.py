"""The nominal model a scenario's env and controllers are built on, checked as construction
builds it.

Guidance mode's heading autopilot and every model-based controller design on the first-order
Nomoto model (K, T) of the scenario's *nominal* ship: a closed form (nomoto2), or the fit to
the ship's own 20/20 zig-zag (:func:`shipgym.identification.nominal.first_order_nomoto`).  A ship
the
schema accepts can still fail there — a rudder limit below the zig-zag's 20°, a simulated
zig-zag that diverges, T = T1 + T2 − T3 ≤ 0, K ≤ 0 — so this check is what both
``shipgym scenarios --validate`` and the env's construction call
(:func:`shipgym.scenarios.loader.nominal_nomoto`), and its errors name
the scenario key (``ship.params.delta_max``, ``ship.params``)."""

from __future__ import annotations

import math
from typing import Any

from shipgym.autopilot import PIDGains
from shipgym.identification.errors import IdentificationError
from shipgym.identification.nominal import first_order_nomoto
from shipgym.manoeuvres import ManoeuvreError
from shipgym.models.base import ParameterError

#: the rudder angle [deg] of the zig-zag that identifies a ship without a closed form
ZIGZAG_RUDDER_DEG = 20.0


def nominal_problem(scenario: Any) -> tuple[str, str] | None:
    """Why the scenario's nominal ship gives no first-order Nomoto model with K, T > 0: the
    dotted key at fault and what is wrong; None when it gives one."""
    model = scenario.model.with_params(scenario.nominal_params)
    fields = getattr(model.params, "__dataclass_fields__", {})
    closed = model.closed_form_nomoto() is not None
    if not closed and model.rudder_limit < math.radians(ZIGZAG_RUDDER_DEG):
        key = "ship.params.delta_max" if "delta_max" in fields else "ship.params"
        return (
            key,
            f"the rudder limit {math.degrees(model.rudder_limit):.4g}° is below the "
            f"{ZIGZAG_RUDDER_DEG:g}° of the zig-zag that identifies the nominal model",
        )
    how = (
        "its closed form" if closed else f"its {ZIGZAG_RUDDER_DEG:g}/{ZIGZAG_RUDDER_DEG:g} zig-zag"
    )
    try:
        K, T = first_order_nomoto(scenario.model, scenario.nominal_params)
        PIDGains.from_nomoto(K, T)
    except (IdentificationError, ManoeuvreError, ParameterError, ValueError) as exc:
        return (
            "ship.params",
            f"no nominal model (first-order Nomoto K, T > 0) from {how}: {exc}",
        )
    return None
