"""The NMPC family's tuned settings (docs/tuning.md): weights as solver parameters, horizon and
weight factors over the ship rule, the measured drift angle, the family's one study."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shipgym.envs.context import ControllerContext
from shipgym.models.nomoto2 import Nomoto2, Nomoto2Params
from shipgym.scenarios.loader import load_scenario
from shipgym_baselines.classical import nmpc as nmpc_module
from shipgym_baselines.classical.nmpc import (
    NMPC,
    NMPCLambdaLSSVMSVF,
    NMPCSettings,
    NMPCSolver,
    get_solver,
    weight_vector,
)
from shipgym_baselines.classical.nmpc_ship import PAPER_Q, ship_plan

DEG = math.pi / 180.0


def test_the_cost_is_the_weighted_sum_of_squares_of_the_prediction() -> None:
    """Cost (16) evaluated by the compiled residual with weights passed as parameters equals
    the sum written out from the predicted states, for weights the solver was not built
    with (eq. (9) reference R = max(nL, |e| + L), input held after N_c)."""
    params = Nomoto2Params()
    solver = NMPCSolver(Nomoto2(params), NMPCSettings(compile=False), 0.5, 30 * DEG)
    settings = NMPCSettings(Q=(3.0, 0.2, 0.05, 0.002, 0.4), R=0.7)
    x0 = np.array([1.0, -2.0, 0.3, 0.02, 0.0, 0.05])
    leg, psip, radius = (0.5, -1.0), 0.2, 2.85
    p = solver.parameters(x0, leg, psip, radius, params.to_vector(), weight_vector(settings))
    plan = np.linspace(-20, 25, settings.control_horizon) * DEG
    states = solver.predict(plan, p)
    e = -(states[:, 0] - leg[0]) * math.sin(psip) + (states[:, 1] - leg[1]) * math.cos(psip)
    rel = np.arctan2(np.sin(states[:, 2] - psip), np.cos(states[:, 2] - psip))
    ref = -np.arcsin(e / np.maximum(radius, np.abs(e) + params.L))
    q = settings.Q
    expected = (
        q[0] * e @ e
        + q[1] * (rel - ref) @ (rel - ref)
        + q[2] * states[:, 3] @ states[:, 3]
        + q[3] * states[:, 4] @ states[:, 4]
        + q[4] * states[:, 5] @ states[:, 5]
        + settings.R * plan @ plan
    )
    assert solver.cost(plan, p) == pytest.approx(expected, rel=1e-12)
    # the solver's own weights (the paper's) when none are passed
    own = solver.parameters(x0, leg, psip, radius, params.to_vector())
    np.testing.assert_array_equal(own[-6:], np.sqrt([*PAPER_Q, 0.01]))


def test_settings_differing_only_in_weights_share_one_solver() -> None:
    model = Nomoto2(Nomoto2Params())
    a = get_solver(model, NMPCSettings(Q=(2.0, 1.0, 0.01, 0.01, 0.001), R=0.3), 0.5, 0.5)
    b = get_solver(model, NMPCSettings(), 0.5, 0.5)
    c = get_solver(model, NMPCSettings(horizon=9), 0.5, 0.5)
    assert a is b and c is not a


def test_bad_weights_and_factors_are_refused_by_name() -> None:
    with pytest.raises(ValueError, match="R=-1"):
        weight_vector(NMPCSettings(R=-1.0))
    with pytest.raises(ValueError, match="horizon_scale"):
        NMPC(horizon_scale=0.0)
    with pytest.raises(ValueError, match="rudder_weight"):
        NMPC(rudder_weight=math.nan)
    with pytest.raises(ValueError, match="not both"):
        NMPC(settings=NMPCSettings(), heading_weight=2.0)
    with pytest.raises(ValueError, match="preset"):
        NMPC(preset="best")


def test_horizon_scale_stretches_the_horizon_time_by_the_rule() -> None:
    """Paper ship: t_H = 4.75 s; ×2 → 9.5 s, so k = ⌈9.5 / 5⌉ = 2 periods per interval and
    N_p = ⌈9.5 / 1⌉ = 10; ×0.5 → 2.375 s: k = 1, N_p = 5, N_c = 5."""
    ctx = ControllerContext.of(load_scenario("nominal"), "rudder")
    plan = ship_plan(ctx, 2.0)
    assert (plan.interval, plan.horizon, plan.control_horizon) == (2, 10, 8)
    short = ship_plan(ctx, 0.5)
    assert (short.interval, short.horizon, short.control_horizon) == (1, 5, 5)
    with pytest.raises(ValueError, match="horizon_scale"):
        ship_plan(ctx, -1.0)


def test_the_family_reads_the_one_nmpc_study_and_paper_reads_none(monkeypatch) -> None:
    """A member without a study of its own reads ``nmpc``'s chosen section of its ship;
    explicit values win; the paper preset reads nothing (``shipgym reproduce liu2019``)."""
    asked: list[tuple[str, str]] = []
    chosen = {
        "horizon_scale": 2.0,
        "cross_track_weight": 4.0,
        "heading_weight": 0.5,
        "rudder_weight": 10.0,
        "drift_compensation": True,
    }

    def fake(controller: str, ship: str) -> dict:
        asked.append((controller, ship))
        return dict(chosen) if controller == "nmpc" else {}

    monkeypatch.setattr(nmpc_module, "tuned_settings", fake)
    ctx = ControllerContext.of(load_scenario("nominal"), "rudder")
    policy = NMPCLambdaLSSVMSVF(heading_weight=3.0)
    policy.reset(ctx, seed=0)
    assert asked == [("nmpc_lambda_lssvm_svf", "nomoto2"), ("nmpc", "nomoto2")]
    s = policy.settings
    assert s.Q == (4.0 * PAPER_Q[0], 3.0 * PAPER_Q[1], *PAPER_Q[2:])
    assert s.R == pytest.approx(0.1) and (s.interval, s.horizon) == (2, 10)
    assert policy.drift_compensation
    paper = NMPC(preset="paper")
    paper.reset(ctx, seed=0)
    assert paper.settings == NMPCSettings() and not paper.drift_compensation
    assert len(asked) == 2
    # a member with its own section reads that one only
    own = {"horizon_scale": 1.0, "rudder_weight": 2.0}
    monkeypatch.setattr(nmpc_module, "tuned_settings", lambda c, ship: dict(own))
    member = NMPCLambdaLSSVMSVF()
    member.reset(ctx, seed=0)
    assert member.settings.R == pytest.approx(0.02) and member.settings.Q == PAPER_Q


def test_the_controller_s_weights_reach_the_shared_solver() -> None:
    """Two controllers sharing one compiled solver plan with their own weights: a 100×
    rudder weight gives a smaller first command from the same state (5 cm right of the
    first leg, (1, 1) → (15, 1), on its heading)."""
    ctx = ControllerContext.of(load_scenario("nominal"), "rudder")
    info = {
        "t": 0.0,
        "heading": 0.0,
        "yaw_rate": 0.0,
        "rudder_angle": 0.0,
        "position": (2.0, 0.95),
    }
    plain, heavy = NMPC(preset="paper"), NMPC(preset="paper", rudder_weight=100.0)
    plain.reset(ctx, seed=0)
    heavy.reset(ctx, seed=0)
    assert plain.solver is heavy.solver
    obs = np.zeros(9, dtype=np.float32)
    gentle, firm = float(heavy.act(obs, info)[0]), float(plain.act(obs, info)[0])
    assert 0 < gentle < 0.5 * firm


def test_drift_compensation_predicts_the_course(monkeypatch) -> None:
    """With compensation the solver's initial heading is ψ + β, β the measured drift angle
    over the last period (classical.drift); without it, ψ."""
    ctx = ControllerContext.of(load_scenario("nominal"), "rudder")
    seen: list[float] = []

    def run(compensate: bool) -> None:
        policy = NMPC(preset="paper", drift_compensation=compensate)
        policy.reset(ctx, seed=0)
        original = policy.solver.parameters

        def spy(x0, *args):
            seen.append(float(x0[2]))
            assert args[-1] is policy.weights  # the controller's weights reach the solver
            return original(x0, *args)

        monkeypatch.setattr(policy.solver, "parameters", spy)
        obs = np.zeros(9, dtype=np.float32)
        # heading 0 both steps; the ship moved 1 m along x and 0.1 m across: β = atan2(0.1, 1)
        base = {"t": 0.0, "heading": 0.0, "yaw_rate": 0.0, "rudder_angle": 0.0}
        policy.act(obs, {**base, "position": (0.0, -1.0)})
        policy.act(obs, {**base, "t": 0.5, "position": (1.0, -0.9)})
        monkeypatch.undo()  # the solver is shared by the next run

    run(True)
    assert seen == [0.0, pytest.approx(math.atan2(0.1, 1.0))]
    seen.clear()
    run(False)
    assert seen == [0.0, 0.0]
