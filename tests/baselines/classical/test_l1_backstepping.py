"""L1 adaptive backstepping of Xu, Oliveira & Guedes Soares (2021) (issue 6, item 1)."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
import scipy.signal
import yaml
from scipy.integrate import solve_ivp

from baselines.classical.l1_backstepping import (
    AdaptiveBackstepping,
    Gains,
    L1Backstepping,
    L1BacksteppingSettings,
    NonlinearNomoto,
    SecondOrderLowPass,
    StatePredictor,
    backstepping_rudder,
    cubic_damping_from_zigzag,
    high_frequency_power,
    linearised_closed_loop_poles,
    nominal_design_model,
    projection,
    tvvf_heading_derivatives,
)
from baselines.evaluation import run_episode
from shipgym.guidance import tvvf_heading
from shipgym.models import MODELS, Nomoto2, Nomoto2Params
from shipgym.scenarios import catalogue_dir, scenario_from_dict

DEG = math.pi / 180.0
#: nomoto2's first-order design model (K, T1 + T2 − T3, β) and its sampling
MODEL = NonlinearNomoto(K=0.506, T=1.4483, a2=0.0081)
H_STEP, TS = 0.01, 0.5
BOUNDS = {"rho": (0.1, 10.0), "sigma": (0.1, 10.0), "b": (-0.3, 0.3)}


def _rudder(t: np.ndarray) -> np.ndarray:
    return 0.3 * np.sin(0.5 * t) + 0.15 * np.sin(1.3 * t + 0.4)


def _plant_samples(
    rho: float, sigma: float, b: float, t_end: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The design model T·ṙ + σH(r)r = ρKδ + b (eq. (17), η = 1) under a known rudder."""
    t = np.arange(0.0, t_end + 1e-9, H_STEP)

    def rhs(tt: float, x: np.ndarray) -> list[float]:
        d = float(_rudder(np.array(tt)))
        r = x[1]
        return [r, (rho * MODEL.K * d + b - sigma * MODEL.damping(r) * r) / MODEL.T]

    sol = solve_ivp(rhs, (0.0, t[-1]), [0.0, 0.0], t_eval=t, rtol=1e-11, atol=1e-13)
    return t, sol.y[0], sol.y[1], _rudder(t)


def _predictor(gammas: tuple[float, float, float], bounds=BOUNDS, initial=(1.0, 1.0, 0.0)):
    return StatePredictor(MODEL, 100.0, 10.0, *gammas, bounds, 0.1, initial)


# --------------------------------------------------------------------------- predictor
def test_prediction_errors_decay_at_gamma1_and_gamma2_when_the_plant_is_the_model() -> None:
    """Plant = design model, estimates = truth (adaptation frozen): eq. (21) reduces to
    ψ̃' = −Γ1·ψ̃, r̃' = −Γ2·r̃, so ψ̃(t) = ψ̃0·e^(−100t) and r̃(t) = r̃0·e^(−10t)."""
    t, psi, r, delta = _plant_samples(1.0, 1.0, 0.02, 1.0)
    pred = _predictor((0.0, 0.0, 0.0), initial=(1.0, 1.0, 0.02))
    pred.reset(psi[0] + 0.2, r[0] + 0.05)
    psi_err, r_err = [0.2], [0.05]
    for j in range(len(t) - 1):
        pred.advance(psi[j : j + 2], r[j : j + 2], delta[j : j + 2], H_STEP)
        psi_err.append(pred.psi_hat - psi[j + 1])
        r_err.append(pred.r_hat - r[j + 1])
    # floor ~1e-6: ψ and r are interpolated linearly between the samples at h
    np.testing.assert_allclose(psi_err, 0.2 * np.exp(-100.0 * t), rtol=1e-3, atol=1e-6)
    np.testing.assert_allclose(r_err, 0.05 * np.exp(-10.0 * t), rtol=1e-3, atol=1e-6)


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


