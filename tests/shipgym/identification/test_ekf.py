"""The augmented EKF and its adaptation map: each test asserts recovery of a known truth or
an identity of the map."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym.identification.adaptation import QUANTITIES, Adaptation
from shipgym.identification.ekf import FilterSettings, ShipEKF, full_rudder_bias
from shipgym.identification.nominal import first_order_nomoto
from shipgym.identification.servo import ServoFit, servo_constants, servo_step
from shipgym.models import MODELS
from shipgym.models.loading import loading_change


@pytest.mark.parametrize("ship", sorted(MODELS))
def test_the_map_is_the_nominal_ship_at_zero_and_a_factor_elsewhere(ship: str) -> None:
    """θ(0) is the nominal vector; a factor's η multiplies exactly its parameters by e^η;
    the Jacobian matches a central difference of the map (1e-5 relative)."""
    nominal = MODELS[ship]().params
    adaptation = Adaptation(ship, nominal)
    assert np.array_equal(adaptation.params(np.zeros(adaptation.size)), nominal.to_vector())
    names = type(nominal).names()
    for i, q in enumerate(adaptation.quantities):
        if q.draught:
            continue
        eta = np.zeros(adaptation.size)
        eta[i] = math.log(2.0)
        expected = [2.0 if n in q.params else 1.0 for n in names] * nominal.to_vector()
        np.testing.assert_allclose(adaptation.params(eta), expected, rtol=1e-12)
    eta = np.linspace(-0.2, 0.2, adaptation.size)
    theta, jac = adaptation.jacobian(eta)
    for i in range(adaptation.size):
        step = np.zeros(adaptation.size)
        step[i] = 1e-6
        numeric = (adaptation.params(eta + step) - adaptation.params(eta - step)) / 2e-6
        np.testing.assert_allclose(jac[:, i], numeric, rtol=1e-5, atol=1e-9 * np.abs(theta).max())


@pytest.mark.parametrize("ship", ["esso_osaka", "mariner", "blanke", "kvlcc2"])
def test_the_draught_is_the_catalogues_loading_change(ship: str) -> None:
    """η_draught = ln 0.4 moves exactly what loading_change(ship, nominal, 0.4) moves."""
    nominal = MODELS[ship]().params
    adaptation = Adaptation(ship, nominal)
    eta = np.zeros(adaptation.size)
    eta[adaptation.names.index("draught")] = math.log(0.4)
    expected = nominal.replace(**loading_change(ship, nominal, 0.4)).to_vector()
    np.testing.assert_allclose(adaptation.params(eta), expected, rtol=1e-12)


def test_every_ship_has_its_quantities_and_bounds_contain_the_nominal_ship() -> None:
    assert set(QUANTITIES) == set(MODELS)
    for quantities in QUANTITIES.values():
        for q in quantities:
            assert q.low < 1.0 < q.high


def _simulate(ship: str, eta: np.ndarray, current: tuple[float, float], seconds: float):
    """The ship with the adapted quantities at ``eta`` and a steady current, steered by a
    20° sine of period 4T: (commands, noiseless measurements y at each period's end)."""
    model = MODELS[ship]()
    adaptation = Adaptation(ship, model.params)
    theta = adaptation.params(eta)
    _, t_yaw = first_order_nomoto(model, model.params)
    ts, h = model.control_period, model.fine_step
    w = np.array([current[0], current[1], 0.0])
    x = model.cruise_state()
    index = [model.state_index(n) for n in ("x", "y", "psi", "r", "delta")]
    commands, measurements = [], [x[index].copy()]
    for k in range(round(seconds / ts)):
        command = math.radians(20.0) * math.sin(2.0 * math.pi * k * ts / (4.0 * t_yaw))
        for _ in range(round(ts / h)):
            x = model.step_numpy(x, [command], w, theta, h)
        commands.append(command)
        measurements.append(x[index].copy())
    return model, adaptation, t_yaw, commands, measurements


@pytest.mark.parametrize(
    ("ship", "truth", "seconds"),
    [
        ("blanke", {"servo": math.log(3.0), "rudder": math.log(1.3)}, 240.0),
        ("esso_osaka", {"servo": math.log(20.0), "draught": math.log(0.7)}, 300.0),
        ("nomoto2", {"servo": math.log(5.0), "gain": math.log(1.4)}, 60.0),
    ],
)
def test_the_filter_recovers_a_changed_ship_and_its_current(
    ship: str, truth: dict[str, float], seconds: float
) -> None:
    """From the nominal ship, noiseless measurements of a changed ship in a steady current
    give back its servo time constant (0.05 in ln), the current (2 % of U) and its steering
    (first-order Nomoto K and T within 5 %).  Rudder effectiveness and draught are not
    told apart by a sine's response (both move K and T), so each alone is not asserted."""
    model = MODELS[ship]()
    names = Adaptation(ship, model.params).names
    eta = np.array([truth.get(n, 0.0) for n in names])
    current = (0.05 * model.nominal_speed, -0.08 * model.nominal_speed)
    model, adaptation, t_yaw, commands, ys = _simulate(ship, eta, current, seconds)
    ekf = ShipEKF(
        model,
        adaptation,
        model.control_period,
        max(1, round(model.control_period / model.fine_step)),
        t_yaw,
        model.length,
        model.nominal_speed,
        model.rudder_limit,
        FilterSettings(),
    )
    ekf.start(ys[0], model.nominal_speed)
    for command, y in zip(commands, ys[1:], strict=True):
        ekf.step(command, y)
    servo = names.index("servo")
    assert ekf.eta[servo] == pytest.approx(eta[servo], abs=0.05)
    np.testing.assert_allclose(ekf.disturbances[:2], current, atol=0.02 * model.nominal_speed)
    record = type(model.params).from_vector

    def steering(theta: np.ndarray) -> tuple[float, float]:
        return first_order_nomoto(model, record(theta))

    np.testing.assert_allclose(steering(ekf.params()), steering(adaptation.params(eta)), rtol=0.05)


def test_a_heading_outlier_is_dropped() -> None:
    """A 10° heading spike on one measurement moves no estimate (the gate)."""
    ship = "blanke"
    model, adaptation, t_yaw, commands, ys = _simulate(ship, np.zeros(4), (0.0, 0.0), 20.0)

    def run(spike: bool) -> np.ndarray:
        ekf = ShipEKF(model, adaptation, 0.2, 4, t_yaw, 51.5, 8.0, model.rudder_limit)
        ekf.start(ys[0], 8.0)
        for k, (command, y) in enumerate(zip(commands, ys[1:], strict=True)):
            y = y.copy()
            if spike and k == 50:
                y[2] += math.radians(10.0)
            ekf.step(command, y)
        return ekf.z

    np.testing.assert_allclose(run(True), run(False), rtol=0, atol=1e-12)


def test_the_full_rudder_bias_of_the_mariner_is_its_rudder_term() -> None:
    """Mariner: ṙ = … + a3·δ + w_ψ, so the full-rudder yaw bias is a3·δmax [rad/s²]."""
    model = MODELS["mariner"]()
    assert full_rudder_bias(model, model.rudder_limit) == pytest.approx(
        model.params.a3 * model.rudder_limit, rel=1e-12
    )


@pytest.mark.parametrize("ship", sorted(MODELS))
def test_every_ships_servo_is_the_fitted_form(ship: str) -> None:
    """The model's δ row is δ̇ = clip((δc − δ)/T, ±δ̇max) with the (T, δ̇max)
    servo_constants reads off it, at random δ, δc in ±δmax (the env's commands) and other
    states (1e-9 relative)."""
    model = MODELS[ship]()
    limit = model.rudder_limit
    params = model.params.to_vector()
    t, rate = servo_constants(model, params, limit)
    rng = np.random.default_rng(0)
    n = 50
    x = model.cruise_state()[:, None] * rng.uniform(0.5, 1.5, (model.n_states, n))
    x[model.state_index("delta")] = rng.uniform(-limit, limit, n)
    command = rng.uniform(-limit, limit, n)
    w = rng.normal(0.0, 0.1, (model.n_disturbances, n))
    rows = model.f_numpy(x, [command], w, np.tile(params[:, None], (1, n)))
    expected = np.clip((command - x[model.state_index("delta")]) / t, -rate, rate)
    np.testing.assert_allclose(rows[model.state_index("delta")], expected, rtol=1e-9)


def _servo_log(t: float, rate: float, h: float, seconds: float, limit: float):
    """δ and δc of a servo (T, δ̇max) under commands that hold for 3 s each, drawn in
    ±limit; (δ at each sample start, commands, δ at the end)."""
    rng = np.random.default_rng(1)
    n = round(seconds / h)
    hold = round(3.0 / h)
    commands = np.repeat(rng.uniform(-limit, limit, n // hold + 1), hold)[:n]
    d = np.zeros(n + 1)
    for k in range(n):
        d[k + 1] = servo_step(d[k : k + 1], commands[k : k + 1], t, rate, h)[0]
    return d, commands


@pytest.mark.parametrize(("t", "rate"), [(20.0, 0.022), (1.0, 0.066), (3.0, math.inf), (0.5, 0.04)])
def test_the_servo_fit_recovers_a_slowed_servo_from_the_nominal_one(t: float, rate: float) -> None:
    """From the nominal servo (T = 1 s, δ̇max = 0.066 rad/s, the Mariner's), the window's
    samples of an aged servo give back its T and, where it binds, δ̇max (1e-3 relative)."""
    h, limit = 0.1, 0.6
    nominal_rate = 0.066 if math.isfinite(rate) else math.inf
    fit = ServoFit(1.0, nominal_rate, h, 1200, limit, ((0.5, 100.0), (0.1, 2.0)))
    d, commands = _servo_log(t, rate, h, 120.0, limit)
    for k in range(0, commands.size, 10):  # periods of 1 s: 10 samples each
        fit.add(d[k : k + 10], commands[k : k + 10], d[k + 10])
        estimate = fit.fit()
    assert estimate[0] == pytest.approx(t, rel=1e-3)
    if math.isfinite(rate) and rate < 2.0 * limit / t:
        assert estimate[1] == pytest.approx(rate, rel=1e-3)
