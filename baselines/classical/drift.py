"""The measured drift angle β: one estimator for every path-following controller.

β [rad] = the course over ground from the last control period's measured position change
minus that period's mean measured heading (the mean of the period's fine heading samples
and the present heading when the env gives them, else the mid-point of the two ends), and
U [m/s] the speed over ground of the same period.  A controller compensates it as the
papers write it, ψd = χd − β (Xu & Guedes Soares 2020; Xu, Oliveira & Guedes Soares 2021
eq. (48)).  On the first step, below a tenth of the nominal speed, or with compensation off,
β = 0 (and U at least a tenth of the nominal speed).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from shipgym.angles import unwrap_floats, wrap_angle


def course_and_drift(
    info: dict[str, Any],
    last: dict[str, Any] | None,
    control_period: float,
    nominal_speed: float,
    compensate: bool = True,
) -> tuple[float, float]:
    """(speed over ground U [m/s], drift angle β [rad]) over the last period (module doc);
    ``last``: the previous step's ``{"position": (x, y), "psi": ψ}`` (None: the first
    step)."""
    if last is None:
        return nominal_speed, 0.0
    x, y = info["position"]
    x0, y0 = last["position"]
    dx, dy = x - x0, y - y0
    speed = math.hypot(dx, dy) / control_period
    if not compensate or speed < 0.1 * nominal_speed:
        return max(speed, 0.1 * nominal_speed), 0.0
    samples = info.get("samples")
    if samples is not None and len(samples["psi"]) > 0:
        headings = unwrap_floats([*samples["psi"].tolist(), float(info["heading"])])
        mean_heading = float(np.mean(np.array(headings)))
    else:
        h0 = last["psi"]
        mean_heading = h0 + 0.5 * wrap_angle(info["heading"] - h0)
    return speed, float(wrap_angle(math.atan2(dy, dx) - mean_heading))
