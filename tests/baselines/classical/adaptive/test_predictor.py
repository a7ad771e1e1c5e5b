"""State predictor and adaptation (Xu, Oliveira & Guedes Soares 2021 eqs. (18)–(26))."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from shipgym_baselines.classical.adaptive.design_model import NonlinearNomoto
from shipgym_baselines.classical.adaptive.predictor import StatePredictor

#: nomoto2's first-order design model (K, T1 + T2 − T3, β)
MODEL = NonlinearNomoto(K=0.506, T=1.4483, a2=0.0081)
H_STEP = 0.01  # [s]
BOUNDS = {"rho": (0.1, 10.0), "sigma": (0.1, 10.0), "b": (-0.3, 0.3)}


def _rudder(t: np.ndarray) -> np.ndarray:
    return 0.3 * np.sin(0.5 * t) + 0.15 * np.sin(1.3 * t + 0.4)


def _plant_samples(
    rho: float, sigma: float, b: float, t_end: float, h: float = H_STEP
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The design model T·ṙ + σH(r)r = ρKδ + b (eq. (17), η = 1) under a known rudder."""
    t = np.arange(0.0, t_end + 1e-9, h)

    def rhs(tt: float, x: np.ndarray) -> list[float]:
        d = float(_rudder(np.array(tt)))
        r = x[1]
        return [r, (rho * MODEL.K * d + b - sigma * MODEL.damping(r) * r) / MODEL.T]

    sol = solve_ivp(rhs, (0.0, t[-1]), [0.0, 0.0], t_eval=t, rtol=1e-11, atol=1e-13)
    return t, sol.y[0], sol.y[1], _rudder(t)


def _predictor(gammas: tuple[float, float, float], bounds=BOUNDS, initial=(1.0, 1.0, 0.0)):
    return StatePredictor(MODEL, 100.0, 10.0, *gammas, bounds, 0.1, initial)


def _run(pred: StatePredictor, psi, r, delta, h=H_STEP) -> tuple[np.ndarray, np.ndarray]:
    """(ψ̃, r̃) after each step of h."""
    psi_err, r_err = [], []
    for j in range(len(psi) - 1):
        pred.advance(psi[j : j + 2], r[j : j + 2], delta[j : j + 2], h)
        psi_err.append(pred.psi_hat - psi[j + 1])
        r_err.append(pred.r_hat - r[j + 1])
    return np.array(psi_err), np.array(r_err)


def test_perfect_model_at_a_steady_turn_has_zero_prediction_error() -> None:
    """Plant = design model, estimates = truth, a steady turn (δ constant, r with
    σH(r)r = ρKδ + b, ψ linear in t: the interpolation is exact): ψ̃ = r̃ = 0 and the
    adaptation (on) leaves the estimates at the truth, over 20 s, to rounding."""
    truth, delta = (0.8, 1.2, 0.02), 0.1
    r_ss = float(
        np.roots([truth[1] * MODEL.a2, 0.0, truth[1], -truth[0] * MODEL.K * delta - 0.02])[-1].real
    )
    assert truth[1] * MODEL.damping(r_ss) * r_ss == pytest.approx(truth[0] * MODEL.K * delta + 0.02)
    t = np.arange(0.0, 20.0 + 1e-9, H_STEP)
    psi, r, d = 0.3 + r_ss * t, np.full_like(t, r_ss), np.full_like(t, delta)
    pred = _predictor((20.0, 20.0, 10.0), initial=truth)
    pred.reset(psi[0], r[0])
    psi_err, r_err = _run(pred, psi, r, d)
    assert np.abs(psi_err).max() < 1e-12 and np.abs(r_err).max() < 1e-12
    np.testing.assert_allclose(pred.estimates, truth, atol=1e-12)


def test_perfect_model_prediction_error_is_only_the_interpolation_error() -> None:
    """Plant = design model, estimates = truth, a manoeuvring rudder: started on the
    measured state, the predictor stays on it up to the error of interpolating ψ, r, δ
    linearly between samples, O(h²): < 1e-6 at h = 10 ms, four times smaller at 5 ms."""
    truth = (0.8, 1.2, 0.02)
    worst = []
    for h in (H_STEP, H_STEP / 2):
        _, psi, r, d = _plant_samples(*truth, 20.0, h)
        pred = _predictor((20.0, 20.0, 10.0), initial=truth)
        pred.reset(psi[0], r[0])
        psi_err, r_err = _run(pred, psi, r, d, h)
        worst.append(max(np.abs(psi_err).max(), np.abs(r_err).max()))
        np.testing.assert_allclose(pred.estimates, truth, atol=1e-5)
    assert worst[0] < 1e-6
    assert 3.5 < worst[0] / worst[1] < 4.5


