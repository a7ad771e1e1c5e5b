"""Tests for the nomoto2 ship model, its two backends and the period integrator.

The reference dynamics are Liu et al. (2019) eq. (3)–(4), written out again here (with
Kc = 1, as in the paper) so that the model's own right-hand side is never used as its own
reference.
"""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from shipgym.models import MODELS
from shipgym.models.base import ParameterError
from shipgym.models.integrator import PeriodIntegrator
from shipgym.models.nomoto2 import (
    Nomoto2,
    Nomoto2Params,
    UnitReading,
    paper_to_si,
    params_from_paper,
    si_to_paper,
)
from tests.shipgym.models.batching import assert_columns_are_ships

DEG = math.pi / 180.0
H = 0.01  # fine step [s] (Liu et al. 2019 §4)
N_SUB = 50  # substeps per control period Ts = 0.5 s

#: The paper's parameters in the paper's units (d0 in °/s), Liu et al. (2019) §4.
PAPER = {
    "K": 0.5060,
    "T1": 1.2481,
    "T2": 0.1245,
    "T3": -0.0757,
    "d0": -1.2370,
    "beta": 0.0081,
    "Tc": 0.1,
}
#: Case 3 parameters after the change (Liu et al. 2019 §4.3), paper units.
PAPER_CASE3_AFTER = {
    "K": 6.0,
    "T1": 3.0,
    "T2": 1.0,
    "T3": -0.6,
    "d0": -4.0,
    "beta": 0.002,
    "Tc": 0.5,
}
# ±20° (and a few smaller) rudder steps every 2.5 s for 20 s
COMMANDS_DEG = [20.0, -20.0, 20.0, -20.0, 10.0, -5.0, 20.0, -20.0]
SEGMENT = 2.5  # s


def liu_rhs(t: float, s: np.ndarray, dc: float, p: dict[str, float]) -> list[float]:
    """Liu et al. (2019) eq. (3)–(4) with Kc = 1 and ẋ = u0 cos ψ, ẏ = u0 sin ψ (SI, rad)."""
    _x, _y, psi, r, r_dot, delta = s
    K, T1, T2, T3, d0, beta, Tc, u0 = (
        p["K"],
        p["T1"],
        p["T2"],
        p["T3"],
        p["d0"],
        p["beta"],
        p["Tc"],
        p["u0"],
    )
    g = (K * delta + (K * T3 / Tc) * (dc - delta) + d0 - (T1 + T2) * r_dot - r - beta * r**3) / (
        T1 * T2
    )
    return [u0 * math.cos(psi), u0 * math.sin(psi), r, r_dot, g, (dc - delta) / Tc]


def reference_solution(p: dict[str, float], s0: np.ndarray, times: np.ndarray) -> np.ndarray:
    """Piecewise solve_ivp (restarted at every command change); states at ``times``."""
    out = np.empty((len(times), 6))
    s = np.array(s0, dtype=float)
    for k, dc_deg in enumerate(COMMANDS_DEG):
        t0, t1 = k * SEGMENT, (k + 1) * SEGMENT
        if t0 >= times[-1] - 1e-12:
            break
        mask = (times > t0 + 1e-12) & (times <= t1 + 1e-12)
        sol = solve_ivp(
            liu_rhs,
            (t0, t1),
            s,
            method="DOP853",
            rtol=1e-10,
            atol=1e-12,
            t_eval=np.clip(times[mask], t0, t1),
            args=(dc_deg * DEG, p),
        )
        assert sol.success
        assert sol.t[-1] == pytest.approx(t1, abs=1e-12)  # every segment ends on a sample
        out[mask] = sol.y.T
        s = sol.y[:, -1]
    return out


def si_dict(params: Nomoto2Params) -> dict[str, float]:
    return params.as_dict()


PARAM_SETS = {
    "paper_si": params_from_paper("si", **PAPER),
    "case3_after_si": params_from_paper("si", **PAPER_CASE3_AFTER),
}


