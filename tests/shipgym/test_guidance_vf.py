"""Vector-field guidance: VF (Xu & Guedes Soares 2020 Algorithm 1) and time-varying VF (Xu,
Oliveira & Guedes Soares 2021 eqs. (9), (48)) — closed forms, the θ ≡ 1 ↔ look-ahead LOS
identity, convergence of a kinematic ship, float/array bit identity, env dispatch."""

from __future__ import annotations

import math
import warnings

import gymnasium as gym
import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

import shipgym  # noqa: F401
from shipgym.angles import wrap_angle
from shipgym.autopilot import HeadingPID, PIDGains
from shipgym.envs.core import GUIDANCE_OFFSET_MAX
from shipgym.guidance import (
    lookahead_los_heading,
    tvvf_heading,
    tvvf_theta,
    vector_field_heading,
)
from shipgym.identification.nominal import first_order_nomoto
from shipgym.scenarios.loader import ScenarioError, load_scenario, scenario_from_dict

HALF_PI = math.pi / 2

# --------------------------------------------------------------------------------------------
# VF, Algorithm 1: χf = 0.3, τ = 2, χe = π/2 unless stated
# --------------------------------------------------------------------------------------------


def test_vf_on_the_path_gives_the_path_angle() -> None:
    assert vector_field_heading(0.0, 0.3, 2.0) == 0.3
    assert vector_field_heading(0.0, 0.3, 2.0, k=3.0, sideslip=0.1) == 0.3 - 0.1


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_vf_inside_the_transition_region(sign: float) -> None:
    # χd = χf − ρχe(|ye|/τ)^k: ye = ±1, τ = 2 → |ye|/τ = ½
    assert vector_field_heading(sign * 1.0, 0.3, 2.0) == pytest.approx(0.3 - sign * math.pi / 4)
    assert vector_field_heading(sign * 1.0, 0.3, 2.0, k=2.0) == pytest.approx(
        0.3 - sign * math.pi / 8
    )
    assert vector_field_heading(
        sign * 1.0, 0.3, 2.0, entry_angle=math.pi / 3, k=3.0, sideslip=0.05
    ) == pytest.approx(0.3 - sign * (math.pi / 3) / 8 - 0.05)


@pytest.mark.parametrize("k", [1.0, 1.5, 4.0])
@pytest.mark.parametrize("entry", [HALF_PI, math.radians(45.0)])
def test_vf_outside_is_exactly_the_entry_angle(k: float, entry: float) -> None:
    """|ye| ≥ τ (lines 8–11): χd = χf ∓ χe exactly, from the boundary |ye| = τ outwards."""
    for e in (2.0, 2.0 + 1e-12, 3.0, 1e6, math.inf):
        assert vector_field_heading(e, 0.3, 2.0, entry, k) == 0.3 - entry
        assert vector_field_heading(-e, 0.3, 2.0, entry, k) == 0.3 + entry
    # just inside: strictly less than the entry angle, and continuous at the boundary
    inner = vector_field_heading(2.0 - 1e-9, 0.3, 2.0, entry, k)
    assert 0.3 - entry < inner < 0.3 - entry + 1e-8 * k


def test_vf_steers_towards_the_path_on_both_sides() -> None:
    """ė = U sin(χd − χf) (paths.py convention) has the sign of −ye: |ye| decreases."""
    e = np.linspace(-10.0, 10.0, 2001)
    for chi_f in (0.0, 2.5, -3.0):
        psi_d = vector_field_heading(e, chi_f, 2.0, k=2.0)
        e_dot = np.sin(psi_d - chi_f)
        assert np.all(e_dot[e != 0.0] * e[e != 0.0] < 0.0)
        assert np.all(e_dot[e == 0.0] == 0.0)


def test_vf_wraps_to_minus_pi_pi() -> None:
    out = vector_field_heading(-3.0, math.pi - 0.1, 2.0)
    assert out == pytest.approx(math.pi - 0.1 + HALF_PI - 2 * math.pi)
    assert -math.pi <= out < math.pi


