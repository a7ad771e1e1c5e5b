"""Tests for the esso_osaka model (Xu et al. 2020 eq. (8)–(16); data/ship_models.md §1).

The §1.8 regression targets of the data file were made with the source's numerics: explicit
Euler, dt = 1 s full scale, rudder stepped (no servo) at t = 19 s, n = 0.68 rps constant,
u0 = 8 kn, (m − X_u̇)' = 0.0188.  ``euler_run`` repeats exactly that with the model's own
right-hand side (``model.f_numpy``), so those tests check the rhs, not the integrator.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from shipgym.manoeuvres import turning_circle
from shipgym.models import MODELS
from shipgym.models.base import ParameterError
from shipgym.models.esso_osaka import EssoOsaka, EssoOsakaParams
from shipgym.models.integrator import PeriodIntegrator

DEG = math.pi / 180.0
VARIANTS = EssoOsaka.variants

#: data/ship_models.md §1.8 (a): port turns (δ_paper > 0), from the execute point / time.
TURN_TARGETS: dict[tuple[str, int], dict[str, float]] = {
    ("literal", 35): dict(advance=697, transfer=405, t_90=215, tactical_diameter=907, t_180=385,
                          steady_diameter=846, steady_speed=3.89, steady_turn_rate=-0.526),
    ("literal", 20): dict(advance=945, transfer=579, t_90=299, tactical_diameter=1240, t_180=534,
                          steady_diameter=1117, steady_speed=3.65, steady_turn_rate=-0.375),
    ("literal", 10): dict(advance=1399, transfer=924, t_90=454, tactical_diameter=1918, t_180=815,
                          steady_diameter=1747, steady_speed=3.72, steady_turn_rate=-0.244),
    ("intended_fix", 35): dict(advance=684, transfer=301, t_90=208, tactical_diameter=705,
                               t_180=371, steady_diameter=536, steady_speed=2.50,
                               steady_turn_rate=-0.534),
    ("intended_fix", 20): dict(advance=880, transfer=404, t_90=267, tactical_diameter=899,
                               t_180=470, steady_diameter=626, steady_speed=2.28,
                               steady_turn_rate=-0.417),
    ("intended_fix", 10): dict(advance=1190, transfer=566, t_90=362, tactical_diameter=1185,
                               t_180=617, steady_diameter=770, steady_speed=2.16,
                               steady_turn_rate=-0.322),
}  # fmt: skip
#: §1.8 (a) zig-zags: (time from start [s], heading [deg], port positive) of the extremes.
ZIGZAG_TARGETS: dict[tuple[str, int], tuple[tuple[float, float], tuple[float, float]]] = {
    ("literal", 10): ((170, 13.64), (433, -13.94)),
    ("literal", 20): ((169, 26.06), (423, -26.95)),
    ("intended_fix", 10): ((208, 16.85), (549, -21.85)),
    ("intended_fix", 20): ((212, 32.77), (546, -38.30)),
}
#: Relative tolerance on distances and speeds.  intended_fix: the rhs is the coded one, the
#: residual ≤ 0.4 % is how the data file read the 90°/180° points (not stated; its times are
#: whole seconds, so the first Euler sample at or past the angle is used here).  literal:
#: the source's X_vvrr term divides by an integrator-driven "Ucapcor" (§1.7 item 3); ours by U
#: (tactical diameter 901 m instead of 907 m, data file §1.1), 2 %.
REL_TOL = {"intended_fix": 0.005, "literal": 0.02}
EXECUTE_STEP = 19  # the rudder moves at step 20 of the source's loop, t = 19 s


def regression_params(**changes: float) -> EssoOsakaParams:
    """The §1.8 configuration: full scale, (m − X_u̇)' = 0.0188, coded slipstream, n = n0."""
    base = dict(scale=1.0, rho=1025.0, m_Xudot=0.0188, slip_exp=2.0, speed_control=0.0)
    return EssoOsakaParams(**{**base, **changes})


def euler_run(model: EssoOsaka, paper_rudder, n_steps: int, dt: float = 1.0) -> np.ndarray:
    """Explicit Euler of the rhs with the rudder *set* (no servo), as the source code does.

    ``paper_rudder(k, x)`` gives the source's δ (port turn for δ > 0); the model state holds
    the project's δ = −δ_paper.  Returns the (n_steps + 1, n_x) states at t = k·dt.
    """
    p = model.params
    pv = p.to_vector()
    x = model.initial_state(u=p.u0, n=p.n0)
    i_delta = model.state_index("delta")
    states = [x.copy()]
    for k in range(n_steps):
        delta = -paper_rudder(k, x)
        x[i_delta] = delta
        xdot = model.f_numpy(x, [delta], [0.0, 0.0, 0.0], pv)
        xdot[i_delta] = 0.0
        x = x + dt * xdot
        states.append(x.copy())
    return np.array(states)