# --------------------------------------------------------------------------------------------
# Against an independent integration of Liu et al. (2019) eq. (3)–(4)
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("which", sorted(PARAM_SETS))
def test_step_numpy_matches_solve_ivp_reference(which: str) -> None:
    params = PARAM_SETS[which]
    model = Nomoto2(params)
    p_vec = params.to_vector()
    s0 = np.array([0.0, 0.0, 0.3, 0.0, 0.0, 0.0])
    n_steps = round(20.0 / H)
    times = H * np.arange(1, n_steps + 1)
    ref = reference_solution(si_dict(params), s0, times)
    x = s0.copy()
    states = np.empty((n_steps, 6))
    w = np.zeros(3)
    steps_per_segment = round(SEGMENT / H)
    for i in range(n_steps):
        dc = COMMANDS_DEG[i // steps_per_segment] * DEG
        x = model.step_numpy(x, np.array([dc]), w, p_vec, H)
        states[i] = x
    heading_err = np.max(np.abs(states[:, 2] - ref[:, 2]))
    assert heading_err < 1e-4
    # the rest of the state too (positions in m, rates in rad/s, rudder in rad)
    np.testing.assert_allclose(states, ref, atol=1e-4, rtol=0)
    # and the motion is not trivial: the heading really swings by tens of degrees
    assert np.ptp(ref[:, 2]) > 10 * DEG


@pytest.mark.parametrize("which", sorted(PARAM_SETS))
def test_period_integrator_matches_solve_ivp_reference(which: str) -> None:
    params = PARAM_SETS[which]
    model = Nomoto2(params)
    integ = PeriodIntegrator(model, H, N_SUB)
    s0 = np.array([1.0, -2.0, -0.2, 0.01, 0.0, 5 * DEG])
    n_periods = round(20.0 / (H * N_SUB))
    times = H * np.arange(1, n_periods * N_SUB + 1)
    ref = reference_solution(si_dict(params), s0, times)
    w_block = np.zeros((N_SUB, 3))
    p_block = np.tile(params.to_vector(), (N_SUB, 1))
    periods_per_segment = round(SEGMENT / (H * N_SUB))
    x = s0.copy()
    out = []
    for k in range(n_periods):
        dc = COMMANDS_DEG[k // periods_per_segment] * DEG
        full = integ(x, dc, w_block, p_block)
        assert full.shape == (N_SUB + 1, 6)
        np.testing.assert_array_equal(full[0], x)  # row 0 is the initial state
        block = full[1:]
        out.append(block)
        x = block[-1]
    states = np.concatenate(out)
    assert np.max(np.abs(states[:, 2] - ref[:, 2])) < 1e-4
    np.testing.assert_allclose(states, ref, atol=1e-4, rtol=0)


def test_reference_would_catch_a_wrong_t3_sign() -> None:
    """The 1e-4 tolerance is meaningful: flipping T3 in the model is detected."""
    params = PARAM_SETS["paper_si"]
    wrong = params.replace(T3=-params.T3)
    model = Nomoto2(wrong)
    s0 = np.zeros(6)
    times = H * np.arange(1, 501)
    ref = reference_solution(si_dict(params), s0, times)
    x = s0.copy()
    for i in range(500):
        x = model.step_numpy(
            x, np.array([COMMANDS_DEG[i // 250] * DEG]), np.zeros(3), wrong.to_vector(), H
        )
    assert abs(x[2] - ref[-1, 2]) > 1e-4


# --------------------------------------------------------------------------------------------
# One rhs, two backends; batched numpy
# --------------------------------------------------------------------------------------------


def random_params(rng: np.random.Generator) -> np.ndarray:
    return np.array(
        [
            rng.uniform(0.1, 10.0),  # K
            rng.uniform(0.5, 3.0),  # T1
            rng.uniform(0.02, 1.0),  # T2
            rng.uniform(-1.0, 1.0),  # T3
            rng.uniform(-0.1, 0.1),  # d0
            rng.uniform(0.0, 0.05),  # beta
            rng.uniform(0.05, 1.0),  # Tc
            rng.uniform(0.5, 1.5),  # Kc
            rng.uniform(0.1, 10.0),  # u0
            rng.uniform(0.5, 200.0),  # L
        ]
    )


def test_parameter_vector_order_matches_random_params() -> None:
    assert Nomoto2Params.names() == ("K", "T1", "T2", "T3", "d0", "beta", "Tc", "Kc", "u0", "L")


def test_casadi_rhs_equals_numpy_rhs_at_random_points() -> None:
    model = Nomoto2()
    rng = np.random.default_rng(1)
    for _ in range(50):
        x = rng.normal(size=6) * np.array([10, 10, 3, 0.5, 0.5, 0.5])
        u = rng.uniform(-0.6, 0.6, size=1)
        w = rng.normal(size=3) * 0.1
        p = random_params(rng)
        expected = model.f_numpy(x, u, w, p)
        got = np.asarray(model.casadi_rhs(x, u, w, p)).ravel()
        assert got.shape == (6,)
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12)


def test_casadi_step_equals_numpy_step() -> None:
    model = Nomoto2()
    step = model.casadi_step(H)
    rng = np.random.default_rng(2)
    for _ in range(20):
        x = rng.normal(size=6)
        u = rng.uniform(-0.5, 0.5, size=1)
        w = rng.normal(size=3) * 0.1
        p = random_params(rng)
        np.testing.assert_allclose(
            np.asarray(step(x, u, w, p)).ravel(),
            model.step_numpy(x, u, w, p, H),
            rtol=1e-12,
            atol=1e-12,
        )


def test_batched_numpy_equals_per_ship() -> None:
    model = Nomoto2()
    rng = np.random.default_rng(3)
    n = 7
    x = rng.normal(size=(6, n))
    u = rng.uniform(-0.5, 0.5, size=(1, n))
    w = rng.normal(size=(3, n)) * 0.1
    p = np.stack([random_params(rng) for _ in range(n)], axis=1)
    assert p.shape == (model.n_params, n)
    assert_columns_are_ships(model, x, u, w, p, H)
    f_batch = model.f_numpy(x, u, w, p)
    # the columns really are different ships
    assert len({round(v, 12) for v in f_batch[4]}) == n


# --------------------------------------------------------------------------------------------
# PeriodIntegrator against step_numpy
# --------------------------------------------------------------------------------------------


def repeated_steps(model: Nomoto2, x0, dc, w_block, p_block) -> np.ndarray:
    x = np.array(x0, dtype=float)
    out = []
    for i in range(p_block.shape[0]):
        x = model.step_numpy(x, np.array([dc]), w_block[i], p_block[i], H)
        out.append(x)
    return np.array(out)


def test_period_integrator_equals_repeated_step_numpy() -> None:
    model = Nomoto2()
    integ = PeriodIntegrator(model, H, N_SUB)
    rng = np.random.default_rng(4)
    for _ in range(5):
        x0 = rng.normal(size=6) * np.array([5, 5, 1, 0.1, 0.1, 0.3])
        dc = float(rng.uniform(-0.5, 0.5))
        w_block = rng.normal(size=(N_SUB, 3)) * 0.05
        p_block = np.tile(random_params(rng), (N_SUB, 1))
        got = integ(x0, dc, w_block, p_block)[1:]
        np.testing.assert_allclose(
            got, repeated_steps(model, x0, dc, w_block, p_block), rtol=1e-12, atol=1e-12
        )


@pytest.mark.parametrize("k", [1, 17, 49])
@pytest.mark.parametrize("name", ["K", "Tc", "d0"])
def test_period_integrator_respects_per_substep_parameter_rows(k: int, name: str) -> None:
    model = Nomoto2()
    integ = PeriodIntegrator(model, H, N_SUB)
    x0 = np.array([0.0, 0.0, 0.1, 0.02, 0.0, 3 * DEG])
    dc = 15 * DEG
    w_block = np.zeros((N_SUB, 3))
    base = Nomoto2Params()
    p_block = np.tile(base.to_vector(), (N_SUB, 1))
    changed = p_block.copy()
    j = Nomoto2Params.names().index(name)
    changed[k:, j] = {"K": 3.0, "Tc": 1.0, "d0": -4.0 * DEG}[name]
    a = integ(x0, dc, w_block, p_block)[1:]
    b = integ(x0, dc, w_block, changed)[1:]
    # identical before substep k, different at substep k (state at its end) and after
    np.testing.assert_array_equal(a[:k], b[:k])
    assert np.any(a[k] != b[k])
    assert all(np.any(a[i] != b[i]) for i in range(k, N_SUB))
    # and the per-row result is the right one, not merely different
    np.testing.assert_allclose(
        b, repeated_steps(model, x0, dc, w_block, changed), rtol=1e-12, atol=1e-12
    )


def test_period_integrator_rejects_bad_arguments() -> None:
    with pytest.raises(ValueError, match="h > 0"):
        PeriodIntegrator(Nomoto2(), 0.0, 10)
    with pytest.raises(ValueError, match="n_sub"):
        PeriodIntegrator(Nomoto2(), 0.01, 0)


def test_period_integrator_output_is_a_fresh_copy() -> None:
    model = Nomoto2()
    integ = PeriodIntegrator(model, H, N_SUB)
    p_block = np.tile(model.params.to_vector(), (N_SUB, 1))
    a = integ(np.zeros(6), 0.1, np.zeros((N_SUB, 3)), p_block)
    a_copy = a.copy()
    integ(np.ones(6), -0.3, np.zeros((N_SUB, 3)), p_block)
    np.testing.assert_array_equal(a, a_copy)


# --------------------------------------------------------------------------------------------
# Steady turning: r + β r³ = K δ + d0
# --------------------------------------------------------------------------------------------


def real_root(coefficients: list[float]) -> float:
    roots = np.roots(coefficients)
    real = roots[np.abs(roots.imag) < 1e-9].real
    assert len(real) == 1  # β ≥ 0: a monotone cubic
    return float(real[0])


def simulate_steady_rates(params: Nomoto2Params, rudders: np.ndarray, seconds: float) -> np.ndarray:
    """Batched simulation of constant rudder commands; final yaw rates [rad/s]."""
    model = Nomoto2(params)
    n = len(rudders)
    x = np.zeros((6, n))
    u = rudders.reshape(1, n)
    w = np.zeros((3, n))
    p = np.tile(params.to_vector()[:, None], (1, n))
    for _ in range(round(seconds / H)):
        x = model.step_numpy(x, u, w, p, H)
    return x[3]


RUDDERS_DEG = np.array([-20.0, -5.0, 3.0, 20.0])


@pytest.mark.parametrize("reading", [r.value for r in UnitReading])
def test_steady_turning_rate_solves_the_cubic(reading: str) -> None:
    params = params_from_paper(reading, **PAPER)
    rudders = RUDDERS_DEG * DEG
    rates = simulate_steady_rates(params, rudders, 60.0)
    for delta, r in zip(rudders, rates, strict=True):
        # SI form of the steady state (ṙ = r̈ = 0, δ = Kc δc, Kc = 1)
        expected = real_root([params.beta, 0.0, 1.0, -(params.K * delta + params.d0)])
        assert r == pytest.approx(expected, abs=1e-6)
        # the same number from the paper's equation read in the paper's units
        if reading == "si":  # d0 in °/s → rad/s, all else SI
            paper_r = real_root(
                [PAPER["beta"], 0.0, 1.0, -(PAPER["K"] * delta + PAPER["d0"] * DEG)]
            )
            assert r == pytest.approx(paper_r, abs=1e-6)
        elif reading == "degrees":  # whole equation in degrees
            r_deg = real_root([PAPER["beta"], 0.0, 1.0, -(PAPER["K"] * delta / DEG + PAPER["d0"])])
            assert r == pytest.approx(r_deg * DEG, abs=1e-6)
        else:  # rudder_degrees: heading/yaw rate in rad, rudder in degrees, d0 in °/s
            paper_r = real_root(
                [PAPER["beta"], 0.0, 1.0, -(PAPER["K"] * delta / DEG + PAPER["d0"] * DEG)]
            )
            assert r == pytest.approx(paper_r, abs=1e-6)
    # the sign follows the rudder (d0 is small against these rudder angles)
    assert np.all(np.sign(rates) == np.sign(rudders))


# --------------------------------------------------------------------------------------------
# Unit readings
# --------------------------------------------------------------------------------------------


def test_params_from_paper_si_reading() -> None:
    p = params_from_paper("si", **PAPER)
    assert p.d0 == pytest.approx(-1.2370 * math.pi / 180.0, rel=1e-15)
    assert p.K == PAPER["K"] and p.beta == PAPER["beta"]
    assert (p.T1, p.T2, p.T3, p.Tc) == (PAPER["T1"], PAPER["T2"], PAPER["T3"], PAPER["Tc"])
    # the model's defaults are the paper's ship read in SI
    assert p == Nomoto2Params()


def test_params_from_paper_degrees_reading() -> None:
    p = params_from_paper(UnitReading.DEGREES, **PAPER)
    assert p.beta == pytest.approx(0.0081 * (180.0 / math.pi) ** 2, rel=1e-14)
    assert p.d0 == pytest.approx(-1.2370 * math.pi / 180.0, rel=1e-15)
    assert p.K == PAPER["K"]
    assert p.T1 == PAPER["T1"]


def test_params_from_paper_rudder_degrees_reading() -> None:
    p = params_from_paper("rudder_degrees", **PAPER)
    assert p.K == pytest.approx(0.5060 * 180.0 / math.pi, rel=1e-14)
    assert p.d0 == pytest.approx(-1.2370 * math.pi / 180.0, rel=1e-15)
    assert p.beta == PAPER["beta"]
    assert p.T2 == PAPER["T2"]


def test_params_from_paper_keeps_base_values() -> None:
    base = Nomoto2Params(u0=1.5, L=2.0)
    p = params_from_paper("degrees", base=base, K=0.7)
    assert (p.K, p.u0, p.L, p.T1) == (0.7, 1.5, 2.0, base.T1)


@pytest.mark.parametrize("reading", [r.value for r in UnitReading])
def test_si_to_paper_round_trip(reading: str) -> None:
    si = paper_to_si(PAPER, reading)
    back = si_to_paper(si, reading)
    assert set(back) == set(PAPER)
    for key, value in PAPER.items():
        assert back[key] == pytest.approx(value, rel=1e-14)
    # and from the record side
    record = params_from_paper(reading, **PAPER)
    from_record = si_to_paper(record.as_dict(), reading)
    for key, value in PAPER.items():
        assert from_record[key] == pytest.approx(value, rel=1e-14)


def test_unknown_unit_reading_is_rejected() -> None:
    with pytest.raises(ValueError, match="furlongs"):
        params_from_paper("furlongs", K=1.0)
    with pytest.raises(ParameterError, match="furlongs") as info:
        Nomoto2.from_config({"K": 1.0}, "furlongs")
    for valid in ("si", "degrees", "rudder_degrees"):
        assert valid in str(info.value)


# --------------------------------------------------------------------------------------------
# Parameter validation
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["T1", "T2", "Tc", "u0", "L"])
@pytest.mark.parametrize("bad", [0.0, -1.0, -1e-12])
def test_non_positive_parameters_raise_naming_the_field(name: str, bad: float) -> None:
    with pytest.raises(ParameterError, match=rf"\.{name}\b"):
        Nomoto2Params(**{name: bad})
    with pytest.raises(ParameterError, match=rf"\.{name}\b"):
        Nomoto2Params().replace(**{name: bad})


@pytest.mark.parametrize("name", Nomoto2Params.names())
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_parameters_raise_naming_the_field(name: str, bad: float) -> None:
    with pytest.raises(ParameterError, match=rf"\.{name}\b"):
        Nomoto2Params(**{name: bad})


def test_parameter_error_is_a_value_error() -> None:
    assert issubclass(ParameterError, ValueError)


def test_negative_t3_and_d0_are_physical() -> None:
    p = Nomoto2Params(T3=-0.6, d0=-0.07, beta=0.0)
    assert (p.T3, p.d0, p.beta) == (-0.6, -0.07, 0.0)


def test_replace_with_unknown_name_raises_naming_it() -> None:
    with pytest.raises(ParameterError, match="Tcc"):
        Nomoto2Params().replace(Tcc=0.5)


def test_from_config_with_unknown_parameter_raises_naming_it() -> None:
    with pytest.raises(ParameterError, match="gamma"):
        Nomoto2.from_config({"gamma": 1.0})


def test_models_registry_and_declared_figures() -> None:
    assert MODELS["nomoto2"] is Nomoto2
    m = Nomoto2()
    assert m.state_names == ("x", "y", "psi", "r", "r_dot", "delta")
    assert m.length == 0.95 and m.nominal_speed == 0.80
    assert m.rudder_limit == pytest.approx(30 * DEG)
    assert (m.control_period, m.fine_step) == (0.5, 0.01)


# --------------------------------------------------------------------------------------------
# Pickling
# --------------------------------------------------------------------------------------------


def test_model_pickle_round_trip() -> None:
    model = Nomoto2(params_from_paper("degrees", **PAPER))
    _ = model.casadi_rhs  # build (and cache) the CasADi function before pickling
    clone = pickle.loads(pickle.dumps(model))
    assert clone.params == model.params
    rng = np.random.default_rng(5)
    x, u, w = rng.normal(size=6), np.array([0.2]), rng.normal(size=3) * 0.1
    p = model.params.to_vector()
    np.testing.assert_array_equal(clone.f_numpy(x, u, w, p), model.f_numpy(x, u, w, p))
    np.testing.assert_array_equal(
        np.asarray(clone.casadi_rhs(x, u, w, p)), np.asarray(model.casadi_rhs(x, u, w, p))
    )
    np.testing.assert_array_equal(clone.step_numpy(x, u, w, p, H), model.step_numpy(x, u, w, p, H))


def test_period_integrator_pickle_round_trip() -> None:
    model = Nomoto2()
    integ = PeriodIntegrator(model, H, N_SUB)
    clone = pickle.loads(pickle.dumps(integ))
    assert (clone.h, clone.n_sub) == (H, N_SUB)
    rng = np.random.default_rng(6)
    x0 = rng.normal(size=6)
    w_block = rng.normal(size=(N_SUB, 3)) * 0.05
    p_block = np.tile(model.params.to_vector(), (N_SUB, 1))
    np.testing.assert_array_equal(
        clone(x0, 0.3, w_block, p_block), integ(x0, 0.3, w_block, p_block)
    )


def test_compiled_period_integrator_is_bit_identical_to_the_vm() -> None:
    """shipgym.codegen's C build of the period function gives the VM's results exactly."""
    model = Nomoto2()
    vm = PeriodIntegrator(model, H, N_SUB, compile=False)
    c = PeriodIntegrator(model, H, N_SUB, compile=True)
    rng = np.random.default_rng(11)
    for _ in range(20):
        x0 = rng.normal(size=6)
        w_block = rng.normal(size=(N_SUB, 3)) * 0.05
        p_block = np.tile(random_params(rng), (N_SUB, 1))
        dc = float(rng.uniform(-0.5, 0.5))
        np.testing.assert_array_equal(vm(x0, dc, w_block, p_block), c(x0, dc, w_block, p_block))


def test_batched_period_integrator_equals_single_calls() -> None:
    model = Nomoto2()
    single = PeriodIntegrator(model, H, N_SUB, compile=True)
    batch = PeriodIntegrator(model, H, N_SUB, compile=True, batch=5)
    rng = np.random.default_rng(12)
    x0 = rng.normal(size=(5, 6))
    u = rng.uniform(-0.5, 0.5, 5)
    w = rng.normal(size=(5, N_SUB, 3)) * 0.05
    p = np.stack([np.tile(random_params(rng), (N_SUB, 1)) for _ in range(5)])
    out = batch.batched(x0, u, w, p)
    for i in range(5):
        np.testing.assert_array_equal(out[i], single(x0[i], u[i], w[i], p[i]))