# --------------------------------------------------------------------------- projection
def test_projection_leaves_the_update_alone_inside_and_stops_it_at_the_bound() -> None:
    lo, hi, eps = 0.1, 10.0, 0.1
    assert projection(5.0, 3.0, lo, hi, eps) == 3.0
    assert projection(hi, 3.0, lo, hi, eps) == pytest.approx(0.0, abs=1e-12)  # f = 1
    assert projection(lo, -3.0, lo, hi, eps) == pytest.approx(0.0, abs=1e-12)
    assert projection(hi, -3.0, lo, hi, eps) == -3.0  # inwards: untouched
    rng = np.random.default_rng(0)
    c, w0 = 0.5 * (lo + hi), 0.5 * (hi - lo) / math.sqrt(1 + eps)
    for _ in range(2000):  # (θ − θ*)(Proj(θ, y) − y) ≤ 0 for θ* in the inner set
        theta, star, y = rng.uniform(lo, hi), rng.uniform(c - w0, c + w0), rng.normal()
        assert (theta - star) * (projection(theta, y, lo, hi, eps) - y) <= 1e-12


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


def test_closed_loop_bias_estimate_stays_bounded_when_the_bias_exceeds_the_rudder() -> None:
    """nomoto2 with d0 = 20 °/s (0.35 rad/s > K·δmax = 0.265 rad/s): b̂ stays in ±K·δmax."""
    data = yaml.safe_load((catalogue_dir() / "nominal.yaml").read_text())
    data["ship"]["params"]["d0"] = 20.0
    data["time_limit"] = 20.0
    policy = L1Backstepping()
    run_episode(policy, scenario_from_dict(data), 0)
    bound = policy.model.K * policy.ctx.rudder_limit
    b_hat = np.array(policy.history["b"])
    assert np.abs(b_hat).max() <= bound
    assert b_hat.max() > 0.9 * bound


# --------------------------------------------------------------------------- filter
def test_low_pass_filter_step_response_matches_c_of_s() -> None:
    """Eq. (39), ω = 0.25 rad/s, ζ = 1, Ts = 0.5 s: the sampled state equals scipy's step
    response of C(s) (1e-9), and the command equals its period average (1e-7)."""
    filt = SecondOrderLowPass(0.25, 1.0, TS)
    system = scipy.signal.lti(*filt.transfer_function())
    n = 120
    averages, samples = [], []
    for _ in range(n):
        averages.append(filt.step(1.0))
        samples.append(filt.output)
    t_samples = TS * np.arange(1, n + 1)
    _, y = scipy.signal.step(system, T=np.concatenate(([0.0], t_samples)))
    np.testing.assert_allclose(samples, y[1:], atol=1e-9)
    fine = np.linspace(0.0, n * TS, n * 500 + 1)
    _, y_fine, _ = scipy.signal.lsim(system, np.ones_like(fine), fine)
    seg = y_fine[:-1].reshape(n, 500)
    nxt = np.append(seg[1:, 0], y_fine[-1])
    trapezoid = (seg.sum(axis=1) - 0.5 * seg[:, 0] + 0.5 * nxt) / 500
    np.testing.assert_allclose(averages, trapezoid, atol=1e-7)
    # closed form of the critically damped step: 1 − (1 + ωt)e^(−ωt)
    np.testing.assert_allclose(samples, 1 - (1 + 0.25 * t_samples) * np.exp(-0.25 * t_samples))


# --------------------------------------------------------------------------- guidance, law
@pytest.mark.parametrize("unit", [1.0, 0.2923])
@pytest.mark.parametrize("ye", [-7.3, -0.4, 0.05, 0.9, 3.0, 25.0])
def test_tvvf_heading_derivatives_match_finite_differences(ye: float, unit: float) -> None:
    delta = 1.9

    def psi_d(e: float) -> float:
        return tvvf_heading(e, 0.0, delta, error_unit=unit)

    d1, d2 = tvvf_heading_derivatives(ye, delta, error_unit=unit)
    step = 1e-4 * max(1.0, abs(ye))
    fd1 = (psi_d(ye + step) - psi_d(ye - step)) / (2 * step)
    fd2 = (psi_d(ye + step) - 2 * psi_d(ye) + psi_d(ye - step)) / step**2
    assert d1 == pytest.approx(fd1, rel=1e-5, abs=1e-9)
    assert d2 == pytest.approx(fd2, rel=1e-3, abs=1e-5)


