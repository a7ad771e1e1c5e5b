"""Borkowski (2018) eq. (29): the quality index J(t) along a logged trajectory."""

from __future__ import annotations

from typing import Any

import numpy as np

from shipgym.angles import wrap_angle
from shipgym.metrics import DEFAULT_SETTINGS
from shipgym.tracking import PathTracker


def cumulative_J(scenario: Any, trajectory: dict[str, np.ndarray], dt: float) -> np.ndarray:
    """J(t) of eq. (29) along a trajectory, as :func:`~shipgym.metrics.compute_metrics` sums it
    (per step).

    Replays the env's path tracker on the logged positions; the heading is the logged
    (measured) one, equal to the true heading in this noise-free scenario.
    """
    s = DEFAULT_SETTINGS
    tracker = PathTracker(scenario.path, scenario.acceptance_radius, scenario.config.path.switching)
    x, y, psi, delta = (trajectory[k] for k in ("x", "y", "heading", "rudder_angle"))
    tracker.reset(float(x[0]), float(y[0]))
    terms = [0.0]
    for k in range(1, x.shape[0]):
        f = tracker.update(float(x[k]), float(y[k]))
        psi_r = wrap_angle(float(psi[k]) - f.path_angle)
        terms.append(
            s.lambda_y * f.cross_track**2 + s.lambda_psi * psi_r**2 + s.lambda_delta * delta[k] ** 2
        )
    return np.cumsum(terms) * dt