def euler_turn_figures(model: EssoOsaka, rudder_deg: float) -> dict[str, float]:
    """§1.8 turning figures from a 2400 s Euler run (readings at the first sample past)."""
    k0 = EXECUTE_STEP
    xs = euler_run(model, lambda k, _x: rudder_deg * DEG if k >= k0 else 0.0, 2400)
    turned = -(xs[k0:, 2] - xs[k0, 2])  # port turn: ψ decreases
    along, across = xs[k0:, 0] - xs[k0, 0], -(xs[k0:, 1] - xs[k0, 1])
    k90 = int(np.flatnonzero(turned >= math.pi / 2)[0])
    k180 = int(np.flatnonzero(turned >= math.pi)[0])
    speed = math.hypot(xs[-1, 3], xs[-1, 4])
    r = float(xs[-1, 5])
    return dict(
        advance=along[k90],
        transfer=across[k90],
        t_90=k90,
        tactical_diameter=across[k180],
        t_180=k180,
        steady_speed=speed,
        steady_turn_rate=r / DEG,
        steady_diameter=2.0 * speed / abs(r),
    )


@pytest.mark.parametrize("variant", VARIANTS)
@pytest.mark.parametrize("rudder_deg", [35, 20, 10])
def test_turning_circle_matches_data_file_targets(variant: str, rudder_deg: int) -> None:
    figures = euler_turn_figures(EssoOsaka(regression_params(), variant), rudder_deg)
    target = TURN_TARGETS[(variant, rudder_deg)]
    for key in ("advance", "transfer", "tactical_diameter", "steady_speed", "steady_diameter"):
        assert figures[key] == pytest.approx(target[key], rel=REL_TOL[variant]), key
    for key in ("t_90", "t_180"):  # one Euler step
        assert abs(figures[key] - target[key]) <= 1.0, key
    # steady rate: the table's 3 decimals; negative = port turn, as in the source
    assert figures["steady_turn_rate"] == pytest.approx(target["steady_turn_rate"], abs=0.002)


@pytest.mark.parametrize("variant", VARIANTS)
@pytest.mark.parametrize("amplitude", [10, 20])
def test_zigzag_matches_data_file_targets(variant: str, amplitude: int) -> None:
    model = EssoOsaka(regression_params(), variant)
    amp = amplitude * DEG
    state = {"rudder": amp, "switches": []}

    def rudder(k: int, x: np.ndarray) -> float:  # port first, switch when |ψ| reaches amp
        if k < EXECUTE_STEP:
            return 0.0
        heading = -float(x[2])  # port positive
        if state["rudder"] * heading >= amp * amp:
            state["rudder"] = -state["rudder"]
            state["switches"].append(k)
        return state["rudder"]

    xs = euler_run(model, rudder, 900)
    heading = -xs[:, 2] / DEG
    s1, s2, s3 = state["switches"][:3]
    k1 = s1 + int(np.argmax(heading[s1:s2]))
    k2 = s2 + int(np.argmin(heading[s2:s3]))
    targets = ZIGZAG_TARGETS[(variant, amplitude)]
    for (t_target, psi_target), k in zip(targets, (k1, k2), strict=True):
        assert abs(k - t_target) <= 1.0
        assert heading[k] == pytest.approx(psi_target, abs=0.02)  # table: 2 decimals


@pytest.mark.parametrize("variant", VARIANTS)
def test_rk4_turning_circle_with_fast_servo_matches_data_file(variant: str) -> None:
    """The model's own CasADi RK4 (h = 0.1 s) with a fast servo reproduces §1.8 too: the
    integration scheme and the 0.3 s servo lag move the 35° figures by < 2 %."""
    params = regression_params(T_servo=0.3, rudder_rate=100.0)
    _, figures = turning_circle(EssoOsaka(params, variant), -35.0, execute_time=19.0, h=0.1)
    target = TURN_TARGETS[(variant, 35)]
    for key in ("advance", "transfer", "tactical_diameter", "steady_speed", "steady_diameter"):
        assert figures[key] == pytest.approx(target[key], rel=0.02), key
    for key in ("t_90", "t_180"):
        assert abs(figures[key] - target[key]) <= 2.0, key
    assert figures["steady_turn_rate"] == pytest.approx(target["steady_turn_rate"], abs=0.005)


