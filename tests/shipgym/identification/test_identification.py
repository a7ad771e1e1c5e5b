"""Identification toolkit: each test asserts a mathematical or physical fact."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym.identification.continuous_ls import ContinuousLeastSquares
from shipgym.identification.errors import IdentificationError
from shipgym.identification.front_end import forward_difference
from shipgym.identification.lssvm import (
    _quantiles,
    lssvm_dual,
    lssvm_primal,
    robust_weights,
    weighted_lssvm,
)
from shipgym.identification.nomoto import fit_nomoto2, params_from_theta1, theta1_from_params
from shipgym.identification.online import LambdaLSSVM, PersistentExcitation, WeightedLSSVMOnline
from shipgym.identification.zigzag import fit_nomoto_zigzag, zigzag_nomoto
from shipgym.models.nomoto2 import Nomoto2, Nomoto2Params
from tests.shipgym.identification.logs import H, simulate


# ----------------------------------------------------------------------------- LS-SVM core
@pytest.mark.parametrize("bias_penalty", [False, True])
@pytest.mark.parametrize("regularisation", [0.0, 1e-8])
def test_dual_and_primal_solutions_are_equal(bias_penalty: bool, regularisation: float) -> None:
    """Eq. (25)/(41) dual and the (d+1)-unknown primal give the same θ̂ and b (1e-9 rel.)."""
    rng = np.random.default_rng(0)
    x = rng.normal(size=(300, 6))
    y = x @ rng.normal(size=6) + 0.3 + 0.1 * rng.normal(size=300)
    v = rng.uniform(0.1, 1.0, 300)
    for gamma in (1.0, 10.0, 100.0):
        d = lssvm_dual(x, y, gamma, v, bias_penalty, regularisation)
        p = lssvm_primal(x, y, gamma, v, bias_penalty, regularisation)
        np.testing.assert_allclose(p.theta, d.theta, rtol=1e-9)
        assert p.bias == pytest.approx(d.bias, rel=1e-9)
        # eq. (38): θ̂ = Σ α_k x_k and eq. (23)/(40): α_k = γ v'_k e_k
        np.testing.assert_allclose(d.residuals, p.residuals, rtol=1e-7, atol=1e-12)


def test_primal_at_paper_gamma_is_weighted_least_squares() -> None:
    """γ = 1e15 (Liu et al. 2019 §4): the ridge vanishes; without bias penalty = weighted LS."""
    rng = np.random.default_rng(1)
    x = rng.normal(size=(500, 4))
    y = x @ np.array([1.0, -2.0, 0.5, 3.0]) + 0.7 + 0.01 * rng.normal(size=500)
    v = rng.uniform(0.2, 1.0, 500)
    sol = lssvm_primal(x, y, 1e15, v, bias_penalty=False)
    z = np.column_stack([x, np.ones(500)]) * np.sqrt(v)[:, None]
    ref, *_ = np.linalg.lstsq(z, y * np.sqrt(v), rcond=None)
    np.testing.assert_allclose(sol.theta, ref[:4], rtol=1e-9)
    assert sol.bias == pytest.approx(ref[4], rel=1e-9)


def test_quantiles_match_numpy_percentile() -> None:
    rng = np.random.default_rng(2)
    for n in (1, 2, 5, 1200, 1201):
        a = rng.normal(size=n)
        np.testing.assert_allclose(_quantiles(a, (0.25, 0.75)), np.percentile(a, [25, 75]))


def test_robust_weights_follow_eq_28() -> None:
    """v = 1 inside c1·ŝ, linear between c1 and c2, 1e-4 beyond c2 (ŝ = IQR/1.349)."""
    base = np.random.default_rng(3).normal(size=1000)
    s = (np.percentile(base, 75) - np.percentile(base, 25)) / (2 * 0.6745)
    probes = np.array([0.0, 2.0 * s, 2.75 * s, 3.5 * s])
    # probes barely move the quartiles of 1000 samples: compare with their own scale
    errors = np.concatenate([base, probes])
    s2 = (np.percentile(errors, 75) - np.percentile(errors, 25)) / (2 * 0.6745)
    v = robust_weights(errors)[-4:]
    expected = [1.0, 1.0, (3.0 - 2.75 * s / s2) / 0.5, 1e-4]
    np.testing.assert_allclose(v, expected, rtol=1e-12)


def test_robust_weights_reject_injected_outliers() -> None:
    """With 5 % gross outliers the weighted estimate stays within 1 % of the clean one."""
    rng = np.random.default_rng(4)
    x = rng.normal(size=(1000, 3))
    theta = np.array([2.0, -1.0, 0.5])
    y_clean = x @ theta + 0.05 * rng.normal(size=1000)
    y = y_clean.copy()
    bad = rng.choice(1000, 50, replace=False)
    y[bad] += rng.choice([-1.0, 1.0], 50) * rng.uniform(5.0, 10.0, 50)
    clean = lssvm_primal(x, y_clean, 1e6).theta
    plain = lssvm_primal(x, y, 1e6).theta
    robust, v = weighted_lssvm(x, y, 1e6)
    assert np.max(np.abs(robust.theta - clean) / np.abs(clean)) < 0.01
    assert np.max(np.abs(plain - clean) / np.abs(clean)) > 0.01  # the outliers do matter
    assert np.all(v[bad] < 0.5)


# ----------------------------------------------------------------------------- regressors
def test_forward_difference_is_eq_32() -> None:
    """Δ³ of t³ sampled at h is exactly 6h³; Δ¹, Δ² follow the binomial sums."""
    h = 0.1
    t = h * np.arange(10)
    np.testing.assert_allclose(forward_difference(t**3, 3), 6 * h**3, rtol=1e-9)
    f = np.random.default_rng(5).normal(size=8)
    np.testing.assert_allclose(forward_difference(f, 2), f[2:] - 2 * f[1:-1] + f[:-2])
    np.testing.assert_allclose(forward_difference(f, 1), np.diff(f))


def test_theta1_round_trip() -> None:
    p = Nomoto2Params()
    back = params_from_theta1(theta1_from_params(p))
    for key in ("K", "T1", "T2", "T3", "d0", "beta"):
        assert back[key] == pytest.approx(getattr(p, key), rel=1e-12)


def test_theta1_without_real_time_constants_is_an_error() -> None:
    theta = theta1_from_params(Nomoto2Params())
    theta[0] = 0.1  # (T1 + T2)² < 4 T1 T2
    with pytest.raises(IdentificationError, match="complex"):
        params_from_theta1(theta)


def rel(est: Nomoto2Params, true: Nomoto2Params, key: str) -> float:
    return (getattr(est, key) - getattr(true, key)) / abs(getattr(true, key))


def test_batch_fit_recovers_nomoto2_on_noise_free_data() -> None:
    """K, T1, d0 within 5 %; Tc within 0.5 % with the ZOH-exact servo inversion."""
    true = Nomoto2Params()
    psi, delta, delta_c = simulate(true)
    est = fit_nomoto2(psi, delta, delta_c, H, servo_model="exact")
    for key in ("K", "T1", "d0"):
        assert abs(rel(est, true, key)) < 0.05, key
    assert abs(rel(est, true, "Tc")) < 0.005


def test_servo_forward_difference_bias_is_h_over_one_minus_exp() -> None:
    """Eq. (34) as written estimates θ2 = h/(1 − e^{−h/Tc}) ≈ Tc + h/2 (+5.1 % at Tc = 0.1 s)."""
    true = Nomoto2Params()
    psi, delta, delta_c = simulate(true)
    est = fit_nomoto2(psi, delta, delta_c, H, servo_model="forward")
    predicted = H / (1.0 - math.exp(-H / true.Tc))
    assert est.Tc == pytest.approx(predicted, rel=1e-3)
    assert rel(est, true, "Tc") == pytest.approx(0.0508, abs=0.001)


def test_remaining_bias_is_first_order_in_h() -> None:
    """The forward-difference bias of T2 and T3 is O(h): halving h halves it.

    Derivation: Δⁿψ/hⁿ = ψ⁽ⁿ⁾(t + nh/2) + O(h²), so the terms of eq. (33) are taken at
    t + 1.5h, t + h, t + h/2 and t; the misalignment is linear in h.  Measured (γ → ∞,
    unweighted, so the LS-SVM ridge does not interfere): T2 +5.4 %, T3 +30 % at h = 0.01 s.
    Tolerances at h = 0.01 s follow: |T2 error| < 10 %, |T3 error| < 40 %.
    """
    true = Nomoto2Params()
    errors = {}
    for h in (0.01, 0.005):
        psi, delta, delta_c = simulate(true, h=h)
        est = fit_nomoto2(psi, delta, delta_c, h, gamma=1e30, weighted=False)
        errors[h] = {k: rel(est, true, k) for k in ("K", "T1", "T2", "T3", "d0")}
    for key in ("T1", "T2", "T3"):
        ratio = errors[0.01][key] / errors[0.005][key]
        assert 1.7 < ratio < 2.3, (key, errors)
    assert abs(errors[0.01]["T2"]) < 0.10
    assert abs(errors[0.01]["T3"]) < 0.40


def test_beta_is_not_identifiable_in_si_units() -> None:
    """A finding: β·r³ is < 0.1 % of the damping term r at these yaw rates (SI reading)."""
    true = Nomoto2Params()
    psi, _, _ = simulate(true)
    r = np.diff(psi) / H
    assert np.max(np.abs(true.beta * r**3)) < 1e-3 * np.max(np.abs(r))


def test_degenerate_batch_data_raise_with_the_reason() -> None:
    n = 500
    with pytest.raises(IdentificationError, match="constant"):
        fit_nomoto2(np.linspace(0, 1, n), np.full(n, 0.1), np.full(n, 0.1), H)
    with pytest.raises(IdentificationError, match="at least 4"):
        fit_nomoto2(np.zeros(3), np.zeros(3), np.zeros(3), H)


# ----------------------------------------------------------------------------- online
def rudder_aging_log(seed: int):
    from shipgym_baselines.studies.benchmarks import identification_log

    return identification_log("rudder_aging", seed=seed, excitation_deg=1.0)


@pytest.fixture(scope="module")
def aging_runs():
    runs = {}
    for seed in (0, 1):
        log, sc = rudder_aging_log(seed)
        ids = {
            "lambda": LambdaLSSVM(sc.fine_step, sc.nominal_params),
            "weighted": WeightedLSSVMOnline(sc.fine_step, sc.nominal_params),
        }
        for samples in log:
            for ident in ids.values():
                ident.update(samples)
        runs[seed] = ids
    return runs


def first_within(ident, key: str, target: float, tol: float, after: float) -> float:
    for entry in ident.history:
        if entry["t"] > after and abs(entry[key] - target) <= tol * abs(target):
            return entry["t"]
    return math.inf


@pytest.mark.parametrize("seed", [0, 1])
def test_lambda_lssvm_tracks_rudder_aging_faster_than_weighted(aging_runs, seed: int) -> None:
    """Tc 0.1 → 1.0 at 12 s: λ-LS-SVM within 10 % by 19 s, before the weighted variant."""
    ids = aging_runs[seed]
    t_lambda = first_within(ids["lambda"], "Tc", 1.0, 0.1, 12.0)
    t_weighted = first_within(ids["weighted"], "Tc", 1.0, 0.1, 12.0)
    assert t_lambda <= 19.0
    assert t_lambda < t_weighted
    assert ids["lambda"].params.Tc == pytest.approx(1.0, rel=0.02)


@pytest.mark.parametrize("seed", [0, 1])
def test_change_index_exceeds_threshold_only_in_the_transition_window(aging_runs, seed) -> None:
    """λ² > λc² only while the window mixes old and new data (12 s < t ≤ 12 s + Nw·h)."""
    lam = aging_runs[seed]["lambda"]
    over = [e["t"] for e in lam.history if e.get("lambda2", 0.0) > lam.lambda_c[1]]
    assert over, "the servo change must be detected"
    assert all(12.0 < t <= 12.0 + 1200 * 0.01 for t in over)
    assert all(e.get("lambda1", 0.0) <= lam.lambda_c[0] for e in lam.history)  # θ1 unchanged


def test_lambda_lssvm_rejects_negative_gain_and_keeps_previous_model() -> None:
    """Algorithm 2 lines 11–12: θ1 with K < 0 is rejected; the weighted variant accepts it."""
    wrong = Nomoto2Params(K=-0.5)
    psi, delta, delta_c = simulate(wrong, duration=20.0)
    start = Nomoto2Params()
    lam = LambdaLSSVM(H, start)
    weighted = WeightedLSSVMOnline(H, start)
    for k in range(0, psi.size - 50, 50):
        chunk = {"psi": psi[k : k + 50], "delta": delta[k : k + 50], "delta_c": delta_c[k : k + 50]}
        lam.update(chunk)
        weighted.update(chunk)
    assert lam.updates > 0 and all(e["rejected1"] for e in lam.history if "rejected1" in e)
    assert lam.params.K == start.K and lam.params.T1 == start.T1
    assert weighted.params.K < 0


def test_online_identifier_keeps_model_on_degenerate_window() -> None:
    lam = LambdaLSSVM(H)
    n = 1300
    assert not lam.update_arrays(np.linspace(0, 1, n), np.full(n, 0.1), np.full(n, 0.1))
    assert lam.params == Nomoto2Params()
    assert "no excitation" in lam.last_reason


def test_online_window_matches_batch_fit() -> None:
    """The first online window (N_w = 1200 rows = 1203 samples) equals fit_nomoto2 on them."""
    true = Nomoto2Params()
    psi, delta, delta_c = simulate(true, duration=13.0)
    psi, delta, delta_c = psi[:1203], delta[:1203], delta_c[:1203]
    weighted = WeightedLSSVMOnline(H, true)
    for k in range(0, 1203, 50):  # streamed in chunks, as info["samples"] arrive
        weighted.update_arrays(psi[k : k + 50], delta[k : k + 50], delta_c[k : k + 50])
    assert weighted.updates == 1
    batch = fit_nomoto2(psi, delta, delta_c, H)
    for key in ("K", "T1", "T2", "T3", "d0", "Tc"):
        assert getattr(weighted.params, key) == pytest.approx(getattr(batch, key), rel=1e-12)


def test_persistent_excitation_has_the_requested_spread() -> None:
    pe = PersistentExcitation(0.02, np.random.default_rng(6))
    draws = np.array([pe(0.1) for _ in range(20000)]) - 0.1
    assert np.std(draws) == pytest.approx(0.02, rel=0.03)
    assert abs(np.mean(draws)) < 5 * 0.02 / math.sqrt(20000)


def test_persistent_excitation_holds_each_draw_for_hold_calls() -> None:
    """hold = 3 (a slower ship than the paper's): the paper's draws, each kept for three calls."""
    paper = PersistentExcitation(0.02, np.random.default_rng(6))
    held = PersistentExcitation(0.02, np.random.default_rng(6), hold=3)
    draws = [paper(0.0) for _ in range(4)]
    assert [held(0.0) for _ in range(12)] == [d for d in draws for _ in range(3)]


# ----------------------------------------------------------------------------- continuous LS
def test_continuous_least_squares_converges_from_wrong_guesses() -> None:
    """Borkowski (2018) §5: a0 = 0.02, c0 = 0.002 against the true a = 0.018, c = 0.001."""
    a, c, h = 0.018, 0.001, 0.1
    est = ContinuousLeastSquares(h, a0=0.02, c0=0.002)
    r, rs, ds = 0.0, [], []
    for i in range(20000):
        t = i * h
        rs.append(r)
        ds.append(0.3 * math.sin(2 * math.pi * t / 300))
        for j in range(10):  # fine Euler for the plant
            d = 0.3 * math.sin(2 * math.pi * (t + j * h / 10) / 300)
            r += h / 10 * (-a * r + c * d)
    est.update(np.array(rs[:2000]), np.array(ds[:2000]))
    early = (est.a, est.c)
    est.update(np.array(rs[2000:]), np.array(ds[2000:]))
    assert est.a == pytest.approx(a, rel=0.01)
    assert est.c == pytest.approx(c, rel=0.01)
    assert abs(early[0] - a) < abs(0.02 - a)  # it moved toward the truth early on


# ----------------------------------------------------------------------------- zig-zag
def test_zigzag_fit_recovers_nomoto2() -> None:
    """Xu & Guedes Soares (2020) §5.2 pipeline on nomoto2 (C = 2544, Euler regression)."""
    true = Nomoto2Params()
    fit, log = zigzag_nomoto(Nomoto2(true))
    assert fit.K == pytest.approx(true.K, rel=0.02)
    assert fit.T1 == pytest.approx(true.T1, rel=0.02)
    assert fit.T2 == pytest.approx(true.T2, rel=0.06)
    assert fit.d0 == pytest.approx(true.d0, rel=0.02)
    assert np.ptp(log.delta_c) == pytest.approx(math.radians(40.0))


def test_zigzag_fit_rejects_degenerate_data() -> None:
    with pytest.raises(IdentificationError, match="constant"):
        fit_nomoto_zigzag(np.zeros(100), np.full(100, 0.2), H)
    with pytest.raises(IdentificationError, match="too few"):
        fit_nomoto_zigzag(np.zeros(5), np.arange(5.0), H)


def test_window_keeps_the_paper_rhythm_for_large_feeds() -> None:
    """N_w rows, then N_u at a time, whatever the chunk size (1300 then 120 samples)."""
    true = Nomoto2Params()
    psi, delta, delta_c = simulate(true, duration=15.0)
    sizes = []
    weighted = WeightedLSSVMOnline(H, true)
    original = weighted._identify

    def spy() -> None:
        sizes.append(weighted._window_data()[1].shape[0])
        original()

    weighted._identify = spy
    weighted.update_arrays(psi[:1300], delta[:1300], delta_c[:1300])
    weighted.update_arrays(psi[1300:1420], delta[1300:1420], delta_c[1300:1420])
    assert sizes == [1200] * len(sizes) and len(sizes) == 1 + (1417 - 1200) // 50


def test_dropped_sample_restarts_the_difference_chain() -> None:
    """A NaN sample must not join its neighbours into one 2h-wide difference."""
    true = Nomoto2Params()
    psi, delta, delta_c = simulate(true, duration=15.0)
    clean = WeightedLSSVMOnline(H, true)
    dropped = WeightedLSSVMOnline(H, true)
    clean.update_arrays(psi, delta, delta_c)
    psi_nan = psi.copy()
    psi_nan[700] = np.nan
    dropped.update_arrays(psi_nan, delta, delta_c)
    # only the 4 rows touching sample 700 are lost; no row spans the gap
    assert dropped._window_data()[1].max() <= clean._window_data()[1].max() * (1 + 1e-12)
    assert "non-finite" in dropped.last_reason


def test_degenerate_window_keeps_the_nu_rhythm() -> None:
    """A held rudder: one skipped window per N_u rows, not one per row."""
    lam = LambdaLSSVM(H)
    for k in range(40):  # 40 periods of 50 samples, rudder held
        n0 = 50 * k
        lam.update_arrays(np.linspace(0, 1, 2000)[n0 : n0 + 50], np.full(50, 0.1), np.full(50, 0.1))
    skipped = [e for e in lam.history if "skipped" in e]
    assert len(skipped) == 1 + (2000 - 3 - 1200) // 50


# ----------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("h", [0.0, -0.01, math.nan, math.inf, "0.01"])
def test_a_bad_sampling_step_is_refused_by_name_before_any_work(h) -> None:
    """A sampling step h = 0, h < 0 or non-finite → IdentificationError naming h, even
    with data that would fail later for another reason (empty arrays)."""
    empty = np.zeros(0)
    with pytest.raises(IdentificationError, match="sampling step h"):
        fit_nomoto2(empty, empty, empty, h)
    for cls in (LambdaLSSVM, WeightedLSSVMOnline):
        with pytest.raises(IdentificationError, match="sampling step h"):
            cls(h)
    with pytest.raises(IdentificationError, match="sampling step h"):
        ContinuousLeastSquares(h, a0=0.02, c0=0.002)
    with pytest.raises(IdentificationError, match="sampling step h"):
        fit_nomoto_zigzag(empty, empty, h)


@pytest.mark.parametrize("cls", [LambdaLSSVM, WeightedLSSVMOnline])
def test_samples_without_a_key_are_refused_naming_it_and_the_keys_needed(cls) -> None:
    """A dict lacking "delta_c" → IdentificationError naming the missing key
    and the keys the identifier needs; nothing is fed."""
    ident = cls(H)
    samples = {"psi": np.zeros(50), "delta": np.zeros(50)}
    with pytest.raises(IdentificationError, match=r"'delta_c'.*'psi', 'delta', 'delta_c'"):
        ident.update(samples)
    assert ident._window_data()[1].shape[0] == 0 and ident.updates == 0
