"""The measured drift angle β every tuned path-following controller compensates."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym_baselines.classical.drift import course_and_drift


@pytest.mark.parametrize("beta", [-0.2, 0.0, 0.05, 0.3])
def test_a_constant_crab_is_recovered_from_positions_and_headings(beta: float) -> None:
    """A ship holding heading ψ while moving at course ψ + β with speed U over one period
    Ts: the estimator returns (U, β) exactly."""
    psi, speed, ts = 0.7, 7.5, 0.5
    course = psi + beta
    last = {"position": (10.0, -4.0), "psi": psi}
    info = {
        "position": (10.0 + speed * ts * math.cos(course), -4.0 + speed * ts * math.sin(course)),
        "heading": psi,
        "samples": {"psi": np.full(5, psi)},
    }
    u, b = course_and_drift(info, last, ts, nominal_speed=8.0)
    assert u == pytest.approx(speed, rel=1e-12) and b == pytest.approx(beta, abs=1e-12)
    no_samples = {**info, "samples": None}
    assert course_and_drift(no_samples, last, ts, 8.0)[1] == pytest.approx(beta, abs=1e-12)


def test_no_drift_on_the_first_step_when_slow_or_switched_off() -> None:
    info = {"position": (1.0, 1.0), "heading": 0.0}
    assert course_and_drift(info, None, 0.5, 8.0) == (8.0, 0.0)
    slow = {"position": (0.0, 0.0), "psi": 0.0}
    assert course_and_drift(info, slow, 100.0, 8.0) == (pytest.approx(0.8), 0.0)
    assert course_and_drift(info, {"position": (0.0, 0.0), "psi": 0.0}, 0.1, 8.0, False)[1] == 0.0
