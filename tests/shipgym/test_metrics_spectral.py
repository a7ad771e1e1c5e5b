"""High-frequency content of a signal (metrics.high_frequency_power)."""

from __future__ import annotations

import numpy as np
import pytest

from shipgym.metrics import high_frequency_power

TS, N, AMPLITUDE = 0.5, 2000, 1.7  # [s], samples, signal units
POWER = AMPLITUDE**2 / 2  # mean square of a sinusoid


def _sine(omega: float) -> np.ndarray:
    return AMPLITUDE * np.sin(omega * TS * np.arange(N) + 0.3) + 0.8  # offset removed by Welch


@pytest.mark.parametrize("omega", [2.0, 4.0])
def test_a_sinusoid_above_the_cutoff_keeps_all_its_power(omega: float) -> None:
    assert high_frequency_power(_sine(omega), TS, 1.0) == pytest.approx(POWER, rel=1e-6)


@pytest.mark.parametrize("omega", [0.2, 0.5])
def test_a_sinusoid_below_the_cutoff_has_none(omega: float) -> None:
    assert high_frequency_power(_sine(omega), TS, 1.0) < 1e-7 * POWER


def test_a_zero_cutoff_gives_the_variance() -> None:
    assert high_frequency_power(_sine(0.7), TS, 0.0) == pytest.approx(POWER, rel=1e-3)


def test_a_cutoff_above_nyquist_gives_zero() -> None:
    assert high_frequency_power(_sine(2.0), TS, 2 * np.pi / TS) == 0.0


def test_short_or_multidimensional_signals_are_refused() -> None:
    with pytest.raises(ValueError, match="at least 8 samples"):
        high_frequency_power(np.zeros(5), TS, 1.0)
    with pytest.raises(ValueError, match="at least 8 samples"):
        high_frequency_power(np.zeros((10, 2)), TS, 1.0)