def test_vf_course_feedforward_is_the_course_rate_of_the_field() -> None:
    """Line 16: ψd = χd − χ̇d/α with χ̇d = (∂χd/∂ye)·U sin(χ − χf) (Nelson et al. 2007)."""
    tau, chi_e, k, alpha, speed, chi_f = 2.0, HALF_PI, 2.0, 0.5, 1.2, 0.3
    course = chi_f + 0.4
    for e in (1.0, -0.7, 1.9):
        h = 1e-6
        dchi_de = (
            vector_field_heading(e + h, chi_f, tau, chi_e, k)
            - vector_field_heading(e - h, chi_f, tau, chi_e, k)
        ) / (2 * h)
        chi_d_rate = dchi_de * speed * math.sin(course - chi_f)
        got = vector_field_heading(
            e, chi_f, tau, chi_e, k, course_gain=alpha, speed=speed, course=course
        )
        assert got == pytest.approx(
            vector_field_heading(e, chi_f, tau, chi_e, k) + chi_d_rate / alpha
        )
    # hand value at ye = 1: (kχeU/(ατ))(|ye|/τ)^(k−1) sin 0.4 = (π·1.2/1)·½·sin 0.4
    ff = math.pi * 1.2 * 0.5 * math.sin(0.4)
    got = vector_field_heading(
        1.0, chi_f, tau, chi_e, k, course_gain=alpha, speed=speed, course=course
    )
    assert got == pytest.approx(chi_f - math.pi / 8 - ff)
    # outside the transition region there is no term (line 11)
    out = vector_field_heading(
        5.0, chi_f, tau, chi_e, k, course_gain=alpha, speed=speed, course=course
    )
    assert out == chi_f - chi_e


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"tau": 0.0}, "tau"),
        ({"tau": np.array([1.0, -1.0])}, "tau"),
        ({"entry_angle": HALF_PI + 1e-9}, "entry_angle"),
        ({"entry_angle": 0.0}, "entry_angle"),
        ({"k": 0.5}, "k"),
        ({"course_gain": 1.0}, "course"),
        ({"course_gain": 0.0, "course": 0.0}, "course_gain"),
    ],
)
def test_vf_rejects_bad_parameters(kwargs: dict, match: str) -> None:
    args = {"cross_track": 1.0, "path_angle": 0.0, "tau": 2.0, **kwargs}
    with pytest.raises(ValueError, match=match):
        vector_field_heading(**args)


# --------------------------------------------------------------------------------------------
# TVVF, eqs. (9), (48): γp = 0.3, Δ = 2
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_tvvf_hand_values(sign: float) -> None:
    # θ(2) = 0.05·2 + 1 = 1.1: χd = γp ∓ atan(2^1.1 / 2)
    assert tvvf_theta(sign * 2.0) == pytest.approx(1.1)
    want = 0.3 - sign * math.atan(2.0**1.1 / 2.0)
    assert tvvf_heading(sign * 2.0, 0.3, 2.0) == pytest.approx(want, rel=1e-15)
    # θ(10) = 1.5: 10^1.5 / 2 = 15.81…
    assert tvvf_heading(sign * 10.0, 0.3, 2.0) == pytest.approx(0.3 - sign * math.atan(10**1.5 / 2))
    # a given θ and sideslip
    assert tvvf_heading(sign * 3.0, 0.3, 2.0, theta=2.0, sideslip=0.1) == pytest.approx(
        0.3 - sign * math.atan(4.5) - 0.1
    )
    assert tvvf_heading(0.0, 0.3, 2.0) == 0.3


def test_tvvf_theta_one_is_lookahead_los_to_machine_precision() -> None:
    """The remark after Definition 1: θ ≡ 1 gives the look-ahead LOS of Xu (2020) eq. (6)."""
    rng = np.random.default_rng(5)
    for e, chi_f, delta in zip(
        rng.normal(0.0, 20.0, 500),
        rng.uniform(-math.pi, math.pi, 500),
        rng.uniform(0.1, 50, 500),
        strict=True,
    ):
        los = lookahead_los_heading(e, chi_f, delta, sideslip=0.02)
        vf = tvvf_heading(e, chi_f, delta, theta=1.0, sideslip=0.02)
        assert abs(wrap_angle(vf - los)) <= 2 * math.ulp(math.pi)


def test_tvvf_saturates_without_overflow_warnings() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert tvvf_heading(1e4, 0.3, 2.0) == 0.3 - HALF_PI  # 1e4^501 overflows → atan(inf)
        assert tvvf_heading(-1e4, 0.3, 2.0) == 0.3 + HALF_PI
        out = tvvf_heading(np.array([1e4, -1e4, 0.0]), 0.3, 2.0)
    np.testing.assert_array_equal(out, [0.3 - HALF_PI, 0.3 + HALF_PI, 0.3])


