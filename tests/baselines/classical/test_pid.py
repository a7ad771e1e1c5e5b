"""PID autopilot tunings (Xu & Guedes Soares 2020 §5; Xu, Oliveira & Guedes Soares 2021 §5.2)
and the pid_* baselines on LOS, look-ahead LOS, VF and TVVF guidance."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from shipgym.autopilot import (
    VYSHNEGRADSKY_AB_PRINTED,
    PIDGains,
    nomoto2_pd_characteristic,
    vyshnegradsky_gains,
    vyshnegradsky_parameters,
    vyshnegradsky_solutions,
)
from shipgym.guidance import tvvf_heading, vector_field_heading
from shipgym.identification.nominal import first_order_nomoto, second_order_nomoto
from shipgym.models.mariner import Mariner
from shipgym.models.nomoto2 import Nomoto2
from shipgym.scenarios.loader import scenario_from_dict
from shipgym_baselines.classical.pid import (
    PIDLOS,
    PIDTVVF,
    PIDVF,
    PIDLookaheadLOS,
    design_gains,
)
from shipgym_baselines.evaluation import evaluate

#: Esso Osaka 2nd-order Nomoto model identified by Xu & Guedes Soares (2020) §5.2
ESSO = {"K": 0.185, "T1": 7.8569, "T2": 0.3815, "T3": 0.5297}
NOMOTO2 = {"K": 0.5060, "T1": 1.2481, "T2": 0.1245, "T3": -0.0757}  # Liu et al. (2019) §4
CONTROLLERS = (PIDLOS, PIDLookaheadLOS, PIDVF, PIDTVVF)
MARINER_TRACK = Path(__file__).resolve().parents[3] / "configs/scenarios/mariner_track.yaml"


def _closed_loop(K: float, T1: float, T2: float, T3: float, kp: float, kd: float) -> np.ndarray:
    """s(T1s + 1)(T2s + 1) + K(1 + T3s)(Kp + Kd·s): plant K(1 + T3s)/(s(T1s + 1)(T2s + 1))
    under δ = Kp(ψd − ψ) − Kd·ψ̇, multiplied out independently of eq. (18)."""
    den = np.polymul([1.0, 0.0], np.polymul([T1, 1.0], [T2, 1.0]))
    return np.polyadd(den, K * np.polymul([T3, 1.0], [kd, kp]))


# ------------------------------------------------------------------ Vyshnegradsky diagram
@pytest.mark.parametrize("model", [ESSO, NOMOTO2], ids=["esso_osaka", "nomoto2"])
@pytest.mark.parametrize("ab", [(4.0, 4.0), (3.0, 3.0), (2.0, 6.0)])
def test_vyshnegradsky_gains_give_the_design_A_B(model: dict, ab: tuple[float, float]) -> None:
    g = vyshnegradsky_gains(**model, A=ab[0], B=ab[1])
    poly = _closed_loop(**model, kp=g.kp, kd=g.kd)
    np.testing.assert_allclose(poly, nomoto2_pd_characteristic(**model, kp=g.kp, kd=g.kd))
    np.testing.assert_allclose(vyshnegradsky_parameters(poly), ab, rtol=0, atol=1e-9)
    assert g.ki == pytest.approx(g.kp / 100.0, rel=1e-15)  # Ki = Kp/100 (§5.2)


def test_vyshnegradsky_4_4_poles_are_the_normalised_cubic_scaled() -> None:
    """q³ + 4q² + 4q + 1 = (q + 1)(q² + 3q + 1): poles ω0·{−1, (−3 ± √5)/2}."""
    g = vyshnegradsky_gains(**ESSO)
    poly = _closed_loop(**ESSO, kp=g.kp, kd=g.kd)
    w0 = (ESSO["K"] * g.kp / (ESSO["T1"] * ESSO["T2"])) ** (1.0 / 3.0)
    expected = w0 * np.array([-1.0, (-3.0 - math.sqrt(5.0)) / 2, (-3.0 + math.sqrt(5.0)) / 2])
    np.testing.assert_allclose(np.sort(np.roots(poly).real), np.sort(expected), rtol=1e-9)
    assert np.allclose(np.roots(poly).imag, 0.0)


def test_paper_printed_gains_are_the_3_3_design() -> None:
    """§5.2 prints "212.6 and 547.8" for the Esso Osaka model: eq. (21) reproduces them
    (as Kd, Kp, to the printed digits) with A = B = 3, not with the stated A = B = 4."""
    A, B = VYSHNEGRADSKY_AB_PRINTED
    assert (A, B) == (3.0, 3.0)
    printed = vyshnegradsky_gains(**ESSO, A=A, B=B)
    assert math.floor(printed.kp * 10) / 10 == pytest.approx(547.8)
    assert math.floor(printed.kd * 10) / 10 == pytest.approx(212.6)
    stated = vyshnegradsky_solutions(**ESSO)  # A = B = 4: one solution only
    assert len(stated) == 1
    assert stated[0] == pytest.approx((2167.54, 541.68), abs=0.01)
    # the printed pair read in eq. (17)'s order (Kp, Kd) is far from (4, 4)
    a, b = vyshnegradsky_parameters(nomoto2_pd_characteristic(**ESSO, kp=212.6, kd=547.8))
    assert a > 8.0 and b > 7.0


def test_vyshnegradsky_several_roots_smallest_first() -> None:
    sols = vyshnegradsky_solutions(**ESSO, A=5.0, B=5.0)
    assert len(sols) == 3
    assert [s[0] for s in sols] == sorted(s[0] for s in sols)
    for kp, kd in sols:
        poly = nomoto2_pd_characteristic(**ESSO, kp=kp, kd=kd)
        np.testing.assert_allclose(vyshnegradsky_parameters(poly), (5.0, 5.0), atol=1e-9)
    assert vyshnegradsky_gains(**ESSO, A=5.0, B=5.0).kp == pytest.approx(sols[0][0])


def test_vyshnegradsky_without_rudder_zero() -> None:
    """T3 = 0: eq. (21) is linear in x; the design still has (A, B) = (4, 4)."""
    g = vyshnegradsky_gains(K=0.2, T1=5.0, T2=0.5, T3=0.0)
    poly = nomoto2_pd_characteristic(0.2, 5.0, 0.5, 0.0, g.kp, g.kd)
    np.testing.assert_allclose(vyshnegradsky_parameters(poly), (4.0, 4.0), atol=1e-9)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"A": 0.5, "B": 1.5}, "AB > 1"),
        ({"A": -1.0, "B": 4.0}, "AB > 1"),
        ({"K": -0.1}, "K > 0"),
        ({"T2": 0.0}, "T2 > 0"),
        ({"ki_ratio": -1.0}, "ki_ratio"),
    ],
)
def test_vyshnegradsky_bad_input(kwargs: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        vyshnegradsky_gains(**{**ESSO, **kwargs})


# ------------------------------------------------------------------ pole placement
@pytest.mark.parametrize(("wn", "zeta"), [(1.0, 1.0), (0.8, 0.7), (0.3, 1.5)])
def test_pole_placement_places_the_pd_poles(wn: float, zeta: float) -> None:
    """Xu, Oliveira & Guedes Soares (2021) §5.2 gains on T·ṙ + r = Kδ: the PD loop
    T s² + (1 + K·Kd) s + K·Kp has its poles at −ζωn ± ωn√(ζ² − 1)."""
    K, T = first_order_nomoto(Nomoto2())
    g = PIDGains.from_nomoto(K, T, wn, zeta)
    assert g.ki == pytest.approx(wn**3 * T / (10.0 * K), rel=1e-12)  # Ki = ωn³T/(10K)
    poles = np.sort_complex(np.roots([T, 1.0 + K * g.kd, K * g.kp]))
    root = np.sqrt(complex(zeta**2 - 1.0))
    expected = np.sort_complex(np.array([-zeta * wn - wn * root, -zeta * wn + wn * root]))
    np.testing.assert_allclose(poles, expected, atol=1e-6 if zeta == 1.0 else 1e-12)
    # with the integral: T·(s³ + 2ζωn s² + ωn² s + ωn³/10), all poles in the left half plane
    pid_poly = np.array([T, 1.0 + K * g.kd, K * g.kp, K * g.ki])
    np.testing.assert_allclose(pid_poly / T, [1.0, 2 * zeta * wn, wn**2, wn**3 / 10], rtol=1e-12)
    assert np.all(np.roots(pid_poly).real < 0.0)


# ------------------------------------------------------------------ controllers
def test_default_tunings_and_nominal_models() -> None:
    assert [c().tuning for c in CONTROLLERS] == [
        "pole_placement",
        "vyshnegradsky",
        "vyshnegradsky",
        "pole_placement",
    ]
    assert second_order_nomoto(Nomoto2()) == pytest.approx(tuple(NOMOTO2.values()))
    K, T = first_order_nomoto(Nomoto2())
    assert design_gains(Nomoto2(), "pole_placement") == PIDGains.from_nomoto(K, T)
    assert design_gains(Nomoto2(), "vyshnegradsky") == vyshnegradsky_gains(**NOMOTO2)
    with pytest.raises(ValueError, match="tuning"):
        PIDVF(tuning="ziegler")
    # the mariner design comes from its zig-zag fit and still has (A, B) = (4, 4)
    fit = second_order_nomoto(Mariner())
    g = design_gains(Mariner(), "vyshnegradsky")
    poly = nomoto2_pd_characteristic(*fit, g.kp, g.kd)
    np.testing.assert_allclose(vyshnegradsky_parameters(poly), (4.0, 4.0), atol=1e-9)


def test_field_laws_use_the_scenario_parameters() -> None:
    scenario = scenario_from_dict(
        {
            "name": "vf_params",
            "ship": {"model": "nomoto2"},
            "path": {"type": "waypoints", "waypoints": [[0, 0], [40, 0]]},
            "guidance": {"vf_tau_L": 3.0, "vf_chi_e_deg": 60.0, "tvvf_delta_L": 1.5},
            "time_limit": 5.0,
        }
    )
    vf, tvvf = PIDVF(preset="paper"), PIDTVVF(preset="paper")  # tuned: the chosen settings
    evaluate(vf, scenario, [0])
    evaluate(tvvf, scenario, [0])
    L = vf.ctx.ship_length
    for e in (-5.0, -0.7, 0.2, 4.0):
        assert vf.desired_heading(e, 0.3) == vector_field_heading(e, 0.3, 3.0 * L, math.pi / 3)
        assert tvvf.desired_heading(e, 0.3) == tvvf_heading(e, 0.3, 1.5 * L)


def _mariner_track(time_limit: float) -> object:
    data = yaml.safe_load(MARINER_TRACK.read_text())
    data["time_limit"] = time_limit
    return scenario_from_dict(data)


@pytest.mark.parametrize("tuning", ["pole_placement", "vyshnegradsky"])
@pytest.mark.parametrize("cls", CONTROLLERS, ids=lambda c: c.name)
def test_controllers_follow_the_nominal_path(cls: type, tuning: str) -> None:
    """nomoto2 `nominal`: the goal is reached, |e| stays within 4 m (legs 14 m and 9 m with
    90° corners, a 0.95 m ship) and the ACE is well below doing nothing."""
    (result,) = evaluate(cls(tuning=tuning), "nominal", [0])
    m = result.metrics
    assert m["termination_reason"] == "goal"
    assert np.max(np.abs(result.trajectory["cross_track_error"])) < 4.0
    assert m["ace"] < 1.6
    assert m["controller_stats"]["pid_kp"] > 0 and m["controller_stats"]["pid_kd"] > 0


@pytest.mark.parametrize("tuning", ["pole_placement", "vyshnegradsky"])
@pytest.mark.parametrize("cls", CONTROLLERS, ids=lambda c: c.name)
def test_controllers_reach_the_mariner_track(cls: type, tuning: str) -> None:
    """mariner_track, first 300 s from 500 m off the first leg: the paper's design reaches
    the path within 160 s and |e| stays below twice the initial offset (the tuned
    lookahead, 2.6 L = 450 m, approaches a 500 m offset more gently)."""
    (result,) = evaluate(cls(tuning=tuning, preset="paper"), _mariner_track(300.0), [0])
    t = result.trajectory["t"]
    e = result.trajectory["cross_track_error"]
    assert np.all(np.isfinite(e))
    assert e[0] == pytest.approx(-500.0, abs=1.0)
    assert np.any(e[t <= 160.0] > 0.0)  # crossed the path
    assert np.max(np.abs(e)) < 1000.0


def test_pid_los_pole_placement_numbers_unchanged() -> None:
    """pid_los's paper preset keeps the old leaderboard numbers: ωn = 1 rad/s, ζ = 1."""
    (result,) = evaluate(PIDLOS(preset="paper"), "nominal", [0])  # the paper's design
    assert result.metrics["ace"] == pytest.approx(1.0298, abs=1e-3)