@pytest.mark.parametrize("variant", VARIANTS)
def test_froude_scaling_of_turning_circle(variant: str) -> None:
    """1:100 model = ship with lengths /100, times /10 (h scaled by √λ as well)."""
    model = EssoOsaka(EssoOsakaParams(), variant)
    ship = EssoOsaka(EssoOsakaParams(scale=1.0, rho=1025.0), variant)
    log_m, fig_m = turning_circle(model, 35.0, h=0.05)
    log_s, fig_s = turning_circle(ship, 35.0, h=0.5)
    factors = dict(
        advance=100.0,
        transfer=100.0,
        tactical_diameter=100.0,
        steady_diameter=100.0,
        t_90=10.0,
        t_180=10.0,
        steady_speed=10.0,
        steady_turn_rate=0.1,
        speed_loss=1.0,
    )
    for key, factor in factors.items():
        assert fig_s[key] == pytest.approx(factor * fig_m[key], rel=1e-6), key
    assert len(log_m.t) == len(log_s.t)
    np.testing.assert_allclose(log_s.x, 100.0 * log_m.x, rtol=0, atol=1e-6 * 325.0)
    np.testing.assert_allclose(log_s.y, 100.0 * log_m.y, rtol=0, atol=1e-6 * 325.0)
    assert model.length == pytest.approx(3.25)
    assert model.nominal_speed == pytest.approx(0.41152)
    assert model.rudder_rate_limit == pytest.approx(23.3 * DEG)


@pytest.mark.parametrize("variant", VARIANTS)
@pytest.mark.parametrize(
    "changes",
    [
        {},
        {"scale": 1.0, "speed_control": 0.0, "slip_exp": 1.0, "m_Xudot": 0.0188},
        {"constant_revolutions": 1.0},
    ],
)
def test_numpy_and_casadi_rhs_agree(variant: str, changes: dict[str, float]) -> None:
    model = EssoOsaka(EssoOsakaParams(**changes), variant)
    rng = np.random.default_rng(5)
    n = 40
    v_scale = 1.0 / math.sqrt(model.params.scale)  # full-scale speeds × this
    x = np.vstack(
        [
            rng.uniform(-50, 50, n),
            rng.uniform(-50, 50, n),
            rng.uniform(-math.pi, math.pi, n),
            rng.uniform(1.0, 6.0, n) * v_scale,
            rng.uniform(-1.0, 1.0, n) * v_scale,
            rng.uniform(-0.01, 0.01, n) / v_scale,
            rng.uniform(-0.6, 0.6, n),
            rng.uniform(0.2, 1.3, n) / v_scale,
            rng.uniform(-5.0, 5.0, n),
        ]
    )
    u = rng.uniform(-0.8, 0.8, (1, n))
    w = np.vstack([rng.uniform(-2, 2, (2, n)) * v_scale, rng.uniform(-1e-3, 1e-3, (1, n))])
    p = model.params.to_vector()
    batched = model.f_numpy(x, u, w, p)
    symbolic = np.hstack(
        [np.asarray(model.casadi_rhs(x[:, i], u[:, i], w[:, i], p)) for i in range(n)]
    )
    row_scale = np.max(np.abs(batched), axis=1, keepdims=True)  # per state: its magnitude
    assert np.all(np.abs(symbolic - batched) <= 1e-12 * (np.abs(batched) + row_scale))


