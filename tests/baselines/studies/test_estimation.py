"""The estimation study: an estimate scored against the truth the env kept."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym.scenarios.loader import load_scenario
from shipgym_baselines.studies.estimation import SETTLED_L, play, summary


def test_an_aged_servo_is_found_and_scored() -> None:
    """``rudder_aging`` (Tc 0.1 → 1.0 s at 12 s) played by nmpc_ekf: read as rudder aging,
    the servo's estimate ends at the truth (2 %), the error after the change is a small
    share of the nominal ship's and settles below SETTLED_L."""
    row = play("nmpc_ekf", load_scenario("rudder_aging"), 10_000)
    assert row["family"] == "rudder_aging"
    assert row["servo_true_s"][-1] == pytest.approx(1.0)
    assert row["servo_estimate_s"][-1] == pytest.approx(1.0, rel=0.02)
    assert row["error_share"] < 0.5
    assert math.isfinite(row["settling_T"])
    assert max(row["error_L"][-5:]) < SETTLED_L
    table = summary([row])
    assert table["nmpc_ekf"]["rudder_aging"]["trials"] == 1


def test_a_current_shift_is_read_off_the_truth() -> None:
    """``current_shift`` on nomoto2 moves d0: read as a current shift; no current acts."""
    row = play("nmpc_ekf", load_scenario("current_shift"), 10_000)
    assert row["family"] == "current_shift"
    np.testing.assert_allclose(row["current_true_m_s"], 0.0, atol=1e-12)


def test_a_controller_without_an_estimate_is_refused() -> None:
    with pytest.raises(ValueError, match="estimate_log"):
        play("pid_los", load_scenario("rudder_aging"), 10_000)
