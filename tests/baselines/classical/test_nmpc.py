"""NMPC of Liu et al. (2019) §2.2.3 and its adaptive variants (issue: NMPC + λ-LS-SVM)."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

from shipgym.models.nomoto2 import Nomoto2, Nomoto2Params
from shipgym.scenarios.loader import scenario_from_dict
from shipgym_baselines.classical.nmpc import NMPC, NMPCLambdaLSSVM, NMPCSettings, NMPCSolver
from shipgym_baselines.evaluation import evaluate, run_episode

DEG = math.pi / 180.0


def test_open_loop_prediction_equals_the_simulator() -> None:
    """Same model, same RK4 at the same step (h = 0.01 s): prediction = env, to 1e-9."""
    params = Nomoto2Params()
    settings = NMPCSettings(prediction_substeps=50, compile=False)
    solver = NMPCSolver(Nomoto2(params), settings, 0.5, 30 * DEG)
    env = gym.make("ShipPathFollow-v0", scenario="nominal")
    env.reset(seed=0)
    inner = env.unwrapped
    x0 = inner._state.x.copy()
    fractions = np.array([0.25, -0.125, 0.75, 0.0, -1.0, 0.5, 0.125, -0.375], dtype=np.float32)
    plan = fractions.astype(float) * 30 * DEG  # exactly what the float32 action becomes
    p = solver.parameters(x0, (1.0, 1.0), 0.0, 2.85, params.to_vector())
    predicted = solver.predict(plan, p)
    for i in range(settings.horizon):
        env.step(fractions[min(i, 7)][None])
        np.testing.assert_allclose(predicted[i], inner._state.x, rtol=0, atol=1e-9)


def test_default_prediction_is_close_to_the_simulator() -> None:
    """10 RK4 substeps per period (h = 0.05 s): the discretisation error stays small."""
    params = Nomoto2Params()
    coarse = NMPCSolver(Nomoto2(params), NMPCSettings(compile=False), 0.5, 30 * DEG)
    fine = NMPCSolver(
        Nomoto2(params), NMPCSettings(prediction_substeps=50, compile=False), 0.5, 30 * DEG
    )
    x0 = np.array([0.0, 0.0, 0.1, 0.05, 0.0, 0.1])
    p = coarse.parameters(x0, (0.0, 0.0), 0.0, 2.85, params.to_vector())
    plan = np.full(8, 20 * DEG)
    assert np.max(np.abs(coarse.predict(plan, p) - fine.predict(plan, p))) < 1e-4


def straight_leg(offset: float = 1.0) -> object:
    return scenario_from_dict(
        {
            "name": "straight_leg",
            "path": {"waypoints": [[0, 0], [60, 0]]},
            "initial_state": {"x": 0.0, "y": -offset},
            "ship": {"model": "nomoto2", "params": {}},
            "time_limit": 40.0,
        }
    )


def test_nmpc_with_true_model_converges_on_a_straight_leg() -> None:
    """From 1 m off the leg, |e| < 0.05 m from t = 10 s on, and |δc| ≤ 30° at every step."""
    policy = NMPC(preset="paper")
    result = run_episode(policy, straight_leg(), seed=0)
    tr = result.trajectory
    after = tr["t"] >= 10.0
    assert np.all(np.abs(tr["cross_track_error"][after]) < 0.05)
    assert np.all(np.abs(tr["rudder_command"]) <= 30 * DEG + 1e-12)
    assert policy.failures == 0


def test_diverging_identified_model_falls_back_to_the_last_good_model() -> None:
    """NaN "identified" parameters: the solve is redone with the last model that worked."""

    class BrokenModel(NMPC):
        name = "nmpc_broken_model"

        def act(self, obs, info):
            if info["t"] >= 2.0:
                self.params = _NaNParams(self.ctx.nominal_params)
            return super().act(obs, info)

    policy, commands = _run_steps(BrokenModel(), 12)
    assert policy.model_fallbacks == 12 - 4 and policy.failures == 0
    assert all(math.isfinite(c) and abs(c) <= 1.0 for c in commands)


def test_solver_failure_falls_back_to_the_shifted_plan() -> None:
    """A NaN state makes every solve fail: no crash, shifted last plan, failures counted."""

    class BrokenSensor(NMPC):
        name = "nmpc_broken_sensor"

        def _state(self, info):
            x0 = super()._state(info)
            if info["t"] >= 2.0:
                x0[:] = np.nan
            return x0

    shifted = []

    def check(policy, before):
        if policy.last_t >= 2.0:
            shifted.append(np.array_equal(policy.plan, np.append(before[1:], before[-1])))

    policy, commands = _run_steps(BrokenSensor(preset="paper"), 12, check)  # 1-period intervals
    assert policy.failures == 12 - 4 and all(shifted) and len(shifted) == 8
    assert all(math.isfinite(c) and abs(c) <= 1.0 for c in commands)
    assert policy.episode_stats()["solver_failures"] == 8.0


def _run_steps(policy, n, check=None):
    env = gym.make("ShipPathFollow-v0", scenario=straight_leg())
    obs, info = env.reset(seed=0)
    policy.reset(env.unwrapped.controller_context, 0)
    commands = []
    for _ in range(n):
        before = policy.plan.copy()
        policy.last_t = info["t"]
        action = policy.act(obs, info)
        commands.append(float(action[0]))
        if check is not None:
            check(policy, before)
        obs, _, _, _, info = env.step(action)
    return policy, commands


class _NaNParams:
    """Stands in for a parameter record whose values are NaN."""

    def __init__(self, record: Nomoto2Params) -> None:
        self._record = record

    def to_vector(self) -> np.ndarray:
        return np.full(len(self._record.names()), np.nan)

    def as_dict(self) -> dict[str, float]:
        return dict.fromkeys(self._record.names(), math.nan)


def test_lambda_lssvm_beats_plain_nmpc_on_current_shift() -> None:
    """Case 2 (d0 jump) on the long-leg path, where tracking after the change (not the
    corner overshoot of the 0.95 m ship, README) decides ACE: adaptation lowers it."""
    plain = evaluate("nmpc", "current_shift_long", [0])[0].metrics["ace"]
    adaptive = evaluate("nmpc_lambda_lssvm", "current_shift_long", [0])[0].metrics["ace"]
    assert adaptive < 0.95 * plain


def test_identifier_tracks_what_the_data_can_identify() -> None:
    """After the d0 jump the steady-state rudder −d0/K is identified; d0 itself needs
    persistent excitation (eq. (45)): without it K and d0 drift together on straight legs."""
    true_ratio = 4.0 / 0.506  # deg: −d0/K after the change
    plain = NMPCLambdaLSSVM(preset="paper")  # σ = 0
    run_episode(plain, "current_shift_long", seed=0)
    ratio = -plain.identifier.params.d0 / plain.identifier.params.K / DEG
    assert ratio == pytest.approx(true_ratio, rel=0.25)
    excited = NMPCLambdaLSSVM(excitation_deg=2.0, preset="paper")
    run_episode(excited, "current_shift_long", seed=0)
    assert excited.identifier.params.d0 == pytest.approx(-4.0 * DEG, rel=0.05)
    assert excited.identifier.params.K == pytest.approx(0.506, rel=0.05)


def test_nmpc_refuses_guidance_mode() -> None:
    env = gym.make("ShipPathFollow-v0", action_mode="guidance")
    env.reset(seed=0)
    with pytest.raises(ValueError, match="rudder"):
        NMPC().reset(env.unwrapped.controller_context, 0)


def test_svf_controllers_are_registered_for_every_ship() -> None:
    from shipgym_baselines.registry import CONTROLLERS

    for name in ("nmpc_lambda_lssvm_svf", "nmpc_wlssvm_svf"):
        record = CONTROLLERS[name]
        assert record.applies_to is None and record.action_mode == "rudder"
        policy = record.factory()
        assert policy.identifier_options == {"front_end": "svf"}


def test_svf_front_end_restores_the_adaptive_advantage_in_case3() -> None:
    """Case 3 (heading noise σ = 0.2° and outliers), 3 seeds: the mean ACE of each
    ``*_svf`` controller is below half that of non-adaptive ``nmpc`` (measured 0.53 and
    0.80 m against 3.53 m), where the paper's differences leave λ-LS-SVM worse than ``nmpc``."""
    from shipgym_baselines.classical.nmpc import NMPCLambdaLSSVMSVF, NMPCWeightedLSSVMSVF
    from shipgym_baselines.evaluation import EVAL_SEED_OFFSET

    def mean_ace(cls) -> float:
        return float(
            np.mean(
                [
                    run_episode(cls(), "maneuverability_change", EVAL_SEED_OFFSET + i).metrics[
                        "ace"
                    ]
                    for i in range(3)
                ]
            )
        )

    plain = mean_ace(NMPC)
    for cls in (NMPCLambdaLSSVMSVF, NMPCWeightedLSSVMSVF):
        assert mean_ace(cls) < 0.5 * plain, cls.name