def test_prediction_errors_decay_at_gamma1_and_gamma2_when_the_plant_is_the_model() -> None:
    """Plant = design model, estimates = truth (adaptation frozen): eq. (21) reduces to
    ψ̃' = −Γ1·ψ̃, r̃' = −Γ2·r̃, so ψ̃(t) = ψ̃0·e^(−100t) and r̃(t) = r̃0·e^(−10t)."""
    t, psi, r, delta = _plant_samples(1.0, 1.0, 0.02, 1.0)
    pred = _predictor((0.0, 0.0, 0.0), initial=(1.0, 1.0, 0.02))
    pred.reset(psi[0] + 0.2, r[0] + 0.05)
    psi_err, r_err = _run(pred, psi, r, delta)
    # floor ~1e-6: ψ and r are interpolated linearly between the samples at h
    np.testing.assert_allclose(psi_err, 0.2 * np.exp(-100.0 * t[1:]), rtol=1e-3, atol=1e-6)
    np.testing.assert_allclose(r_err, 0.05 * np.exp(-10.0 * t[1:]), rtol=1e-3, atol=1e-6)


def test_prediction_lyapunov_function_dissipates_as_eq_26_says() -> None:
    """Eq. (26): with the adaptation laws (24)/(25) (projection inactive), V_pred of
    eq. (22) obeys dV/dt = −Γ1·ψ̃² − T·Γ2·r̃² for a mismatched plant (ρ = 0.6, σ = 1.5,
    b = 0.02).  ψ̃ decays on its own (previous test); its part of V is taken out and the
    rest, V_r = ½T·r̃² + Σ(θ̂ − θ)²/(2γ), must equal V_r(0) − ∫T·Γ2·r̃²dt (to 0.1 % of V_r(0))
    and never increase."""
    truth = (0.6, 1.5, 0.02)
    t, psi, r, delta = _plant_samples(*truth, 30.0)
    pred = _predictor((20.0, 20.0, 10.0))
    pred.reset(psi[0] + 0.1, r[0] - 0.05)

    def v_r(j: int) -> float:
        return pred.lyapunov(psi[j], r[j], truth) - 0.5 * (pred.psi_hat - psi[j]) ** 2

    values, rates = [v_r(0)], [MODEL.T * 10.0 * 0.05**2]
    for j in range(len(t) - 1):
        pred.advance(psi[j : j + 2], r[j : j + 2], delta[j : j + 2], H_STEP)
        values.append(v_r(j + 1))
        rates.append(MODEL.T * 10.0 * (pred.r_hat - r[j + 1]) ** 2)
    rates_a = np.array(rates)
    dissipated = np.concatenate(([0.0], np.cumsum(0.5 * (rates_a[1:] + rates_a[:-1]))))
    v0 = values[0]
    np.testing.assert_allclose(values, v0 - H_STEP * dissipated, atol=1e-3 * v0)
    assert np.diff(values).max() <= 1e-9 * v0
    assert values[-1] < 0.7 * v0  # measured 0.62


def test_estimates_stay_inside_the_projection_bounds_under_a_large_disturbance() -> None:
    """b = 0.5 rad/s against |b̂| ≤ 0.1 and K halved: every estimate stays in its set at
    every fine step, b̂ is pressed against its bound, and without projection it would not
    have stayed there."""
    bounds = {"rho": (0.3, 3.0), "sigma": (0.3, 3.0), "b": (-0.1, 0.1)}
    t, psi, r, delta = _plant_samples(0.5, 1.0, 0.5, 20.0)
    for bnds, must_hold in ((bounds, True), ({**bounds, "b": (-100.0, 100.0)}, False)):
        pred = _predictor((20.0, 20.0, 10.0), bounds=bnds)
        pred.reset(psi[0], r[0])
        history = []
        for j in range(len(t) - 1):
            pred.advance(psi[j : j + 2], r[j : j + 2], delta[j : j + 2], H_STEP)
            history.append(pred.estimates)
        est = np.array(history)
        inside = all(
            (bounds[k][0] <= est[:, i]).all() and (est[:, i] <= bounds[k][1]).all()
            for i, k in enumerate(("rho", "sigma", "b"))
        )
        assert inside is must_hold
        if must_hold:
            assert est[:, 2].max() > 0.95 * bounds["b"][1]


