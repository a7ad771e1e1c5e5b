"""Low-pass filter C(s) of eq. (39) (Xu, Oliveira & Guedes Soares 2021), exact ZOH."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.signal

from shipgym_baselines.classical.adaptive.lowpass import (
    SecondOrderLowPass,
    low_pass_transfer_function,
)

TS = 0.5  # [s]


def _step_samples(filt: SecondOrderLowPass, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(period averages, sampled outputs) of the response to a unit step held from t = 0."""
    averages, samples = [], []
    for _ in range(n):
        averages.append(filt.step(1.0))
        samples.append(filt.output)
    return np.array(averages), np.array(samples)


def test_critically_damped_step_response_is_the_closed_form_at_the_samples() -> None:
    """ζ = 1 (§5.2): y(t) = 1 − (1 + ωt)e^(−ωt) at t = Ts, 2Ts, …, and the period averages
    are (Y(t_k+1) − Y(t_k))/Ts with Y(t) = ∫y = t − (2 − (2 + ωt)e^(−ωt))/ω."""
    w, n = 0.25, 120
    averages, samples = _step_samples(SecondOrderLowPass(w, 1.0, TS), n)
    t = TS * np.arange(n + 1)
    np.testing.assert_allclose(samples, 1 - (1 + w * t[1:]) * np.exp(-w * t[1:]), atol=1e-12)
    integral = t - (2 - (2 + w * t) * np.exp(-w * t)) / w
    np.testing.assert_allclose(averages, np.diff(integral) / TS, atol=1e-12)


def test_underdamped_step_response_is_the_closed_form_at_the_samples() -> None:
    """ζ = 0.3: y(t) = 1 − e^(−ζωt)(cos ωd·t + ζω/ωd·sin ωd·t), ωd = ω√(1 − ζ²)."""
    w, zeta, n = 1.3, 0.3, 80
    _, samples = _step_samples(SecondOrderLowPass(w, zeta, TS), n)
    t = TS * np.arange(1, n + 1)
    wd = w * math.sqrt(1 - zeta**2)
    exact = 1 - np.exp(-zeta * w * t) * (np.cos(wd * t) + zeta * w / wd * np.sin(wd * t))
    np.testing.assert_allclose(samples, exact, atol=1e-12)


def test_sampled_response_to_a_held_input_equals_scipy_zoh_discretisation() -> None:
    """A random staircase input: y(t_k+1) after holding u_k equals scipy's ZOH model of C(s)
    (whose output at k is y(t_k), a one-sample shift)."""
    filt = SecondOrderLowPass(0.6, 0.8, TS)
    u = np.random.default_rng(3).uniform(-1, 1, 200)
    ours = []
    for value in u:
        filt.step(float(value))
        ours.append(filt.output)
    num, den = filt.transfer_function()
    dnum, dden, _ = scipy.signal.cont2discrete((num, den), TS, method="zoh")
    theirs = scipy.signal.lfilter(dnum.ravel(), dden, u)
    np.testing.assert_allclose(ours[:-1], theirs[1:], atol=1e-12)


def test_transfer_function_has_unit_dc_gain_and_the_printed_poles() -> None:
    num, den = low_pass_transfer_function(0.25, 1.0)
    assert num[0] / den[-1] == 1.0
    np.testing.assert_allclose(np.roots(den), [-0.25, -0.25])


def test_reset_starts_the_filter_at_rest_on_a_constant_input() -> None:
    filt = SecondOrderLowPass(0.25, 1.0, TS)
    filt.reset(0.4)
    assert [filt.step(0.4) for _ in range(5)] == pytest.approx([0.4] * 5, abs=1e-14)


def test_bad_filter_parameters_are_refused() -> None:
    with pytest.raises(ValueError, match="> 0"):
        SecondOrderLowPass(0.0, 1.0, TS)