def test_tvvf_error_unit() -> None:
    """ye and Δ measured in ship lengths: θ = 0.05|ye/L| + 1, |ye/L|^θ / (Δ/L)."""
    L = 150.0
    e, delta = 30.0, 2 * L
    theta = 0.05 * (e / L) + 1.0
    want = 0.3 - math.atan((e / L) ** theta / (delta / L))
    assert tvvf_heading(e, 0.3, delta, error_unit=L) == pytest.approx(want)
    # in metres (the paper) the same ship is steered much harder: θ(30 m) = 2.5
    assert tvvf_heading(e, 0.3, delta) == pytest.approx(0.3 - math.atan(30.0**2.5 / delta))
    # θ ≡ 1 does not depend on the unit
    assert tvvf_heading(e, 0.3, delta, theta=1.0, error_unit=L) == pytest.approx(
        tvvf_heading(e, 0.3, delta, theta=1.0), abs=1e-15
    )


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"delta": 0.0}, "delta"),
        ({"theta": 0.9}, "theta"),
        ({"theta": np.array([1.0, 0.5])}, "theta"),
        ({"theta_slope": -0.01}, "slope"),
        ({"theta_offset": 0.5}, "offset"),
        ({"error_unit": 0.0}, "error_unit"),
    ],
)
def test_tvvf_rejects_bad_parameters(kwargs: dict, match: str) -> None:
    args = {"cross_track": 1.0, "path_angle": 0.0, "delta": 2.0, **kwargs}
    with pytest.raises(ValueError, match=match):
        tvvf_heading(**args)


# --------------------------------------------------------------------------------------------
# Float and array evaluation: bit for bit
# --------------------------------------------------------------------------------------------


def test_float_and_array_results_are_bit_identical() -> None:
    """The batched env evaluates the laws over N ships; each element must equal the float
    evaluation exactly (math.atan / math.pow would differ from numpy in the last bit)."""
    rng = np.random.default_rng(11)
    n = 3000
    e = np.concatenate(
        [rng.normal(0.0, 3.0, n - 8), [0.0, -0.0, 2.0, -2.0, 1e4, -1e4, 1e-300, 60.0]]
    )
    chi_f = rng.uniform(-math.pi, math.pi, n)
    chi_f[:4] = [-math.pi, math.pi - 1e-16, 3.1, -3.1]
    length = rng.uniform(1.0, 4.0, n)  # per-ship τ, Δ (the action scales them per ship)
    beta = rng.normal(0.0, 0.05, n)
    course = chi_f + rng.normal(0.0, 0.3, n)
    cases = [
        (vector_field_heading, {}, {}),
        (vector_field_heading, {"entry_angle": 1.0, "k": 2.5}, {}),
        (
            vector_field_heading,
            {"k": 2.0, "course_gain": 0.7},
            {"sideslip": beta, "speed": np.abs(beta) * 20, "course": course},
        ),
        (tvvf_heading, {}, {"sideslip": beta}),
        (tvvf_heading, {"error_unit": 1.7, "theta_slope": 0.2}, {}),
        (tvvf_heading, {}, {"theta": 1.0 + np.abs(beta)}),
    ]
    for law, fixed, per_ship in cases:
        batch = law(e, chi_f, length, **fixed, **per_ship)
        assert isinstance(batch, np.ndarray) and batch.shape == (n,)
        singles = [
            law(
                float(e[i]),
                float(chi_f[i]),
                float(length[i]),
                **fixed,
                **{key: float(v[i]) for key, v in per_ship.items()},
            )
            for i in range(n)
        ]
        assert all(type(s) is float for s in singles)
        np.testing.assert_array_equal(batch, np.array(singles), err_msg=f"{law.__name__} {fixed}")
        assert np.all((batch >= -math.pi) & (batch < math.pi))


