"""Tests for the kvlcc2 model (MMG standard method, Yasukawa & Yoshimura 2015).

The manoeuvre figures are run with shipgym's own manoeuvres (:mod:`shipgym.manoeuvres`: RK4,
h = 0.05 s, the rudder servo inside the plant, constant propeller revolutions), from the
straight run at the nominal speed.  ``FIGURES`` pins what the model gives at its defaults
(``shipgym manoeuvre kvlcc2 turning|zigzag --rudder 10|20 --json``); docs/ships.md sets them
beside the published tests.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from shipgym.manoeuvres import turning_circle, zigzag
from shipgym.models import MODELS
from shipgym.models.base import ParameterError
from shipgym.models.kvlcc2 import FULL_SCALE, KVLCC2, KVLCC2Params, full_scale

DEG = math.pi / 180.0

#: the model's own standard manoeuvres at its defaults (L7 model, starboard first):
#: advance and tactical diameter in ship lengths, overshoots in degrees
FIGURES = {
    "advance": 3.081,
    "tactical_diameter": 3.118,
    "overshoot_10_1": 5.04,
    "overshoot_10_2": 13.72,
    "overshoot_20_1": 10.61,
    "overshoot_20_2": 15.79,
}


@pytest.fixture(scope="module")
def model() -> KVLCC2:
    return KVLCC2()


def test_registered_and_declared(model: KVLCC2) -> None:
    assert MODELS["kvlcc2"] is KVLCC2
    assert model.length == 7.0
    assert model.rudder_limit == pytest.approx(35.0 * DEG)
    assert model.rudder_rate_limit == pytest.approx(15.68 * DEG)
    assert (model.control_period, model.fine_step) == (0.5, 0.05)


def test_straight_run_is_the_simman_approach_speed(model: KVLCC2) -> None:
    """n_P = 11.85 rps holds U0 = 1.179 m/s (Fn = 0.142, 15.5 kn full scale) to 0.1 %, and
    the cruise state is an exact equilibrium (δ = 0, v = r = 0)."""
    assert model.nominal_speed == pytest.approx(1.179, rel=1e-3)
    fn = model.nominal_speed / math.sqrt(9.81 * model.length)
    assert fn == pytest.approx(0.142, abs=5e-4)
    x = model.cruise_state()
    xdot = model.f_numpy(x, [0.0], [0.0, 0.0, 0.0], model.params.to_vector())
    np.testing.assert_allclose(xdot[3:], 0.0, atol=1e-12)
    assert xdot[0] == pytest.approx(model.nominal_speed)


@pytest.mark.parametrize("params", [KVLCC2Params(), full_scale()], ids=["model", "ship"])
def test_numpy_and_casadi_rhs_agree(params: KVLCC2Params) -> None:
    """At random states (drift either side, so both branches of C2 and γ_R), inputs and
    disturbances, single and batched."""
    model = KVLCC2(params)
    rng = np.random.default_rng(7)
    pv = params.to_vector()
    root_lam = math.sqrt(params.scale)
    f = model.casadi_rhs
    batch_x, batch_u, batch_w = [], [], []
    for _ in range(40):
        x = np.array(
            [
                rng.normal(0.0, 10.0),
                rng.normal(0.0, 10.0),
                rng.uniform(-math.pi, math.pi),
                rng.uniform(0.2, 1.5) * root_lam,
                rng.uniform(-0.3, 0.3) * root_lam,
                rng.uniform(-0.15, 0.15) / root_lam,
                rng.uniform(-0.6, 0.6),
            ]
        )
        u = np.array([rng.uniform(-0.8, 0.8)])
        w = np.array([rng.normal(0.0, 0.1), rng.normal(0.0, 0.1), rng.normal(0.0, 1e-3)])
        expected = np.array(f(x, u, w, pv)).ravel()
        np.testing.assert_allclose(model.f_numpy(x, u, w, pv), expected, rtol=1e-12, atol=1e-12)
        batch_x.append(x)
        batch_u.append(u)
        batch_w.append(w)
    xb = np.array(batch_x).T
    ub = np.array(batch_u).T
    wb = np.array(batch_w).T
    out = model.f_numpy(xb, ub, wb, pv[:, None])
    for k in range(xb.shape[1]):
        expected = np.array(f(xb[:, k], ub[:, k], wb[:, k], pv)).ravel()
        np.testing.assert_allclose(out[:, k], expected, rtol=1e-12, atol=1e-12)


def test_rhs_is_finite_at_rest_and_symbolically_smooth_enough(model: KVLCC2) -> None:
    """No division by U or J_P at rest (the propeller still pushes), and the CasADi rhs has
    a finite Jacobian at cruise (NMPC and linearisation)."""
    x = model.initial_state()
    xdot = model.f_numpy(x, [0.0], [0.0, 0.0, 0.0], model.params.to_vector())
    assert np.all(np.isfinite(xdot)) and xdot[3] > 0.0
    xs = ca.SX.sym("x", model.n_states)
    jac = ca.Function(
        "j",
        [xs],
        [ca.jacobian(model.casadi_rhs(xs, [0.1], [0, 0, 0], model.params.to_vector()), xs)],
    )
    assert np.all(np.isfinite(np.array(jac(model.cruise_state()))))


def test_positive_rudder_turns_to_starboard(model: KVLCC2) -> None:
    """δ > 0 (MMG and project sign): Y_R < 0 at the stern, N_R > 0, r > 0; no sign flip."""
    x = model.cruise_state(delta=10.0 * DEG)
    xdot = model.f_numpy(x, [10.0 * DEG], [0.0, 0.0, 0.0], model.params.to_vector())
    assert xdot[model.state_index("r")] > 0.0
    assert xdot[model.state_index("v")] < 0.0  # the rudder's side force pushes the stern to port


def test_current_enters_through_the_water_relative_velocities(model: KVLCC2) -> None:
    """At r = 0 a ship moving (u_r, v_r) through a current has the accelerations of the same
    ship moving (u_r, v_r) in still water (a Galilean shift)."""
    pv = model.params.to_vector()
    psi, ur, vr = 0.4, 1.1, -0.05
    vc = np.array([0.2, -0.1])
    u_c = vc[0] * math.cos(psi) + vc[1] * math.sin(psi)
    v_c = -vc[0] * math.sin(psi) + vc[1] * math.cos(psi)
    still = model.f_numpy(
        model.initial_state(psi=psi, u=ur, v=vr, delta=0.1), [0.1], [0.0, 0.0, 0.0], pv
    )
    moving = model.f_numpy(
        model.initial_state(psi=psi, u=ur + u_c, v=vr + v_c, delta=0.1),
        [0.1],
        [vc[0], vc[1], 0.0],
        pv,
    )
    np.testing.assert_allclose(moving[3:], still[3:], rtol=1e-12, atol=1e-14)


def test_turning_circle_and_zigzags_pin_the_model(model: KVLCC2) -> None:
    """The default model's 35° turn and 10/10, 20/20 zig-zags (``FIGURES``) to 0.5 %: a
    regression pin of the equations and coefficients, not a claim about the real ship."""
    _, turn = turning_circle(model, 35.0)
    _, z10 = zigzag(model, 10.0)
    _, z20 = zigzag(model, 20.0)
    got = {
        "advance": turn["advance"] / model.length,
        "tactical_diameter": turn["tactical_diameter"] / model.length,
        "overshoot_10_1": z10["overshoot_1"],
        "overshoot_10_2": z10["overshoot_2"],
        "overshoot_20_1": z20["overshoot_1"],
        "overshoot_20_2": z20["overshoot_2"],
    }
    for key, value in FIGURES.items():
        assert got[key] == pytest.approx(value, rel=5e-3), key
    # port and starboard turns differ only by the asymmetric C2 and γ_R: within 1 %
    _, port = turning_circle(model, -35.0)
    assert port["tactical_diameter"] == pytest.approx(turn["tactical_diameter"], rel=0.01)
    assert port["steady_turn_rate"] < 0.0 < turn["steady_turn_rate"]


def test_froude_scaling_is_exact() -> None:
    """The 320 m ship's turning circle is the L7 model's ×λ (lengths) and ×√λ (times)."""
    small = KVLCC2()
    big = KVLCC2(full_scale())
    assert big.length == pytest.approx(320.0)
    assert big.nominal_speed == pytest.approx(small.nominal_speed * math.sqrt(FULL_SCALE))
    assert big.rudder_rate_limit == pytest.approx(2.32 * DEG, rel=1e-3)
    _, a = turning_circle(small, 35.0)
    _, b = turning_circle(big, 35.0)
    for key in ("advance", "transfer", "tactical_diameter"):
        assert b[key] == pytest.approx(a[key] * FULL_SCALE, rel=1e-6), key
    assert b["t_90"] == pytest.approx(a["t_90"] * math.sqrt(FULL_SCALE), rel=1e-6)
    assert b["steady_turn_rate"] == pytest.approx(
        a["steady_turn_rate"] / math.sqrt(FULL_SCALE), rel=1e-6
    )


@pytest.mark.parametrize(
    "changes",
    [{"L": 0.0}, {"w_P0": 1.0}, {"t_R": -0.1}, {"D_P": 0.5}, {"m_y": -0.1}, {"T_servo": 0.0}],
)
def test_non_physical_parameters_are_refused(changes: dict[str, float]) -> None:
    with pytest.raises(ParameterError):
        KVLCC2Params(**changes)


def test_no_straight_run_is_an_error() -> None:
    with pytest.raises(ParameterError, match="straight-run"):
        # a K_T that rises as fast as the resistance: thrust exceeds it at every speed
        _ = KVLCC2(KVLCC2Params(k_2=10.0)).nominal_speed
