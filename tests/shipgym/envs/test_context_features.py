"""The optional controller-context observation features: what the classical controllers
are designed from (docs/observation.md)."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import shipgym
from shipgym.envs import core
from shipgym.envs.path_follow import ShipPathFollowEnv
from shipgym.envs.vector import ShipPathFollowVectorEnv
from shipgym.scenarios.loader import load_scenario, nominal_nomoto
from shipgym.scenarios.sampling import load_distribution, train_rng


def _steps(env: gym.Env, n: int, seed: int = 0) -> list[np.ndarray]:
    obs, _ = env.reset(seed=seed)
    out = [obs]
    rng = np.random.default_rng(seed)
    for _ in range(n):
        obs, *_ = env.step(rng.uniform(-1, 1, env.action_space.shape).astype(np.float32))
        out.append(obs)
    return out


def test_default_observation_unchanged_and_context_appended() -> None:
    plain = gym.make("ShipPathFollow-v0", scenario="rudder_aging")
    rich = gym.make("ShipPathFollow-v0", scenario="rudder_aging", context_features=True)
    assert plain.observation_space.shape == (len(core.OBS_NAMES),)
    assert rich.observation_space.shape == (len(core.OBS_NAMES) + len(core.CONTEXT_NAMES),)
    assert core.observation_names(True)[-len(core.CONTEXT_NAMES) :] == core.CONTEXT_NAMES
    for a, b in zip(_steps(plain, 30), _steps(rich, 30), strict=True):
        np.testing.assert_array_equal(a, b[: len(core.OBS_NAMES)])
        assert rich.observation_space.contains(b)


def test_features_are_the_closed_form_of_the_nominal_model() -> None:
    sc = load_scenario("rudder_aging")
    gain, tc = nominal_nomoto(sc)
    length, speed, ts = sc.ship_length, sc.model.nominal_speed, sc.control_period
    want = [
        gain * length / speed / 2,
        tc * speed / length / 2,
        math.log10(tc / ts) / 2,
        math.log10(length / 0.1) / 4,
        math.log10(speed / 0.1) / 2,
        2 * ts * speed / length,
        sc.model.rudder_limit / (math.pi / 4),
    ]
    got = core.scenario_context_row(sc)
    np.testing.assert_allclose(got, np.clip(want, 0, 2).astype(np.float32), rtol=1e-6)


def test_features_ignore_true_parameters_and_schedule() -> None:
    """Trials that differ only in their event schedule (the true parameters after the
    change, the change time) observe the same features, at every step, before and after
    the change."""
    base = load_scenario("rudder_aging").config
    event = base.events[0].model_dump()
    other = base.model_copy(
        update={
            "events": [
                type(base.events[0]).model_validate(
                    {**event, "time": event["time"] / 2, "params": {"Tc": 0.9}}
                )
            ]
        }
    )
    assert other.events != base.events
    rows = []
    for config in (base, other):
        env = ShipPathFollowEnv(config, context_features=True)
        observations = _steps(env, int(2 * event["time"] / env.scenario.control_period))
        tail = np.array([o[len(core.OBS_NAMES) :] for o in observations])
        assert np.all(tail == tail[0])  # constant through the change
        rows.append(tail[0])
    np.testing.assert_array_equal(rows[0], rows[1])


@pytest.mark.parametrize("ship", [0, 1, 2, 3])
def test_scaling_keeps_every_training_ship_inside_the_bounds(ship: int) -> None:
    """No feature of a trial of the training distribution is clipped (the scaling fits the
    suite's ships), and the ships are told apart."""
    dist = load_distribution("train")
    rows = []
    for seed in range(3):
        config = dist.sample(train_rng(seed), ship_index=ship)
        from shipgym.scenarios.loader import build_scenario

        sc = build_scenario(config, config.name)
        raw = np.array(
            core.context_columns(
                *nominal_nomoto(sc),
                sc.ship_length,
                sc.model.nominal_speed,
                sc.control_period,
                sc.model.rudder_limit,
            )
        )
        assert np.all(raw > 0) and np.all(raw < 2), raw
        rows.append(raw)
    assert len({round(r[3], 6) for r in rows}) == 1  # the ship length is the ship's


def test_batched_env_gives_the_single_env_rows() -> None:
    vec = ShipPathFollowVectorEnv(3, "rudder_aging", context_features=True)
    single = ShipPathFollowEnv("rudder_aging", context_features=True)
    obs_v, _ = vec.reset(seed=4)
    for i in range(3):
        obs_s, _ = single.reset(seed=4 + i)
        np.testing.assert_array_equal(obs_v[i], obs_s)
    assert vec.single_observation_space == single.observation_space


def test_randomized_env_passes_the_option() -> None:
    env = gym.make(shipgym.RANDOMIZED_ENV_ID, distribution="train", context_features=True)
    obs, _ = env.reset(seed=1)
    assert obs.shape == (len(core.OBS_NAMES) + len(core.CONTEXT_NAMES),)
    want = core.scenario_context_row(env.unwrapped.scenario)
    np.testing.assert_array_equal(obs[len(core.OBS_NAMES) :], want)
