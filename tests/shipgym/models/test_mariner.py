"""Tests for the mariner ship (de Wit–Oppe model, Borkowski 2018 eq. (35)).

The reference equations are written out again here (the sway line read as algebraic,
v = r1·r + r3·r³, data/ship_models.md §2.1) so that the model's rhs is never its own
reference.  Published figures: Borkowski (2018) §5 (r_max = 0.0191 rad/s, 7.7 m/s,
δmax = 0.6 rad, δ̇max = 0.066 rad/s).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym.manoeuvres import ManoeuvreError, turning_circle, zigzag
from shipgym.models import MODELS
from shipgym.models.base import ParameterError
from shipgym.models.integrator import PeriodIntegrator
from shipgym.models.mariner import Mariner, MarinerParams
from tests.shipgym.models.batching import assert_columns_are_ships

DEG = math.pi / 180.0
R_MAX = 0.0191  # rad/s, Borkowski (2018) §5
PAPER_SPEED = 7.7  # m/s, initial speed of Borkowski (2018) §5
DELTA_MAX = 0.6  # rad
DELTA_DOT_MAX = 0.066  # rad/s
IX = {name: i for i, name in enumerate(Mariner.state_names)}


def reference_rhs(s: np.ndarray, dz: float, w: np.ndarray, p: MarinerParams) -> np.ndarray:
    """de Wit–Oppe with the steering gear of eq. (35), sway algebraic (written out anew)."""
    _x, _y, psi, r, V, _v, d = s
    dz = min(max(dz, -p.delta_max), p.delta_max)
    rd = -p.a1 * r - p.a2 * r**3 + p.a3 * d + w[2]
    v = p.r1 * r + p.r3 * r**3
    return np.array(
        [
            V * math.cos(psi) - v * math.sin(psi) + w[0],
            V * math.sin(psi) + v * math.cos(psi) + w[1],
            r,
            rd,
            -p.f * V - p.W * r**2 + p.S,
            (p.r1 + 3 * p.r3 * r**2) * rd,
            min(max((dz - d) / p.T_delta, -p.delta_dot_max), p.delta_dot_max),
        ]
    )


def random_params(rng: np.random.Generator) -> MarinerParams:
    d = MarinerParams()
    scale = lambda v: v * rng.uniform(0.5, 1.5)  # noqa: E731
    return MarinerParams(
        a1=scale(d.a1),
        a2=scale(d.a2),
        a3=scale(d.a3),
        f=scale(d.f),
        W=scale(d.W),
        S=scale(d.S),
        r1=scale(d.r1),
        r3=rng.uniform(-2e4, 2e4),
        T_delta=scale(d.T_delta),
        delta_max=scale(d.delta_max),
        delta_dot_max=scale(d.delta_dot_max),
        L=scale(d.L),
    )


def random_state(rng: np.random.Generator) -> np.ndarray:
    return rng.normal(size=7) * np.array([500, 500, 3, 0.03, 4, 2, 0.5])


def run(
    model: Mariner, x0: np.ndarray, commands: list[float], w=(0.0, 0.0, 0.0), h: float = 0.1
) -> np.ndarray:
    """States at t = 0, 1, 2, … s (Ts = 1 s) with the command held over each second."""
    n_sub = round(1.0 / h)
    integ = PeriodIntegrator(model, h, n_sub)
    wb = np.tile(np.asarray(w, dtype=float), (n_sub, 1))
    pb = np.tile(model.params.to_vector(), (n_sub, 1))
    out, x = [np.array(x0, dtype=float)], np.array(x0, dtype=float)
    for c in commands:
        x = integ(x, c, wb, pb)[-1]
        out.append(x)
    return np.array(out)


# --------------------------------------------------------------------------------------------
# one rhs, two backends, against the written-out equations
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("variant", Mariner.variants)
def test_casadi_rhs_equals_numpy_rhs_at_random_states(variant: str) -> None:
    model = Mariner(variant=variant)
    rng = np.random.default_rng(0)
    for _ in range(50):
        x = random_state(rng)
        u = rng.uniform(-1.0, 1.0, size=1)  # beyond ±δmax too
        w = rng.normal(size=3) * np.array([0.5, 0.5, 1e-3])
        p = random_params(rng).to_vector()
        expected = model.f_numpy(x, u, w, p)
        got = np.asarray(model.casadi_rhs(x, u, w, p)).ravel()
        assert got.shape == (7,)
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-15)


def test_numpy_rhs_equals_the_written_out_equations() -> None:
    model = Mariner()
    rng = np.random.default_rng(1)
    for _ in range(50):
        x, dz = random_state(rng), float(rng.uniform(-1.0, 1.0))
        w = rng.normal(size=3) * np.array([0.5, 0.5, 1e-3])
        p = random_params(rng)
        np.testing.assert_allclose(
            model.f_numpy(x, [dz], w, p.to_vector()),
            reference_rhs(x, dz, w, p),
            rtol=1e-12,
            atol=1e-15,
        )


def test_batched_numpy_equals_per_ship() -> None:
    model = Mariner()
    rng = np.random.default_rng(2)
    n = 5
    x = np.stack([random_state(rng) for _ in range(n)], axis=1)
    u = rng.uniform(-1.0, 1.0, size=(1, n))
    w = rng.normal(size=(3, n)) * 0.1
    p = np.stack([random_params(rng).to_vector() for _ in range(n)], axis=1)
    assert_columns_are_ships(model, x, u, w, p)


# --------------------------------------------------------------------------------------------
# the paper's ship figures
# --------------------------------------------------------------------------------------------


def test_steady_turn_at_full_rudder_matches_closed_form_and_r_max() -> None:
    model = Mariner()
    r, u, v = model.steady_turn(DELTA_MAX)
    p = model.params
    assert p.a1 * r + p.a2 * r**3 == pytest.approx(p.a3 * DELTA_MAX, rel=1e-12)
    # Borkowski (2018) §5: r_max = 0.0191 rad/s; the closed form gives 0.019049 (−0.27 %)
    assert r == pytest.approx(R_MAX, rel=0.005)
    log, fig = turning_circle(model, rudder_deg=DELTA_MAX / DEG)
    # the simulated steady turn rate over the last 360° is the root of the cubic
    assert fig["steady_turn_rate"] * DEG == pytest.approx(r, rel=1e-4)
    assert fig["steady_turn_rate"] * DEG == pytest.approx(R_MAX, rel=0.005)
    # speed over ground (the 720° run still carries ≈0.2 % of the 71 s surge transient)
    assert fig["steady_speed"] == pytest.approx(math.hypot(u, v), rel=0.005)
    assert log.r[-1] == pytest.approx(r, rel=1e-6)
    assert log.delta[-1] == pytest.approx(DELTA_MAX, rel=1e-9)


def test_data_file_plausibility_figures_at_35_degrees() -> None:
    """data/ship_models.md §2.1: δ = 35° → r 0.0192 rad/s, V 4.59 m/s, v −1.33 m/s."""
    r, u, v = Mariner().steady_turn(35.0 * DEG)
    assert r == pytest.approx(0.0192, abs=5e-5)
    assert u == pytest.approx(4.59, abs=0.015)  # the data file rounded r first
    assert v == pytest.approx(-1.33, abs=0.01)


def test_straight_line_speed_converges_to_s_over_f() -> None:
    model = Mariner()
    p = model.params
    x0 = model.cruise_state(u=PAPER_SPEED)  # Borkowski (2018) §5 starts at 7.7 m/s
    states = run(model, x0, [0.0] * 1000)
    t = np.arange(1001.0)
    V_inf = p.S / p.f
    assert V_inf == pytest.approx(7.857142857, rel=1e-9)
    # u̇ = −f u + S: u(t) = S/f + (u0 − S/f) e^{−ft}; x(t) = ∫u dt
    decay = np.exp(-p.f * t)
    np.testing.assert_allclose(states[:, IX["u"]], V_inf + (PAPER_SPEED - V_inf) * decay, atol=1e-9)
    x_exact = V_inf * t + (PAPER_SPEED - V_inf) * (1 - decay) / p.f
    np.testing.assert_allclose(states[:, IX["x"]], x_exact, atol=1e-6)
    assert abs(states[-1, IX["u"]] - V_inf) < 1e-6
    np.testing.assert_array_equal(states[:, [IX["y"], IX["psi"], IX["r"], IX["v"]]], 0.0)


def test_cruise_state_is_an_equilibrium() -> None:
    model = Mariner()
    x = model.cruise_state()
    assert x[IX["u"]] == pytest.approx(model.nominal_speed) == pytest.approx(0.11 / 0.014)
    xdot = model.f_numpy(x, [0.0], np.zeros(3), model.params.to_vector())
    np.testing.assert_allclose(xdot, [model.nominal_speed, 0, 0, 0, 0, 0, 0], atol=1e-15)
    assert model.cruise_state(u=7.7, psi=0.3)[[IX["u"], IX["psi"]]].tolist() == [7.7, 0.3]
    # the default variant's sway read-out starts consistent with a given yaw rate
    assert model.cruise_state(r=0.01)[IX["v"]] == pytest.approx(-0.695)


def test_positive_rudder_gives_positive_yaw_rate_and_outward_drift() -> None:
    model = Mariner()
    states = run(model, model.cruise_state(), [0.2] * 120)
    assert states[-1, IX["r"]] > 0 and states[-1, IX["psi"]] > 0 and states[-1, IX["y"]] > 0
    assert states[-1, IX["v"]] < 0  # the stern slides out of the turn (r1 < 0)
    _, fig = turning_circle(model, rudder_deg=20.0, duration=300.0)
    assert fig["transfer"] > 0 and fig["advance"] > 0


# --------------------------------------------------------------------------------------------
# steering gear
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("rudder_deg", "switch_deg"), [(10.0, 10.0), (20.0, 20.0)])
def test_zigzag_respects_rudder_rate_and_angle_limits(rudder_deg: float, switch_deg: float) -> None:
    model = Mariner()
    log, fig = zigzag(model, rudder_deg, switch_deg)
    assert "overshoot_2" in fig
    rate = np.abs(np.diff(log.delta)) / log.h
    assert rate.max() <= DELTA_DOT_MAX * (1 + 1e-12)
    assert rate.max() >= DELTA_DOT_MAX * (1 - 1e-9)  # the rate limit is active
    assert np.abs(log.delta).max() <= rudder_deg * DEG + 1e-12


def test_a_command_beyond_the_rudder_limit_is_cut_in_the_plant() -> None:
    """The plant saturates δ at 0.6 rad; a manoeuvre asked for beyond it is refused."""
    model = Mariner()
    states = run(model, model.cruise_state(), [45.0 * DEG] * 30)
    assert np.abs(states[:, IX["delta"]]).max() == pytest.approx(DELTA_MAX, rel=1e-9)
    with pytest.raises(ManoeuvreError, match="beyond the mariner rudder limit"):
        zigzag(model, 45.0, 20.0)


def test_rudder_servo_is_first_order_with_unit_time_constant() -> None:
    model = Mariner()
    # small step: below the rate limit, δ(t) = δz (1 − e^{−t/1 s})
    states = run(model, model.cruise_state(), [0.05] * 5, h=0.01)
    np.testing.assert_allclose(
        states[:, IX["delta"]], 0.05 * (1 - np.exp(-np.arange(6.0))), rtol=1e-8
    )


# --------------------------------------------------------------------------------------------
# disturbances
# --------------------------------------------------------------------------------------------


def test_ship_at_rest_drifts_exactly_with_the_current() -> None:
    model = Mariner(MarinerParams(S=0.0))  # engine stopped: u = 0 stays 0
    current = (0.3, -0.2)
    states = run(model, model.initial_state(x=10.0, y=5.0, psi=1.0), [0.0] * 100, (*current, 0))
    t = np.arange(101.0)
    np.testing.assert_allclose(states[:, IX["x"]], 10.0 + current[0] * t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(states[:, IX["y"]], 5.0 + current[1] * t, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(states[:, [IX["r"], IX["u"], IX["v"], IX["delta"]]], 0.0)


@pytest.mark.parametrize("variant", Mariner.variants)
def test_current_only_adds_to_position_rates_and_yaw_disturbance_to_r_dot(variant: str) -> None:
    model = Mariner(variant=variant)
    p = model.params.to_vector()
    rng = np.random.default_rng(3)
    for _ in range(20):
        x, u = random_state(rng), rng.uniform(-1, 1, size=1)
        calm = model.f_numpy(x, u, np.zeros(3), p)
        w = np.array([*rng.normal(size=2), 0.0])
        np.testing.assert_allclose(model.f_numpy(x, u, w, p) - calm, [*w[:2], 0, 0, 0, 0, 0])
        d = rng.normal() * 1e-3
        diff = model.f_numpy(x, u, np.array([0, 0, d]), p) - calm
        np.testing.assert_allclose(diff[[0, 1, 2, 4, 6]], 0.0, atol=1e-15)
        assert diff[IX["r"]] == pytest.approx(d, rel=1e-9)


def test_constant_yaw_disturbance_acts_like_the_equivalent_rudder() -> None:
    """ṙ = −a1 r − a2 r³ + d: steady r solves a1 r + a2 r³ = d, i.e. rudder δ = d/a3."""
    model = Mariner()
    d = 2e-4  # rad/s²
    states = run(model, model.cruise_state(), [0.0] * 600, (0.0, 0.0, d))
    r_eq, _, _ = model.steady_turn(d / model.params.a3)
    assert states[-1, IX["r"]] == pytest.approx(r_eq, rel=1e-6)
    assert states[-1, IX["delta"]] == 0.0


# --------------------------------------------------------------------------------------------
# the two readings of the sway line
# --------------------------------------------------------------------------------------------


def test_default_sway_state_stays_on_the_algebraic_relation() -> None:
    model = Mariner(MarinerParams(r3=-5e4))
    commands = [0.5] * 100 + [-0.6] * 150 + [0.1] * 50
    states = run(model, model.cruise_state(), commands)
    r = states[:, IX["r"]]
    assert np.abs(r).max() > 0.015
    np.testing.assert_allclose(states[:, IX["v"]], -69.5 * r - 5e4 * r**3, atol=1e-9)


def test_printed_variant_integrates_the_yaw_rate() -> None:
    """Eq. (35) as printed, v̇ = −r1 r: v = 69.5 m/rad × heading change (hence not default)."""
    model = Mariner(variant="printed")
    states = run(model, model.cruise_state(), [0.6] * 150)
    np.testing.assert_allclose(states[:, IX["v"]], 69.5 * states[:, IX["psi"]], rtol=1e-9)
    assert states[-1, IX["psi"]] > math.pi / 2 and states[-1, IX["v"]] > 109.0


# --------------------------------------------------------------------------------------------
# declaration, registry, validation
# --------------------------------------------------------------------------------------------


def test_declared_figures_and_registry() -> None:
    assert MODELS["mariner"] is Mariner
    model = Mariner()
    assert {"x", "y", "psi", "r", "u", "v", "delta"} <= set(model.state_names)
    assert model.disturbance_names == ("current_x", "current_y", "yaw_disturbance")
    assert model.length == 172.0
    assert model.rudder_limit == DELTA_MAX and model.rudder_rate_limit == DELTA_DOT_MAX
    n = model.control_period / model.fine_step
    assert n == round(n)
    other = model.with_params(model.params.replace(delta_max=0.5, delta_dot_max=0.05))
    assert other.rudder_limit == 0.5 and other.rudder_rate_limit == 0.05
    assert Mariner(variant="printed").with_params(model.params).variant == "printed"


@pytest.mark.parametrize(
    ("name", "bad"),
    [
        ("a3", 0.0),
        ("f", -0.014),
        ("T_delta", 0.0),
        ("delta_max", -0.6),
        ("delta_dot_max", 0.0),
        ("L", 0.0),
        ("a2", -1.0),
        ("W", -124.0),
        ("S", -0.11),
        ("a1", math.nan),
    ],
)
def test_bad_parameters_raise_naming_the_field(name: str, bad: float) -> None:
    with pytest.raises(ParameterError, match=rf"\.{name} must be"):
        MarinerParams(**{name: bad})


def test_no_yaw_damping_is_rejected_and_negative_a1_with_cubic_damping_is_allowed() -> None:
    with pytest.raises(ParameterError, match="a1"):
        MarinerParams(a1=0.0, a2=0.0)
    MarinerParams(a1=-0.005)  # course-unstable ship, stabilised by a2·r³


def test_unknown_variant_and_config_keys_raise() -> None:
    with pytest.raises(ParameterError, match="bogus"):
        Mariner(variant="bogus")
    with pytest.raises(ParameterError, match="speed"):
        Mariner.from_config({"speed": 7.7})
    assert Mariner.from_config({"W": 100.0}).params.W == 100.0
