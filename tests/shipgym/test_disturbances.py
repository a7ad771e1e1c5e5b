"""Stochastic environmental disturbances: currents, waves, their use in the env.

Statistical tolerances are about five standard errors of the estimate for the sample used
(stated per test), with fixed seeds, so the tests are deterministic and cannot pass by luck
with a wrong process.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from scipy.linalg import solve_continuous_lyapunov, solve_discrete_lyapunov
from scipy.signal import lfilter, welch

from shipgym.disturbance_config import ConstantCurrent, DisturbanceConfig, WaveConfig
from shipgym.disturbances import (
    Disturbances,
    WaveFilter,
    ar1_saturated,
    gauss_markov_coefficients,
    spectrum_coefficients,
    wave_spectrum,
)
from shipgym.envs.path_follow import ShipPathFollowEnv
from shipgym.scenarios.loader import (
    ScenarioError,
    list_scenarios,
    load_scenario,
    scenario_from_dict,
)

DEG = math.pi / 180.0
NAMES = ("current_x", "current_y", "yaw_disturbance")
IX, IY, IYAW = 0, 1, 2


def sample(
    config: dict, h: float, n_sub: int, periods: int, batch: int = 1, seed: int = 0
) -> np.ndarray:
    """(batch, periods·n_sub, 3) disturbance samples of ``batch`` independent ships."""
    dist = Disturbances(
        DisturbanceConfig.model_validate(config), NAMES, h, n_sub, batch, time_limit=1e9
    )
    rngs = [np.random.default_rng([seed, i]) for i in range(batch)]
    for i, rng in enumerate(rngs):
        dist.reset(i, rng)
    block = np.zeros((batch, n_sub, 3))
    rows = np.arange(batch)
    out = []
    for k in range(periods):
        noise = [dist.draw(rng) for rng in rngs]
        noise = None if noise[0] is None else np.stack(noise)
        dist.fill(block, np.full(batch, k * n_sub * h), noise, rows)
        out.append(block.copy())
    return np.concatenate(out, axis=1)


def speed_of(samples: np.ndarray) -> np.ndarray:
    return np.sqrt(samples[..., IX] ** 2 + samples[..., IY] ** 2)


def nomoto_scenario(disturbances: dict, **changes) -> dict:
    """A straight-line nomoto2 scenario with d0 = 0 (heading stays put under zero rudder)."""
    data = {
        "name": "drift",
        "ship": {"model": "nomoto2", "params": {"d0": 0.0}},
        "path": {"waypoints": [[0.0, 0.0], [1000.0, 0.0]]},
        "disturbances": disturbances,
        "time_limit": 30.0,
    }
    data.update(changes)
    return data


# ------------------------------------------------------------------ (a) drift with the current


def test_ship_without_rudder_drifts_exactly_with_a_constant_current() -> None:
    """ẋ = u0 cos ψ + Vcx, ẏ = u0 sin ψ + Vcy with ψ ≡ 0: the displacement beyond the ship's
    own u0·t is V_c·t (u0 > 0 is required by the model, so it is subtracted)."""
    speed, direction = 0.3, 60.0
    env = ShipPathFollowEnv(
        scenario_from_dict(
            nomoto_scenario({"current": {"speed": speed, "direction_deg": direction}})
        )
    )
    env.reset(seed=0)
    u0 = env.model.nominal_speed
    for k in range(1, 41):
        _, _, terminated, truncated, info = env.step(np.zeros(1))
        assert not (terminated or truncated)
        t = k * 0.5
        x, y = info["position"]
        assert info["heading"] == 0.0
        assert x - u0 * t == pytest.approx(speed * math.cos(direction * DEG) * t, abs=1e-12)
        assert y == pytest.approx(speed * math.sin(direction * DEG) * t, abs=1e-12)


def test_ship_drifts_by_the_integral_of_a_stochastic_current() -> None:
    """RK4 of the kinematics is exact for a current held per substep: each period moves the
    ship by h·Σ (rows of the disturbance block), i.e. the block enters at the right rows."""
    current = {"kind": "gauss_markov", "speed": 0.2, "direction_deg": 30, "mu": 0.2}
    current |= {"sigma": 0.05, "direction_sigma_deg": 5.0}
    env = ShipPathFollowEnv(scenario_from_dict(nomoto_scenario({"current": current})))
    env.reset(seed=1)
    h, u0 = env.scenario.fine_step, env.model.nominal_speed
    x_prev, y_prev = 0.0, 0.0
    for _ in range(20):
        _, _, _, _, info = env.step(np.zeros(1))
        block = env._w_block
        x, y = info["position"]
        assert np.ptp(block[:, IX]) > 0  # the current really varies within a period
        assert x - x_prev - u0 * 0.5 == pytest.approx(h * block[:, IX].sum(), abs=1e-12)
        assert y - y_prev == pytest.approx(h * block[:, IY].sum(), abs=1e-12)
        x_prev, y_prev = x, y


def test_current_shift_expressed_as_a_real_current() -> None:
    """Liu et al. (2019) Case 2 (d0 −1.237 → −4 °/s at 12 s) as a current appearing at 12 s
    with ``yaw_bias_per_speed`` = Δd0/V: the same heading response, plus the drift V·(t − 12)."""
    case2 = load_scenario("current_shift")
    data = case2.config.model_dump()
    data["events"] = []
    v2 = 0.2
    data["disturbances"] = {
        "current": {
            "kind": "two_phase",
            "speed": 0.0,
            "second_speed": v2,
            "direction_deg": 90.0,
            "sigma": 0.0,
            "switch_time": 12.0,
            "yaw_bias_per_speed": (-4.0 + 1.2370) * DEG / v2,
        }
    }
    as_current = ShipPathFollowEnv(scenario_from_dict(data))
    as_event = ShipPathFollowEnv(case2)
    as_current.reset(seed=0)
    as_event.reset(seed=0)
    for k in range(1, 61):
        action = np.array([0.3 * math.sin(0.2 * k)])
        info_c, info_e = as_current.step(action)[4], as_event.step(action)[4]
        assert info_c["heading"] == pytest.approx(info_e["heading"], abs=1e-9)
        assert info_c["yaw_rate"] == pytest.approx(info_e["yaw_rate"], abs=1e-9)
        drift = v2 * max(0.0, k * 0.5 - 12.0)
        assert info_c["position"][0] == pytest.approx(info_e["position"][0], abs=1e-9)
        assert info_c["position"][1] - info_e["position"][1] == pytest.approx(drift, abs=1e-9)


# ------------------------------------------------------------------ (b) Gauss–Markov current


def autocorrelation(x: np.ndarray, lag: int) -> float:
    """Pooled lag autocorrelation of the rows of x about their common mean."""
    d = x - x.mean()
    return float(np.mean(d[:, lag:] * d[:, :-lag]) / np.mean(d * d))


@pytest.mark.parametrize("h", [0.1, 2.0])
def test_gauss_markov_current_has_exact_mean_variance_and_correlation(h: float) -> None:
    """μ = 0.5 1/s, σ = 0.2 → std σ/√(2μ) = 0.2 m/s, correlation exp(−μτ), at a fine step
    and at h = 2/μ (where Euler would give variance σ²h = 0.08, twice the true 0.04).
    Sample: 20 ships × 2000 s, μT = 2·10⁴ ⇒ standard errors ≈ 0.2·√(2/μT) = 0.002 m/s on
    the mean, √(2/μT) = 1 % on the variance, ≈ 1 % on the correlation; tolerances 5×."""
    mu, sigma, mean = 0.5, 0.2, 1.0
    current = {"kind": "gauss_markov", "speed": mean, "mu": mu, "sigma": sigma}
    n_sub = round(100 / h)
    v = speed_of(sample({"current": current}, h, n_sub, periods=20, batch=20))
    assert v.min() > 0  # 5σ above the bound: saturation never acts here
    assert v.mean() == pytest.approx(mean, abs=0.01)
    assert v.var() == pytest.approx(sigma**2 / (2 * mu), rel=0.05)
    for tau in (h, 2.0, 4.0):
        lag = round(tau / h)
        assert autocorrelation(v, lag) == pytest.approx(math.exp(-mu * lag * h), abs=0.05)


def test_gauss_markov_discretisation_is_the_exact_ar1() -> None:
    a, s = gauss_markov_coefficients(0.5, 0.2, 2.0)
    assert a == pytest.approx(math.exp(-1.0), rel=1e-15)
    assert s**2 / (1 - a * a) == pytest.approx(0.2**2 / (2 * 0.5), rel=1e-14)  # stationary


def test_saturated_recursion_equals_the_clipped_reference_loop() -> None:
    """ar1_saturated (lfilter + scalar restarts) equals x = clip(a·x + e) sample by sample,
    bit for bit, in a batch and row by row, with constant and time-varying bounds."""
    rng = np.random.default_rng(3)
    a, e = 0.95, 0.3 * rng.standard_normal((6, 300))
    x_prev = rng.uniform(-0.1, 0.1, 6)
    lo = -0.2 - 0.1 * np.sin(np.arange(300) / 20.0)  # varies along time (two-phase mean)
    hi = 0.25
    reference = np.empty_like(e)
    for i in range(6):
        x = x_prev[i]
        for k in range(300):
            x = min(max(a * x + e[i, k], lo[k]), hi)
            reference[i, k] = x
    got = ar1_saturated(x_prev, a, e, lo, hi)
    np.testing.assert_array_equal(got, reference)
    assert np.mean((got == hi) | (got == lo)) > 0.1  # the bounds are active
    for i in range(6):
        np.testing.assert_array_equal(
            ar1_saturated(x_prev[i : i + 1], a, e[i : i + 1], lo, hi)[0], got[i]
        )
    unbounded = ar1_saturated(x_prev, a, e)
    np.testing.assert_allclose(unbounded[:, 0], a * x_prev + e[:, 0], rtol=0, atol=0)


def test_saturation_bounds_speed_and_direction() -> None:
    """The state is clipped at every sample: V_min ≤ V ≤ V_max, |β − β̄| ≤ d_max, and both
    speed bounds are reached (std 0.2 m/s against a ±0.05 m/s band)."""
    current = {
        "kind": "gauss_markov",
        "speed": 0.5,
        "direction_deg": 45.0,
        "mu": 0.5,
        "sigma": 0.2,
        "min_speed": 0.45,
        "max_speed": 0.55,
        "direction_sigma_deg": 20.0,
        "direction_max_deviation_deg": 10.0,
    }
    s = sample({"current": current}, 0.1, 500, periods=4, batch=5)
    v = speed_of(s)
    assert v.min() >= 0.45 - 1e-15 and v.max() <= 0.55 + 1e-15
    assert np.mean(np.isclose(v, 0.45)) > 0.05 and np.mean(np.isclose(v, 0.55)) > 0.05
    beta = np.arctan2(s[..., IY], s[..., IX]) / DEG
    assert beta.min() >= 35.0 - 1e-9 and beta.max() <= 55.0 + 1e-9
    assert beta.max() - beta.min() > 19.0  # it does move between the bounds


# ------------------------------------------------------------------ (c) wave filter

ITTC = {"spectrum": "ittc", "significant_height": 2.0, "modal_period": 8.0, "gain": 1.0}


def test_modal_frequencies_of_the_spectra() -> None:
    """ω₀ = (4B/5)^¼ is the peak of S; PM: ω₀ = 0.877 g/V; ITTC: ω₀ ≈ 2π/T₀."""
    pm = WaveConfig(spectrum="pierson_moskowitz", wind_speed=10.0, gain=1.0)
    for config in (pm, WaveConfig(**ITTC)):
        wf = WaveFilter.from_config(config)
        a, b = spectrum_coefficients(config)
        grid = np.linspace(0.5 * wf.omega0, 2.0 * wf.omega0, 200001)
        assert grid[np.argmax(wave_spectrum(grid, a, b))] == pytest.approx(wf.omega0, rel=1e-4)
        assert wf.sigma_w**2 == pytest.approx(wave_spectrum(grid, a, b).max(), rel=1e-9)
        assert wf.psd(wf.omega0) == pytest.approx(wf.sigma_w**2, rel=1e-12)  # Fossen's fit
    assert WaveFilter.from_config(pm).omega0 == pytest.approx(0.8772 * 9.81 / 10.0, rel=1e-4)
    # λ = 0.8e^{5/4}/(4π) makes the filter's variance the sea's m₀ = ∫S dω = A/(4B)
    matched = WaveConfig(**{**ITTC, "damping": 0.8 * math.exp(1.25) / (4 * math.pi)})
    a, b = spectrum_coefficients(matched)
    assert WaveFilter.from_config(matched).stationary_variance() == pytest.approx(
        a / (4 * b), rel=1e-12
    )
    assert a / (4 * b) == pytest.approx(ITTC["significant_height"] ** 2 / 16, rel=0.01)
    assert WaveFilter.from_config(WaveConfig(**ITTC)).omega0 * 8.0 == pytest.approx(
        2 * math.pi, rel=1e-3
    )


@pytest.mark.parametrize("h", [0.01, 0.25, 2.0])
def test_discrete_wave_filter_variance_equals_the_continuous_one(h: float) -> None:
    """Van Loan (Φ, Q_d) and the ARMA(2,1) form keep the continuous stationary variance
    πλω₀σ_w² at any step (continuous Lyapunov vs discrete Lyapunov vs Σ impulse²)."""
    wf = WaveFilter.from_config(WaveConfig(**ITTC))
    a_c, b_c, c = wf.state_space()
    continuous = solve_continuous_lyapunov(a_c, -math.pi * b_c @ b_c.T)
    phi, qd = wf.discretise(h)
    discrete = solve_discrete_lyapunov(phi, qd)
    np.testing.assert_allclose(discrete, continuous, rtol=1e-9, atol=1e-15)
    b, a, _ = wf.arma(h)
    impulse = lfilter(b, a, np.r_[1.0, np.zeros(400_000)])
    closed_form = math.pi * wf.damping * wf.omega0 * wf.sigma_w**2
    assert (c @ continuous @ c.T).item() == pytest.approx(closed_form, rel=1e-12)
    assert float(np.sum(impulse**2)) == pytest.approx(closed_form, rel=1e-9)


def test_wave_disturbance_spectrum_peaks_at_the_modal_frequency() -> None:
    """Welch PSD of 10 ships × 2.5·10⁴ s at h = 0.25 s (resolution Δω = 0.0123 rad/s):
    the peak lies within 2Δω (3 %) of ω₀ and its height is S(ω₀) within 20 % (≈ 80
    averaged segments per ship, 800 in all: a few % of noise, plus window smoothing of a
    peak of half-power width 2λω₀ = 0.16 rad/s); the sample variance is πλω₀σ_w² within 5 %
    (≈ 3·10³ correlation times 1/(λω₀) in all)."""
    h = 0.25
    wf = WaveFilter.from_config(WaveConfig(**ITTC))
    y = sample({"waves": ITTC}, h, 1000, periods=100, batch=10)[..., IYAW]
    f, p = welch(y, fs=1.0 / h, nperseg=2048, axis=-1)
    omega, psd = 2 * math.pi * f, p.mean(axis=0) / (2 * math.pi)  # one-sided, per rad/s
    d_omega = omega[1] - omega[0]
    peak = int(np.argmax(psd))
    assert abs(omega[peak] - wf.omega0) <= 2 * d_omega
    assert psd[peak] == pytest.approx(wf.sigma_w**2, rel=0.2)
    assert y.var() == pytest.approx(wf.stationary_variance(), rel=0.05)
    assert abs(y.mean()) < 0.05 * y.std()


def test_wave_gain_scales_the_yaw_column_only() -> None:
    base = sample({"waves": ITTC}, 0.25, 100, periods=3, seed=4)
    scaled = sample({"waves": {**ITTC, "gain": -0.5}}, 0.25, 100, periods=3, seed=4)
    np.testing.assert_array_equal(scaled[..., IYAW], -0.5 * base[..., IYAW])
    assert not np.any(scaled[..., :IYAW])  # calm current


# ------------------------------------------------------------------ (d) two-phase current


def test_two_phase_current_follows_the_papers_phases() -> None:
    """Xu et al. (2021) §5.2: direction 180°, mean 0.1 m/s then 0.2 m/s (switch at 200 s).
    200 ships × 200 s per phase with the default fluctuation (std 0.02 m/s, 1/μ = 50 s):
    standard error of a phase mean ≈ 0.02·√(2/(μT))/√200 = 0.0014 m/s; tolerance 0.007."""
    current = {"kind": "two_phase", "switch_time": 200.0}
    s = sample({"current": current}, 0.5, 100, periods=8, batch=200)
    t = 0.5 * np.arange(s.shape[1])
    np.testing.assert_allclose(s[..., IY], 0.0, atol=1e-15)  # flows to 180°: −x
    assert np.all(s[..., IX] <= 0)
    v = speed_of(s)
    assert v[:, t < 200].mean() == pytest.approx(0.1, abs=0.007)
    assert v[:, t >= 200].mean() == pytest.approx(0.2, abs=0.007)
    assert 0.01 < v[:, t < 200].std() < 0.03  # it fluctuates ("oscillates around 0.1")


def test_two_phase_defaults_switch_time_and_ramp() -> None:
    """Deterministic (σ = 0): switch at half the time limit by default; a ramp is linear."""
    step = Disturbances(
        DisturbanceConfig.model_validate({"current": {"kind": "two_phase", "sigma": 0.0}}),
        NAMES,
        1.0,
        100,
        time_limit=100.0,
    )
    assert step.n_noise == 0 and step.time_varying
    block = np.zeros((1, 100, 3))
    step.fill(block, np.zeros(1), None, np.zeros(1, dtype=np.intp))
    np.testing.assert_array_equal(-block[0, :50, IX], 0.1)
    np.testing.assert_array_equal(-block[0, 50:, IX], 0.2)
    ramp = {"kind": "two_phase", "sigma": 0.0, "switch_time": 10.0, "transition_time": 20.0}
    v = -sample({"current": ramp}, 1.0, 40, periods=1)[0, :, IX]
    np.testing.assert_allclose(v[[0, 10, 20, 30, 39]], [0.1, 0.1, 0.15, 0.2, 0.2], atol=1e-15)


@pytest.mark.parametrize("ramp", [0.0, 20.0])
def test_a_settled_block_is_the_same_every_period(ramp: float) -> None:
    """``steady_from``: a deterministic two-phase current fills the same block (bit for bit)
    at every period start from it on, as the batched envs assume when they skip refilling;
    a block across the switch differs.  Noise or waves never settle."""
    current = {"kind": "two_phase", "sigma": 0.0, "switch_time": 10.0, "transition_time": ramp}
    h, n_sub = 0.25, 8  # Ts = 2 s
    dist = Disturbances(DisturbanceConfig.model_validate({"current": current}), NAMES, h, n_sub)
    start = dist.steady_from
    assert start == (10.0 - 1e-9 if ramp == 0 else 10.0 + 2 * ramp)
    blocks = []
    first = math.ceil(start / 2.0) * 2.0
    for t0 in [8.0, first, first + 2.0, first + 50.0]:  # the first one: across the switch
        block = np.zeros((1, n_sub, 3))
        dist.fill(block, np.array([t0]), None, np.zeros(1, dtype=np.intp))
        blocks.append(block.tobytes())
    assert blocks[0] != blocks[1] and blocks[1] == blocks[2] == blocks[3]
    noisy = Disturbances(DisturbanceConfig.model_validate(STOCHASTIC), NAMES, h, n_sub)
    assert noisy.steady_from == math.inf


# ------------------------------------------------------------------ (e) reproducibility


STOCHASTIC = {
    "current": {
        "kind": "gauss_markov",
        "speed": 0.1,
        "direction_deg": 90.0,
        "mu": 0.1,
        "sigma": 0.03,
        "max_speed": 0.2,
        "direction_sigma_deg": 2.0,
    },
    "waves": {"wind_speed": 1.0, "gain": 1.0},
}


def disturbance_sequence(env: ShipPathFollowEnv, seed: int, steps: int = 15) -> np.ndarray:
    env.reset(seed=seed)
    blocks = []
    for _ in range(steps):
        env.step(np.array([0.1]))
        blocks.append(env._w_block.copy())
    return np.array(blocks)


def test_same_seed_gives_the_same_disturbance_sequence() -> None:
    scenario = scenario_from_dict(nomoto_scenario(STOCHASTIC))
    env, twin = ShipPathFollowEnv(scenario), ShipPathFollowEnv(scenario)
    first = disturbance_sequence(env, 7)
    np.testing.assert_array_equal(first, disturbance_sequence(twin, 7))
    np.testing.assert_array_equal(first, disturbance_sequence(env, 7))  # reset restarts it
    other = disturbance_sequence(env, 8)
    assert not np.any(first == other)  # every sample of every column differs


def test_constant_current_draws_nothing() -> None:
    dist = Disturbances(DisturbanceConfig(), NAMES, 0.01, 50)
    rng = np.random.default_rng(0)
    state = copy.deepcopy(rng.bit_generator.state)
    dist.reset(0, rng)
    assert not dist.time_varying and dist.draw(rng) is None
    assert rng.bit_generator.state == state


def test_catalogue_loads_unchanged_with_a_constant_current() -> None:
    for name in list_scenarios():
        scenario = load_scenario(name)
        if scenario.model.name != "nomoto2":  # the other ships' scenarios choose theirs
            continue
        assert isinstance(scenario.config.disturbances.current, ConstantCurrent)
    data = nomoto_scenario({"current": {"speed": 0.2, "direction_deg": 10.0}})
    assert scenario_from_dict(data).config.disturbances.current.kind == "constant"


# ------------------------------------------------------------------ (f) bad configs


@pytest.mark.parametrize(
    ("disturbances", "key"),
    [
        ({"current": {"kind": "gauss_markov", "speed": 0.1, "mu": -0.1}}, "mu"),
        ({"current": {"kind": "gauss_markov", "speed": 0.1, "sigma": -1}}, "sigma"),
        (
            {"current": {"kind": "gauss_markov", "speed": 0.1, "min_speed": 0.3, "max_speed": 0.2}},
            "min_speed",
        ),
        ({"current": {"kind": "gauss_markov", "speed": 0.5, "max_speed": 0.2}}, "max_speed"),
        ({"current": {"kind": "gauss_markov"}}, "speed"),
        ({"current": {"kind": "swirl", "speed": 0.1}}, "kind"),
        ({"current": {"speed": 0.1, "mu": 0.1}}, "mu"),  # constant: no Gauss–Markov keys
        ({"current": {"kind": "two_phase", "switch_time": -1}}, "switch_time"),
        ({"waves": {"wind_speed": 5.0}}, "gain"),
        ({"waves": {"spectrum": "ittc", "significant_height": 1.0, "gain": 1}}, "modal_period"),
        ({"waves": {"wind_speed": 5.0, "modal_period": 3.0, "gain": 1}}, "modal_period"),
        ({"waves": {"wind_speed": 5.0, "gain": 1, "damping": 1.5}}, "damping"),
        ({"waves": {"wind_speed": 5.0, "gain": 1, "height": 1.0}}, "height"),
    ],
)
def test_bad_disturbance_config_names_the_key(disturbances: dict, key: str) -> None:
    with pytest.raises(ScenarioError, match=key):
        scenario_from_dict(nomoto_scenario(disturbances))