# --------------------------------------------------------------------------------------------
# Convergence of a kinematic ship: ẋ = U cos ψ, ẏ = U sin ψ, ψ̇ = −(ψ − ψd)/Tψ
# --------------------------------------------------------------------------------------------
L_SHIP, SPEED = 0.95, 0.8  # the nomoto2 scale ship of Liu et al. (2019)
T_PSI = 0.5 * L_SHIP / SPEED  # heading response time constant
CHI_F = 2.0  # a path not aligned with an axis
TOL = 0.05 * L_SHIP


def _ideal_time(rate) -> float:
    """Time for |ye| to go from 5L to 0.05L if ψ ≡ ψd: ∫ d|ye| / |ẏe(|ye|)|."""
    return quad(lambda y: 1.0 / rate(y), TOL, 5 * L_SHIP, limit=200, points=[2 * L_SHIP])[0]


TAU = DELTA = 2 * L_SHIP
LAWS = {
    # name: (law ψd(ye), |ẏe|(|ye|) of the ideal closed loop, exponential?)
    "vf": (
        lambda e: vector_field_heading(e, CHI_F, TAU),
        lambda y: SPEED * math.sin(HALF_PI * min(y / TAU, 1.0)),
        True,
    ),
    "vf_k2": (
        lambda e: vector_field_heading(e, CHI_F, TAU, k=2.0),
        lambda y: SPEED * math.sin(HALF_PI * min(y / TAU, 1.0) ** 2),
        False,
    ),
    # eq. (A3): ẏe = −sgn(ye)·U|ye|^θ / sqrt(Δ² + |ye|^2θ), θ = 0.05|ye| + 1
    "tvvf": (
        lambda e: tvvf_heading(e, CHI_F, DELTA),
        lambda y: SPEED * y ** (0.05 * y + 1) / math.sqrt(DELTA**2 + y ** (2 * (0.05 * y + 1))),
        True,
    ),
    "tvvf_theta1": (
        lambda e: tvvf_heading(e, CHI_F, DELTA, theta=1.0),
        lambda y: SPEED * y / math.sqrt(DELTA**2 + y * y),
        True,
    ),
}


@pytest.mark.parametrize("side", [1.0, -1.0])
@pytest.mark.parametrize("name", list(LAWS))
def test_kinematic_ship_converges_to_a_straight_line(name: str, side: float) -> None:
    """From 5L off the line, parallel to it, |ye| < 0.05L from the ideal (ψ ≡ ψd) convergence
    time plus 5 heading time constants on, and — for the laws linear near the path — the
    error then decays exponentially (|ye| < 1e-6 L at 80 L/U)."""
    law, rate, exponential = LAWS[name]
    sin_f, cos_f = math.sin(CHI_F), math.cos(CHI_F)

    def cross_track(x: float, y: float) -> float:
        return -x * sin_f + y * cos_f  # paths.py convention, line through the origin

    def rhs(_t: float, s: np.ndarray) -> list[float]:
        x, y, psi = s
        psi_d = law(cross_track(x, y))
        return [SPEED * math.cos(psi), SPEED * math.sin(psi), -wrap_angle(psi - psi_d) / T_PSI]

    e0 = side * 5 * L_SHIP
    t_end = 80 * L_SHIP / SPEED
    sol = solve_ivp(
        rhs,
        (0.0, t_end),
        [-e0 * sin_f, e0 * cos_f, CHI_F],
        max_step=0.05 * L_SHIP / SPEED,
        rtol=1e-9,
        atol=1e-12,
        dense_output=True,
    )
    assert sol.success
    t = np.linspace(0.0, t_end, 8001)
    xy = sol.sol(t)
    e = -xy[0] * sin_f + xy[1] * cos_f
    assert e[0] == pytest.approx(e0)
    t_conv = _ideal_time(rate) + 5 * T_PSI
    assert t_conv < t_end
    assert np.max(np.abs(e[t >= t_conv])) < TOL, f"{name}: not within 0.05L after {t_conv:.1f} s"
    if exponential:
        assert abs(e[-1]) < 1e-6 * L_SHIP
    else:  # k = 2: ẏe ∝ −ye² near the path, only algebraic decay
        assert abs(e[-1]) > 1e-3 * L_SHIP


# --------------------------------------------------------------------------------------------
# Scenario schema and the env's guidance mode
# --------------------------------------------------------------------------------------------


def _nominal(guidance: dict) -> dict:
    data = load_scenario("nominal").config.model_dump()
    data["name"] = "nominal_field"
    data["guidance"] = guidance
    return data