def test_backstepping_error_system_is_the_designed_linear_one() -> None:
    """Plant = design model, exact estimates, δ applied continuously: z1, z2 obey
    ż1 = −K1·z1 + z2, T·ż2 = −c·z1 − K2·z2 (eqs. (30), (35)) for a moving reference."""
    gains = Gains.transfer(L1BacksteppingSettings(), 0.95, 0.8, "m")
    b = 0.02

    def reference(t: float) -> tuple[float, float, float]:
        return 0.3 * math.sin(0.2 * t), 0.06 * math.cos(0.2 * t), -0.012 * math.sin(0.2 * t)

    def closed_loop(t: float, x: np.ndarray) -> list[float]:
        delta, _, _ = backstepping_rudder(MODEL, gains, x[0], x[1], reference(t), (1, 1, b))
        return [x[1], (MODEL.K * delta + b - MODEL.damping(x[1]) * x[1]) / MODEL.T]

    t = np.linspace(0.0, 20.0, 201)
    sol = solve_ivp(closed_loop, (0, 20), [0.2, 0.0], t_eval=t, rtol=1e-10, atol=1e-12)
    z = np.array(
        [
            backstepping_rudder(MODEL, gains, p, r, reference(tt), (1, 1, b))[1:]
            for tt, p, r in zip(t, sol.y[0], sol.y[1], strict=True)
        ]
    )
    a = np.array([[-gains.K1, 1.0], [-gains.z1_weight / MODEL.T, -gains.K2 / MODEL.T]])
    lin = solve_ivp(lambda _, x: a @ x, (0, 20), z[0], t_eval=t, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(z, lin.y.T, atol=1e-6)


# --------------------------------------------------------------------------- nominal model
def test_cubic_damping_fit_recovers_a2_of_a_first_order_ship() -> None:
    """A nomoto2 with T2 → 0, T3 = 0 is T1·ṙ + r + β·r³ = K·δ + d0: the zig-zag fit with
    the true K and T returns a2 = β (to 2 %; T2 = 5 ms leaves a 0.6 % bias)."""
    params = Nomoto2Params(T2=0.005, T3=0.0, beta=20.0, d0=0.01)
    a2 = cubic_damping_from_zigzag(Nomoto2(params), params.K, params.T1 + params.T2)
    assert a2 == pytest.approx(20.0, rel=0.02)


def test_nomoto2_design_model_is_the_first_order_reduction_with_beta() -> None:
    m = nominal_design_model(Nomoto2())
    p = Nomoto2Params()
    assert (m.K, m.T, m.a2) == pytest.approx((p.K, p.T1 + p.T2 - p.T3, p.beta))


def test_similarity_transfer_keeps_the_printed_gains_on_the_paper_ship() -> None:
    settings = L1BacksteppingSettings()
    paper = Gains.transfer(settings, 3.25, 0.41, "m")
    assert (paper.K1, paper.gamma1, paper.filter_frequency, paper.error_unit) == (
        0.02,
        100.0,
        0.25,
        1.0,
    )
    mariner = Gains.transfer(settings, 172.0, 7.7, "m")
    tau = (172.0 / 7.7) / (3.25 / 0.41)
    assert mariner.K1 * tau == pytest.approx(0.02)
    assert mariner.gamma_rho / tau == pytest.approx(20.0)
    assert mariner.error_unit == pytest.approx(172.0 / 3.25)


# --------------------------------------------------------------------------- closed loop
def _catalogue(name: str, **changes: object) -> dict:
    data = yaml.safe_load((catalogue_dir() / f"{name}.yaml").read_text())
    data.update(changes)
    return data


@pytest.mark.parametrize("policy_type", [L1Backstepping, AdaptiveBackstepping])
def test_nomoto2_nominal_reaches_the_goal(policy_type: type) -> None:
    res = run_episode(policy_type(), "nominal", 0)
    assert res.metrics["termination_reason"] == "goal"
    assert np.abs(res.trajectory["cross_track_error"]).max() < 6.0  # corridor 9.5 m


@pytest.mark.parametrize("policy_type", [L1Backstepping, AdaptiveBackstepping])
def test_blanke_current_shift_reaches_the_goal(policy_type: type) -> None:
    """blanke_current_shift: four legs, 0.5 m/s cross current from t = 150 s."""
    res = run_episode(policy_type(), "blanke_current_shift", 0)
    assert res.metrics["termination_reason"] == "goal"
    assert res.metrics["ace"] < 15.0  # measured 10.3 (L1), 4.2 (adaptive); L = 51.5 m


def test_mariner_track_stays_bounded() -> None:
    """First 400 s of mariner_track (first leg): adaptive backstepping converges; the L1
    controller (filter ω = 0.09 rad/s here) limit-cycles but never drifts beyond the
    500-m start offset."""
    scenario = scenario_from_dict(_catalogue("mariner_track", time_limit=400.0))
    adaptive = run_episode(AdaptiveBackstepping(), scenario, 0)
    t = adaptive.trajectory["t"]
    settled = (t >= 280.0) & (t <= 380.0)  # end of the first leg, before the switch
    assert np.abs(adaptive.trajectory["cross_track_error"][settled]).max() < 5.0
    l1 = run_episode(L1Backstepping(), scenario, 0)
    assert l1.metrics["termination_reason"] == "time_limit"
    assert np.abs(l1.trajectory["cross_track_error"]).max() < 505.0


@pytest.mark.parametrize("policy_type", [L1Backstepping, AdaptiveBackstepping])
def test_esso_osaka_follows_the_paper_route_in_the_two_phase_current(policy_type: type) -> None:
    """osaka_stochastic_current (Xu et al. 2021 §5.2): the paper's ship, route and current,
    gains as printed (τ = 0.996): both reach the last waypoint with ACE < 1.5 m
    (measured 0.89 m with C(s), 0.19 m without; L = 3.25 m)."""
    res = run_episode(policy_type(), "osaka_stochastic_current", 0)
    assert res.metrics["termination_reason"] == "goal"
    assert res.metrics["ace"] < 1.5


def test_filter_removes_high_frequency_rudder_activity() -> None:
    """nomoto2 nominal: the rudder angle's power above the filter corner (ω = 1.67 rad/s
    after the similarity transfer) with C(s) is < 10 % of that without (measured 2.2 %)."""
    power = {}
    for policy in (L1Backstepping(), AdaptiveBackstepping()):
        res = run_episode(policy, "nominal", 0)
        omega = policy.gains.filter_frequency
        power[policy.name] = high_frequency_power(res.trajectory["rudder_angle"], TS, omega)
    assert power["l1_backstepping"] < 0.1 * power["adaptive_backstepping"]


def test_bad_settings_are_refused() -> None:
    with pytest.raises(ValueError, match="gain_transfer"):
        L1Backstepping(gain_transfer="froude")
    with pytest.raises(ValueError, match="error_unit"):
        AdaptiveBackstepping(error_unit="ft")
    with pytest.raises(ValueError, match="K1, K2"):
        L1Backstepping(K2=0.0)
    with pytest.raises(ValueError, match="outside its bounds"):
        StatePredictor(MODEL, 100, 10, 20, 20, 10, BOUNDS, 0.1, (20.0, 1.0, 0.0))


def test_a_step_without_samples_uses_the_period_end_points() -> None:
    """info without ``samples`` (a diverged step): the predictor interpolates the two end
    measurements and the command stays finite and within ±1."""
    env = gym.make("ShipPathFollow-v0", scenario="nominal")
    obs, info = env.reset(seed=0)
    policy = L1Backstepping()
    policy.reset(env.unwrapped.controller_context, seed=0)
    for k in range(6):
        action = policy.act(obs, info)
        assert np.isfinite(action).all() and np.abs(action).max() <= 1.0
        obs, _, _, _, info = env.step(action)
        if k == 3:
            info = {key: value for key, value in info.items() if key != "samples"}
    assert abs(policy.predictor.r_hat - info["yaw_rate"]) < 0.05
    env.close()


def test_printed_design_is_linearly_unstable_with_the_filter_on_the_paper_ship() -> None:
    """Why ``l1_backstepping`` limit-cycles: on the Esso Osaka's identified design model
    (K = 0.189 1/s, T = 7.37 s) the printed gains give a stable loop without C(s) (its poles
    are the designed error system's) and an unstable one with C(s) on the whole command
    (eq. (39), ω = 0.25 rad/s): the saturated rudder then bounds an oscillation."""
    model = nominal_design_model(MODELS["esso_osaka"]())
    gains = Gains.transfer(L1BacksteppingSettings(gain_transfer="literal"), 3.25, 0.41, "m")
    without = np.sort_complex(linearised_closed_loop_poles(model, gains))
    error_system = np.array([[-gains.K1, 1.0], [-gains.z1_weight / model.T, -gains.K2 / model.T]])
    np.testing.assert_allclose(without, np.sort_complex(np.linalg.eigvals(error_system)))
    assert without.real.max() < 0
    with_filter = linearised_closed_loop_poles(model, gains, 0.25, 1.0)
    assert with_filter.real.max() > 0.05  # measured 0.070 1/s