def test_heading_is_unwrapped_onto_the_predictor_branch() -> None:
    """A steady turn through ±π: measured ψ wraps, ψ̂ follows it continuously."""
    t = np.arange(0.0, 2.0 + 1e-9, H_STEP)
    r_ss = 0.4
    unwrapped = math.pi - 0.2 + r_ss * t
    wrapped = (unwrapped + math.pi) % (2 * math.pi) - math.pi
    pred = _predictor((0.0, 0.0, 0.0))
    pred.reset(wrapped[0], r_ss)
    for j in range(len(t) - 1):
        pred.advance(wrapped[j : j + 2], [r_ss, r_ss], [0.0, 0.0], H_STEP)
    assert pred.psi_hat == pytest.approx(unwrapped[-1], abs=1e-3)


def test_initial_estimates_outside_their_bounds_are_refused() -> None:
    with pytest.raises(ValueError, match="outside its bounds"):
        StatePredictor(MODEL, 100, 10, 20, 20, 10, BOUNDS, 0.1, (20.0, 1.0, 0.0))
    with pytest.raises(ValueError, match="positive"):
        StatePredictor(MODEL, 100, 10, 20, 20, 10, {**BOUNDS, "rho": (-1.0, 2.0)})


def _reference_advance(pred: StatePredictor, psi, r, delta, step: float) -> None:
    """The predictor's integration written plainly on :meth:`StatePredictor._rhs` (RK4 with
    list arithmetic): what ``advance`` computes, more slowly."""
    psi = np.unwrap(np.asarray(psi, dtype=float))
    psi = psi + 2.0 * math.pi * round((pred.psi_hat - psi[0]) / (2.0 * math.pi))
    n_sub = max(1, math.ceil(pred.gamma2 * step / 0.5))
    dt = step / n_sub
    decay = math.exp(-pred.gamma1 * step)
    phi1 = (1.0 - decay) / pred.gamma1
    phi2 = (step - phi1) / pred.gamma1
    s = [pred.r_hat, pred.rho, pred.sigma, pred.b]
    for j in range(len(psi) - 1):
        u0 = pred.gamma1 * psi[j] + r[j]
        u1 = pred.gamma1 * psi[j + 1] + r[j + 1]
        pred.psi_hat = decay * pred.psi_hat + u0 * phi1 + (u1 - u0) / step * phi2
        r0, dr = r[j], (r[j + 1] - r[j]) / n_sub
        e0, de = delta[j], (delta[j + 1] - delta[j]) / n_sub
        for i in range(n_sub):
            ra, da = r0 + i * dr, e0 + i * de
            rm, dm = ra + 0.5 * dr, da + 0.5 * de
            k1 = pred._rhs(s, ra, da)
            k2 = pred._rhs([x + 0.5 * dt * k for x, k in zip(s, k1, strict=True)], rm, dm)
            k3 = pred._rhs([x + 0.5 * dt * k for x, k in zip(s, k2, strict=True)], rm, dm)
            k4 = pred._rhs([x + dt * k for x, k in zip(s, k3, strict=True)], ra + dr, da + de)
            s = [
                x + dt / 6.0 * (a + 2.0 * b + 2.0 * c + d)
                for x, a, b, c, d in zip(s, k1, k2, k3, k4, strict=True)
            ]
    pred.r_hat, pred.rho, pred.sigma, pred.b = s


def test_advance_equals_the_plain_rk4_of_the_rhs_bit_for_bit() -> None:
    """The unrolled integration (speed) is the RK4 of eq. (20), (25) as written, including
    active projections (a large disturbance pushes b̂ into its boundary layer)."""
    t, psi, r, delta = _plant_samples(1.4, 0.7, 0.35, 40.0, h=0.05)  # b beyond its bound
    fast, slow = _predictor((5.0, 5.0, 5.0)), _predictor((5.0, 5.0, 5.0))
    fast.reset(psi[0], r[0])
    slow.reset(psi[0], r[0])
    for j in range(0, len(t) - 10, 10):  # periods of 10 samples, as the env's Ts/h
        fast.advance(psi[j : j + 11], r[j : j + 11], delta[j : j + 11], 0.05)
        _reference_advance(
            slow, psi[j : j + 11].tolist(), r[j : j + 11].tolist(), delta[j : j + 11].tolist(), 0.05
        )
        assert (fast.psi_hat, *fast.estimates, fast.r_hat) == (
            slow.psi_hat,
            *slow.estimates,
            slow.r_hat,
        )
    w0 = BOUNDS["b"][1] / math.sqrt(1.1)  # inner interval of the projection (ε = 0.1)
    assert w0 < fast.b <= BOUNDS["b"][1]  # b̂ went into the boundary layer: projection active