@pytest.mark.parametrize(
    ("guidance", "key"),
    [
        ({"law": "pure_pursuit"}, "guidance.law"),
        ({"law": "vf", "vf_chi_e_deg": 91.0}, "guidance.vf_chi_e_deg"),
        ({"law": "vf", "vf_k": 0.5}, "guidance.vf_k"),
        ({"law": "vf", "vf_tau_L": 0.0}, "guidance.vf_tau_L"),
        ({"law": "tvvf", "tvvf_delta_L": -1.0}, "guidance.tvvf_delta_L"),
        ({"law": "tvvf", "tvvf_theta_offset": 0.9}, "guidance.tvvf_theta_offset"),
        ({"law": "tvvf", "tvvf_theta_slope": -0.1}, "guidance.tvvf_theta_slope"),
        ({"law": "tvvf", "tvvf_error_unit": "ft"}, "guidance.tvvf_error_unit"),
    ],
)
def test_guidance_config_rejects_bad_values(guidance: dict, key: str) -> None:
    with pytest.raises(ScenarioError, match=key.replace(".", r"\.")):
        scenario_from_dict(_nominal(guidance))


def test_guidance_config_defaults_are_the_papers() -> None:
    g = scenario_from_dict(_nominal({"law": "tvvf"})).config.guidance
    assert (g.vf_tau_L, g.vf_chi_e_deg, g.vf_k) == (2.0, 90.0, 1.0)
    assert (g.tvvf_delta_L, g.tvvf_theta_slope, g.tvvf_theta_offset) == (2.0, 0.05, 1.0)
    assert g.tvvf_error_unit == "m"


@pytest.mark.parametrize(
    ("guidance", "law"),
    [
        ({"law": "vf"}, lambda e, chi, L, s: vector_field_heading(e, chi, 2 * L * s)),
        (
            {"law": "vf", "vf_tau_L": 3.0, "vf_chi_e_deg": 60.0, "vf_k": 2.0},
            lambda e, chi, L, s: vector_field_heading(e, chi, 3 * L * s, math.pi / 3, 2.0),
        ),
        ({"law": "tvvf"}, lambda e, chi, L, s: tvvf_heading(e, chi, 2 * L * s)),
        (
            {"law": "tvvf", "tvvf_error_unit": "L", "tvvf_theta_slope": 0.1},
            lambda e, chi, L, s: tvvf_heading(e, chi, 2 * L * s, theta_slope=0.1, error_unit=L),
        ),
    ],
)
def test_env_guidance_mode_uses_the_law(guidance: dict, law) -> None:
    """δc = PID(ψd(ye; 2^a0·length scale) + a1·30°) on the measured heading."""
    env = gym.make(
        "ShipPathFollow-v0", scenario=scenario_from_dict(_nominal(guidance)), action_mode="guidance"
    ).unwrapped
    _, info = env.reset(seed=0)
    L = env.scenario.ship_length
    gains = PIDGains.from_nomoto(*first_order_nomoto(env.model, env.scenario.nominal_params))
    pid = HeadingPID(gains, env.model.rudder_limit)
    for a0, a1 in [(0.0, 0.0), (0.5, -0.25), (-1.0, 1.0)]:  # exact in float32
        frame = env.frame
        desired = law(frame.cross_track, frame.path_angle, L, 2.0**a0) + a1 * GUIDANCE_OFFSET_MAX
        want = pid.command(desired, info["heading"], info["yaw_rate"], env.scenario.control_period)
        *_, info = env.step(np.array([a0, a1], dtype=np.float32))
        assert info["rudder_command"] == pytest.approx(want, rel=1e-12, abs=1e-15)


@pytest.mark.parametrize("law", ["vf", "tvvf"])
def test_env_follows_the_nominal_path_with_the_plain_law(law: str) -> None:
    """With a zero action (the law as configured) the ship passes all waypoints of the
    nominal path within its time limit, never leaving the 10L corridor."""
    env = gym.make(
        "ShipPathFollow-v0",
        scenario=scenario_from_dict(_nominal({"law": law})),
        action_mode="guidance",
    )
    env.reset(seed=0)
    terminated = truncated = False
    while not (terminated or truncated):
        *_, terminated, truncated, info = env.step(np.zeros(2, dtype=np.float32))
    assert info["termination_reason"] == "goal"
