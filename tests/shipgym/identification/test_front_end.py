"""Front ends of the Nomoto regression: the Hampel filter, the state-variable filter and the
two sources of the rows of eq. (36) (docs/identification.md)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.signal import cont2discrete

from shipgym.identification.errors import IdentificationError
from shipgym.identification.front_end import (
    FrontEndSettings,
    HampelFilter,
    StateVariableFilter,
    difference_signals,
)
from shipgym.identification.nomoto import fit_nomoto2, nomoto_regressors, regression_rows
from shipgym.models.nomoto2 import Nomoto2Params
from tests.shipgym.identification.logs import H, measured_heading, simulate


# ----------------------------------------------------------------------------- Hampel
def test_hampel_removes_a_spike_and_nothing_else() -> None:
    """A 10° spike on a ramp becomes the window median (the next ramp value: the spike is the
    window's largest sample); no other sample moves."""
    ramp = 0.01 * np.arange(200)
    x = ramp.copy()
    x[80] += math.radians(10.0)
    hampel = HampelFilter(window=7, threshold=3.0)
    out = np.concatenate([hampel.push(x[:55]), hampel.push(x[55:])])
    assert out.shape[0] == 200 - hampel.delay
    assert out[80] == ramp[81]
    np.testing.assert_array_equal(np.delete(out, 80), np.delete(ramp[: out.shape[0]], 80))
    assert hampel.replaced == 1


def test_hampel_leaves_a_clean_ramp_untouched_up_to_its_delay() -> None:
    """Streaming in uneven chunks: each sample leaves (window − 1)/2 samples later, unchanged."""
    ramp = -0.3 + 0.02 * np.arange(101)
    hampel = HampelFilter(window=9)
    assert hampel.delay == 4
    pieces, fed = [], 0
    for size in (1, 2, 3, 10, 37, 48):
        pieces.append(hampel.push(ramp[fed : fed + size]))
        fed += size
        assert sum(p.shape[0] for p in pieces) == max(fed - hampel.delay, 0)
    np.testing.assert_array_equal(np.concatenate(pieces), ramp[: fed - hampel.delay])
    assert hampel.replaced == 0


def test_hampel_replaces_a_non_finite_sample_by_the_median() -> None:
    x = np.arange(20.0)
    x[10] = np.nan
    out = HampelFilter(window=5).push(x)
    assert out[10] == pytest.approx(10.0)  # median of 8, 9, 11, 12
    np.testing.assert_array_equal(np.delete(out, 10), np.delete(x[:18], 10))


@pytest.mark.parametrize(
    ("window", "threshold", "match"),
    [(6, 3.0, "odd"), (1, 3.0, "≥ 3"), (7, 0.0, "threshold"), (7, math.nan, "threshold")],
)
def test_hampel_settings_are_checked(window, threshold, match) -> None:
    with pytest.raises(IdentificationError, match=match):
        HampelFilter(window, threshold)


# ----------------------------------------------------------------------------- SVF
def test_svf_is_the_exact_zero_order_hold_discretisation() -> None:
    """Ad, Bd equal scipy's ZOH discretisation of (λ/(s+λ))⁴ in companion form."""
    svf = StateVariableFilter(3.0, H)
    ad, bd, *_ = cont2discrete((svf.A, svf.B[:, None], np.eye(4), np.zeros((4, 1))), H, "zoh")
    np.testing.assert_allclose(svf.Ad, ad, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(svf.Bd, bd[:, 0], rtol=1e-12, atol=1e-18)
    # the characteristic polynomial is (s + λ)⁴
    np.testing.assert_allclose(np.poly(svf.A), np.poly(np.full(4, -3.0)), rtol=1e-12)


def test_svf_step_response_and_its_derivatives_are_the_closed_form() -> None:
    """A held unit step is exact under ZOH: y = 1 − e^{−λt}Σ_{k<4}(λt)^k/k!, and the states
    are y′ = λ⁴t³e^{−λt}/6, y″ = λ⁴e^{−λt}(3t² − λt³)/6, y‴ = λ⁴e^{−λt}(6t − 6λt² + λ²t³)/6."""
    lam = 3.0
    svf = StateVariableFilter(lam, H)
    n = 600
    states = svf.run(np.ones((n, 1)), np.zeros((4, 1)))[:, :, 0]
    t = H * np.arange(1, n + 1)
    e = np.exp(-lam * t)
    lt = lam * t
    expected = np.column_stack(
        [
            1.0 - e * (1 + lt + lt**2 / 2 + lt**3 / 6),
            lam**4 * t**3 * e / 6,
            lam**4 * e * (3 * t**2 - lam * t**3) / 6,
            lam**4 * e * (6 * t - 6 * lam * t**2 + lam**2 * t**3) / 6,
        ]
    )
    np.testing.assert_allclose(states, expected, rtol=0, atol=1e-12)


def test_svf_states_of_a_sinusoid_are_its_filtered_derivatives() -> None:
    """In steady state the states of sin(ωt) are ω^k·|F|·sin(ωt + ∠F + kπ/2) (k = 0…3),
    evaluated half a step earlier (a held sample is the signal delayed by h/2): to 1e-4 of
    their amplitude, ψf‴ to 1e-3 (the steps of the held input leave a ripple of the order
    of λ⁴·ω·h²/8 on it at the sampling frequency: 5e-4 of its amplitude here)."""
    lam, omega = 3.0, 1.5
    svf = StateVariableFilter(lam, H)
    t = H * np.arange(4000)
    states = svf.run(np.sin(omega * t)[:, None], np.zeros((4, 1)))[:, :, 0]
    gain = (lam / math.hypot(lam, omega)) ** 4
    phase = -4.0 * math.atan2(omega, lam)
    after = t + H - H / 2  # the state after sample j is at t_j + h; the hold delays by h/2
    for k in range(4):
        expected = omega**k * gain * np.sin(omega * after + phase + k * math.pi / 2)
        tail = slice(2000, None)  # transient (λt)³e^{−λt} long gone
        scale = omega**k * gain
        tol = 1e-3 if k == 3 else 1e-4
        assert np.max(np.abs(states[tail, k] - expected[tail])) < tol * scale, k


def test_svf_runs_equally_in_blocks_and_sample_by_sample() -> None:
    svf = StateVariableFilter(3.0, H)
    rng = np.random.default_rng(0)
    u, x0 = rng.normal(size=(300, 2)), rng.normal(size=(4, 2))
    x, reference = x0, []
    for uj in u:
        x = svf.Ad @ x + svf.Bd[:, None] * uj
        reference.append(x)
    np.testing.assert_allclose(svf.run(u, x0), np.array(reference), rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("bandwidth", [0.0, -3.0, math.inf, math.nan])
def test_svf_bandwidth_must_be_positive_and_finite(bandwidth) -> None:
    with pytest.raises(IdentificationError, match="svf_bandwidth"):
        FrontEndSettings("svf", svf_bandwidth=bandwidth)


def test_unknown_front_end_is_refused_by_name() -> None:
    with pytest.raises(IdentificationError, match=r"front_end.*'splines'"):
        FrontEndSettings("splines")


# ----------------------------------------------------------------------------- sources
def test_difference_rows_are_the_papers_bit_for_bit() -> None:
    """One definition of the rows: on the differences they are eq. (35)–(37) as written."""
    psi, delta, delta_c = simulate(Nomoto2Params(), duration=5.0)
    reg = nomoto_regressors(psi, delta, delta_c, H)
    n = psi.size - 3
    d1, d2, d3 = (np.diff(psi, k)[:n] for k in (1, 2, 3))
    dd = np.diff(delta)[:n]
    x1 = np.column_stack(
        [-H * d2, H**3 * delta[:n], np.full(n, H**3), -(H**2) * d1, -(d1**3), H**2 * dd]
    )
    # forward_difference sums the binomial terms in its own order: equal to rounding
    np.testing.assert_allclose(reg.x1, x1, rtol=1e-9, atol=1e-18)
    np.testing.assert_allclose(reg.y1, d3, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(reg.y2, (delta_c[:n] - delta[:n]) * H)
    again = regression_rows(difference_signals(psi, delta, delta_c), H)
    for a, b in ((reg.x1, again.x1), (reg.y1, again.y1), (reg.x2, again.x2)):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("front_end", ["differences", "svf"])
def test_streamed_front_end_equals_one_call(front_end: str) -> None:
    """Filter states carried across calls: uneven chunks give the rows of one call."""
    psi, delta, delta_c = simulate(Nomoto2Params(), duration=12.0)
    psi = measured_heading(psi, seed=3)
    settings = FrontEndSettings(front_end)
    whole, _ = settings.make(H).push(psi, delta, delta_c)
    source = settings.make(H)
    parts, start = [], 0
    for size in [1, 3, 50, 7, 400, *[50] * 40]:
        signals, _ = source.push(
            psi[start : start + size], delta[start : start + size], delta_c[start : start + size]
        )
        parts.append(signals)
        start += size
    assert start >= psi.size
    streamed = type(whole).concatenate(parts)
    assert len(streamed) == len(whole) == psi.size - source.delay - getattr(source, "settle", 0)
    for name in ("psi1", "psi2", "psi3", "delta", "delta1", "servo_delta1", "servo_command"):
        np.testing.assert_allclose(getattr(streamed, name), getattr(whole, name), rtol=1e-9)


def test_svf_delay_is_the_hampel_look_ahead_plus_one_sample() -> None:
    source = FrontEndSettings("svf", outlier_window=11).make(H)
    assert source.delay == 5 + 1
    assert FrontEndSettings("svf", outlier_filter=False).make(H).delay == 1
    assert FrontEndSettings().make(H).delay == 3


def test_the_outlier_filter_belongs_to_the_svf_front_end() -> None:
    """Even a spike replaced by its window median is off by up to one sample's increment,
    far above Δ³ψ: the differences get no outlier filter, and asking for one is an error."""
    with pytest.raises(IdentificationError, match="outlier_filter=True needs front_end='svf'"):
        FrontEndSettings("differences", outlier_filter=True)
    assert not FrontEndSettings("differences").use_outlier_filter
    assert FrontEndSettings("svf").use_outlier_filter
    assert not FrontEndSettings("svf", outlier_filter=False).use_outlier_filter


def test_a_log_shorter_than_the_svf_start_transient_is_refused() -> None:
    psi, delta, delta_c = simulate(Nomoto2Params(), duration=3.0)
    with pytest.raises(IdentificationError, match="svf front end's start transient"):
        fit_nomoto2(psi, delta, delta_c, H, front_end="svf")
