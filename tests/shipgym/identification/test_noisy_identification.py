"""Identification that survives sensor noise: the SVF front end against the paper's
differences on noisy headings."""

from __future__ import annotations

import math

import pytest

from shipgym.identification.errors import IdentificationError
from shipgym.identification.nomoto import fit_nomoto2
from shipgym.identification.online import LambdaLSSVM, WeightedLSSVMOnline
from shipgym.models.nomoto2 import Nomoto2Params
from tests.shipgym.identification.logs import H, measured_heading, simulate

#: a ship unlike the paper's (slower, larger gain, other servo and bias)
SHIP = Nomoto2Params(K=2.0, T1=2.5, T2=0.4, T3=0.2, d0=math.radians(-1.0), beta=0.001, Tc=0.4)


def rel(est: Nomoto2Params, key: str, true: Nomoto2Params = SHIP) -> float:
    return abs(getattr(est, key) - getattr(true, key)) / abs(getattr(true, key))


@pytest.fixture(scope="module")
def log():
    return simulate(SHIP, duration=60.0)


@pytest.mark.parametrize("seed", [0, 1])
def test_svf_fit_recovers_a_noisy_ship_the_differences_cannot(log, seed: int) -> None:
    """σ = 0.2° heading noise and 5–15° outliers (the Case 3 sensor): the SVF fit has K, T1
    and Tc within 10 % (measured: K 0.3 %, T1 1.4 %, Tc exact); the differences give no real
    T1, T2 or are far off."""
    psi, delta, delta_c = log
    noisy = measured_heading(psi, seed)
    est = fit_nomoto2(noisy, delta, delta_c, H, front_end="svf", servo_model="exact")
    for key in ("K", "T1", "Tc"):
        assert rel(est, key) < 0.10, key
    try:
        paper = fit_nomoto2(noisy, delta, delta_c, H, servo_model="exact")
    except IdentificationError:
        return  # rejected
    assert max(rel(paper, "K"), rel(paper, "T1")) > 0.5


@pytest.mark.parametrize("front_end", ["differences", "svf"])
def test_both_front_ends_recover_a_noise_free_ship_within_2_percent(log, front_end) -> None:
    psi, delta, delta_c = log
    est = fit_nomoto2(psi, delta, delta_c, H, front_end=front_end, servo_model="exact")
    for key in ("K", "T1", "Tc"):
        assert rel(est, key) < 0.02, key


def test_noise_free_svf_fit_resolves_the_fast_time_constant_of_the_papers_ship() -> None:
    """Without noise the filtered signals obey eq. (1) exactly, whatever λ: on the paper's
    ship (T2 = 0.1245 s, beyond 1/λ = 0.33 s) every parameter is within 0.5 %, where the
    differences' O(h) bias leaves T3 +29 % (β is not identifiable: README)."""
    true = Nomoto2Params()
    psi, delta, delta_c = simulate(true, duration=60.0)
    est = fit_nomoto2(psi, delta, delta_c, H, front_end="svf", servo_model="exact")
    for key in ("K", "T1", "T2", "T3", "d0", "Tc"):
        assert rel(est, key, true) < 0.005, key


def test_online_svf_window_matches_the_batch_fit(log) -> None:
    """Streamed in periods of 50 samples, the first SVF window equals fit_nomoto2 on the
    same samples (the batch fit is the streaming front end fed at once)."""
    psi, delta, delta_c = log
    psi = measured_heading(psi, seed=2)
    online = WeightedLSSVMOnline(H, SHIP, front_end="svf")
    settle = online._source.settle
    n = settle + online.window + online.delay  # exactly one window of rows
    for k in range(0, n, 50):
        stop = min(k + 50, n)
        online.update_arrays(psi[k:stop], delta[k:stop], delta_c[k:stop])
    assert online.updates == 1
    batch = fit_nomoto2(psi[:n], delta[:n], delta_c[:n], H, front_end="svf")
    for key in ("K", "T1", "T2", "T3", "d0", "Tc"):
        assert getattr(online.params, key) == pytest.approx(getattr(batch, key), rel=1e-9)


@pytest.fixture(scope="module")
def case3_log():
    """Case 3 (maneuverability_change, heading noise and outliers) under pid_los + 1° eq. (45)
    excitation, open loop for the identifiers."""
    from shipgym_baselines.studies.benchmarks import identification_log

    return identification_log("maneuverability_change", seed=0, excitation_deg=1.0)


def test_change_index_with_the_svf_detects_the_case3_change_and_only_it(case3_log) -> None:
    """λ¹ (eq. (43)) stays below λc¹ on every update before the change at 18 s and exceeds it
    after; with the differences the noise pushes λ¹ over λc¹ before the change already."""
    log, sc = case3_log
    change = sc.change_time
    indices = {}
    for front_end in ("svf", "differences"):
        ident = LambdaLSSVM(sc.fine_step, sc.nominal_params, front_end=front_end)
        for samples in log:
            ident.update(samples)
        indices[front_end] = [
            (e["t"], e["lambda1"] > ident.lambda_c[0]) for e in ident.history if "lambda1" in e
        ]
    svf = indices["svf"]
    before = [over for t, over in svf if t <= change]
    assert before and not any(before)
    assert any(over for t, over in svf if t > change)
    assert any(over for t, over in indices["differences"] if t <= change)


def test_svf_identifier_finds_the_post_change_ship_of_case3(case3_log) -> None:
    """After the change (K 0.59 → 6, T1 0.95 → 3, T2 0.0247 → 1 s) the SVF identifier ends
    within 5 % on K, T1, T2, T3 and Tc; the paper's differences end > 50 % off on K."""
    log, sc = case3_log
    truth = sc.schedule.final
    ends = {}
    for front_end in ("svf", "differences"):
        ident = LambdaLSSVM(sc.fine_step, sc.nominal_params, front_end=front_end)
        for samples in log:
            ident.update(samples)
        ends[front_end] = ident.params
    for key in ("K", "T1", "T2", "T3", "Tc"):
        assert rel(ends["svf"], key, truth) < 0.05, key
    assert rel(ends["differences"], "K", truth) > 0.5