@pytest.mark.parametrize("variant", VARIANTS)
def test_zero_relative_velocity_drifts_exactly_with_the_current(variant: str) -> None:
    """Exact condition: u_r = v_r = r = 0 and the propeller stopped (n = 0, set-point
    U_ref = 0 with the speed controller on, so it stays stopped); any rudder angle (c = 0
    carries no rudder force).  Every force then vanishes: the ship moves with the water."""
    model = EssoOsaka(EssoOsakaParams(U_ref=0.0), variant)
    current = np.array([0.15, -0.08])
    psi = 0.7
    u_c = current[0] * math.cos(psi) + current[1] * math.sin(psi)
    v_c = -current[0] * math.sin(psi) + current[1] * math.cos(psi)
    x0 = model.initial_state(x=3.0, y=-2.0, psi=psi, u=u_c, v=v_c, delta=0.2)
    w = np.array([current[0], current[1], 0.0])
    xdot = model.f_numpy(x0, [0.2], w, model.params.to_vector())
    np.testing.assert_allclose(xdot, [current[0], current[1], 0, 0, 0, 0, 0, 0, 0], atol=1e-15)
    n_sub, h = 400, model.fine_step
    integ = PeriodIntegrator(model, h, n_sub)
    states = integ(x0, 0.2, np.tile(w, (n_sub, 1)), model.params.to_vector()[None, :])
    t = h * np.arange(n_sub + 1)
    np.testing.assert_allclose(states[:, 0], 3.0 + current[0] * t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(states[:, 1], -2.0 + current[1] * t, rtol=0, atol=1e-12)
    np.testing.assert_allclose(states[:, 2:], np.tile(x0[2:], (n_sub + 1, 1)), atol=1e-15)


@pytest.mark.parametrize("variant", VARIANTS)
def test_constant_current_only_shifts_the_still_water_track(variant: str) -> None:
    """Xu et al. (2020) eq. (8)–(9): in a constant current the motion through the water is
    the still-water motion, the track displaced by Vc·t."""
    model = EssoOsaka(variant=variant)
    current = np.array([-0.12, 0.05])
    n_sub, h = 600, model.fine_step
    integ = PeriodIntegrator(model, h, n_sub)
    p = model.params.to_vector()[None, :]
    x_still = model.cruise_state(psi=0.4)
    still = integ(x_still, 20.0 * DEG, np.zeros((n_sub, 3)), p)
    psi = x_still[2]
    x_cur = x_still.copy()
    x_cur[3] += current[0] * math.cos(psi) + current[1] * math.sin(psi)
    x_cur[4] += -current[0] * math.sin(psi) + current[1] * math.cos(psi)
    w = np.tile([current[0], current[1], 0.0], (n_sub, 1))
    moving = integ(x_cur, 20.0 * DEG, w, p)
    t = h * np.arange(n_sub + 1)
    np.testing.assert_allclose(moving[:, 0] - current[0] * t, still[:, 0], atol=1e-6)
    np.testing.assert_allclose(moving[:, 1] - current[1] * t, still[:, 1], atol=1e-6)
    np.testing.assert_allclose(moving[:, 2], still[:, 2], atol=1e-7)
    assert abs(still[-1, 2] - psi) > 60 * DEG  # it did turn


@pytest.mark.parametrize("variant", VARIANTS)
def test_positive_rudder_turns_to_starboard(variant: str) -> None:
    """Project convention: δ > 0 → r > 0 (the source's δ > 0 turns to port)."""
    model = EssoOsaka(variant=variant)
    _, plus = turning_circle(model, 10.0)
    _, minus = turning_circle(model, -10.0)
    assert plus["steady_turn_rate"] > 0 > minus["steady_turn_rate"]


@pytest.mark.parametrize("variant", VARIANTS)
def test_cruise_state_is_the_straight_ahead_equilibrium(variant: str) -> None:
    model = EssoOsaka(variant=variant)
    x = model.cruise_state()
    assert x[model.state_index("u")] == pytest.approx(4.1152 / 10.0)
    assert x[model.state_index("r")] == 0.0
    # neutral rudder balances the propeller asymmetry: ≈ +0.8° (data file §1.7 item 6)
    assert x[model.state_index("delta")] / DEG == pytest.approx(0.79, abs=0.05)
    xdot = model.f_numpy(x, [x[model.state_index("delta")]], [0, 0, 0], model.params.to_vector())
    np.testing.assert_allclose(xdot[2:], 0.0, atol=1e-10)


@pytest.mark.parametrize(("variant", "stable"), [("literal", True), ("intended_fix", False)])
def test_course_stability_at_cruise(variant: str, stable: bool) -> None:
    """Data file §1.7 item 2: u/U_max (literal) makes the ship course-stable; with u/U
    (intended_fix) it is course-unstable, as the real Esso Osaka in deep water."""
    model = EssoOsaka(variant=variant)
    x0 = model.cruise_state()
    xs, us = ca.SX.sym("x", model.n_states), ca.SX.sym("u", 1)
    xdot = model.casadi_rhs(xs, us, ca.DM.zeros(3), model.params.to_vector())
    jac = ca.Function("linearisation", [xs, us], [ca.jacobian(xdot, xs)])
    sway_yaw = [model.state_index("v"), model.state_index("r")]
    a = np.asarray(jac(x0, x0[model.state_index("delta")]))[np.ix_(sway_yaw, sway_yaw)]
    assert (np.max(np.linalg.eigvals(a).real) < 0) == stable


def test_speed_controller_settles_at_a_new_set_point() -> None:
    """Integral action: after a set-point change the surge speed settles on it exactly."""
    model = EssoOsaka()
    new = EssoOsaka(model.params.replace(U_ref=7.0 * 0.5144))
    x0 = model.cruise_state()
    delta = new.cruise_state()[new.state_index("delta")]
    n_sub = 200  # 10 s periods; 24 of them = 240 s model scale (the PI zero is at 1/34 s)
    integ = PeriodIntegrator(new, new.fine_step, n_sub)
    x = x0
    for _ in range(24):
        x = integ(x, delta, np.zeros((n_sub, 3)), new.params.to_vector()[None, :])[-1]
    assert x[3] == pytest.approx(7.0 * 0.5144 / 10.0, rel=1e-4)
    assert x[new.state_index("n")] == pytest.approx(new.cruise_state()[7], rel=1e-4)


def test_speed_controller_off_holds_the_propeller_at_n0() -> None:
    model = EssoOsaka(EssoOsakaParams(speed_control=0.0))
    x = model.initial_state(u=0.3, n=5.0, speed_error_integral=2.0)
    xdot = model.f_numpy(x, [0.0], [0, 0, 0], model.params.to_vector())
    n0, t_shaft = 0.68 * 10.0, 50.0 / 10.0
    assert xdot[model.state_index("n")] == pytest.approx((n0 - 5.0) / t_shaft)
    assert xdot[model.state_index("speed_error_integral")] == 0.0
    assert model.cruise_state()[3] == pytest.approx(0.41152)  # the source's start, u0


def test_constant_revolutions_hold_the_straight_run_rps_of_the_set_point() -> None:
    """constant_revolutions = 1: n → ν·U_ref/L (0.644 rps full scale at 8 kn, data file
    §1.2), the controller integral frozen; the cruise state is the equilibrium at that n."""
    model = EssoOsaka(EssoOsakaParams(constant_revolutions=1.0))
    n_hold = 0.644 * 10.0
    x = model.initial_state(u=0.3, n=5.0, speed_error_integral=2.0)
    xdot = model.f_numpy(x, [0.0], [0, 0, 0], model.params.to_vector())
    assert xdot[model.state_index("n")] == pytest.approx((n_hold - 5.0) / 5.0, rel=1e-3)
    assert xdot[model.state_index("speed_error_integral")] == 0.0
    x0 = model.cruise_state()
    assert x0[model.state_index("n")] == pytest.approx(n_hold, rel=1e-3)
    assert x0[model.state_index("u")] == pytest.approx(model.nominal_speed, rel=1e-4)
    delta = x0[model.state_index("delta")]
    xdot = model.f_numpy(x0, [delta], [0, 0, 0], model.params.to_vector())
    np.testing.assert_allclose(xdot[2:], 0.0, atol=1e-10)


def test_constant_revolutions_lose_speed_in_the_turn_and_turn_slower() -> None:
    """The speed controller holds u in a 35° turn; at constant revolutions the ship slows
    down and its yaw rate drops (docs/validation.md)."""
    _, held = turning_circle(EssoOsaka(), 35.0)
    _, free = turning_circle(EssoOsaka(EssoOsakaParams(constant_revolutions=1.0)), 35.0)
    assert free["speed_loss"] > held["speed_loss"] + 0.03
    assert free["steady_turn_rate"] < 0.75 * held["steady_turn_rate"]


def test_model_mass_matches_the_scaled_displacement() -> None:
    """m'·½ρL³ at 1:100 in fresh water ≈ 311.6 kg (data file §1.3; m' = 0.0181 is rounded)."""
    assert EssoOsaka().mass == pytest.approx(311.6, rel=0.005)


@pytest.mark.parametrize("field", ["L", "scale"])
@pytest.mark.parametrize("value", [0.0, -1.0])
def test_bad_parameters_raise_naming_the_field(field: str, value: float) -> None:
    with pytest.raises(ParameterError, match=rf"\.{field} "):
        EssoOsakaParams(**{field: value})


@pytest.mark.parametrize("field", ["speed_control", "slip_exp", "constant_revolutions"])
def test_switch_parameters_accept_only_their_values(field: str) -> None:
    with pytest.raises(ParameterError, match=field):
        EssoOsakaParams(**{field: 0.5})


def test_unknown_variant_raises() -> None:
    with pytest.raises(ParameterError, match="unknown variant"):
        EssoOsaka(variant="fixed")


def test_registered() -> None:
    assert MODELS["esso_osaka"] is EssoOsaka
    assert EssoOsaka().variant == "literal"