def test_every_guidance_parameter_and_design_setting_is_a_keyword() -> None:
    """The PID's keywords are exactly the design settings and the scenario's guidance
    parameters (so a misspelt setting is named before anything runs: the registry binds
    settings to the signature)."""
    import inspect

    from shipgym_baselines.classical.pid import GUIDANCE_SETTINGS, SETTINGS

    params = set(inspect.signature(PIDLOS).parameters) - {"preset"}
    assert params == set(SETTINGS) | set(GUIDANCE_SETTINGS)
    with pytest.raises(ValueError, match="preset"):
        PIDLOS(preset="best")


def test_paper_preset_is_the_literal_design_and_guidance_settings_reach_the_law() -> None:
    """preset='paper' ignores chosen settings; an explicit los_radius_L replaces the
    scenario's R_LOS in the controller's own reference, ψd = γp − arcsin(ye / R_LOS) (Liu et al.
    2019 eq. (9))."""
    import math

    from shipgym.envs.context import ControllerContext
    from shipgym.scenarios.loader import load_scenario

    ctx = ControllerContext.of(load_scenario("nominal"), "rudder")
    pid = PIDLOS(preset="paper", los_radius_L=5.0)
    pid.reset(ctx)
    paper = PIDLOS(preset="paper")
    paper.reset(ctx)
    assert pid.gains == paper.gains
    ye = 0.4 * ctx.ship_length
    assert pid.desired_heading(ye, 0.0) == pytest.approx(-math.asin(ye / (5.0 * ctx.ship_length)))
