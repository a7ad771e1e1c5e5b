"""The oracle as a DAgger teacher (baselines/learned/teachers.py): a rollout of the teacher
alone is the oracle's own episode, bit for bit; a student's applied command becomes the
oracle's previous command; the truth channel refuses an env without a plant."""

from __future__ import annotations

import functools

import gymnasium as gym
import numpy as np
import pytest

import shipgym  # noqa: F401  (registers the envs)
from shipgym_baselines.errors import ControllerError
from shipgym_baselines.evaluation import evaluate
from shipgym_baselines.learned.dagger import RolloutJob, rollout
from shipgym_baselines.learned.teachers import OracleTeacher, oracle_teacher
from shipgym_baselines.privileged import teacher_truth
from shipgym_baselines.training.dagger_agent import make_env

pytest.importorskip("stable_baselines3")

SCENARIO = "rudder_aging"  # nomoto2: ≈ 85 control steps
SEED = 10_003


def _env() -> gym.Env:
    """The training env of the scenario with context features and 4 steps of history (the
    student's observation; the plant and its noise draws are the plain env's)."""
    return make_env({"scenario": SCENARIO}, "rudder", True, 4)


def test_the_teachers_rollout_is_the_oracles_own_episode() -> None:
    """Round 0 (β = 1): the applied actions, the labels and the rewards of the teacher's
    rollout are those of ``evaluate("oracle", …)`` on the same trial."""
    job = RolloutJob(
        round=0,
        episode=0,
        seed=SEED,
        beta=1.0,
        mix_seed=0,
        make_env=_env,
        make_teacher=oracle_teacher,
        policy_kwargs={},
    )
    found = rollout(job)
    reference = evaluate("oracle", SCENARIO, [SEED])[0]
    limit = _env().unwrapped.controller_context.rudder_limit
    assert found["by_teacher"].all()
    np.testing.assert_array_equal(found["applied"], found["label"])
    commands = found["applied"][:, 0].astype(np.float64) * limit
    assert len(commands) == reference.metrics["steps"] > 20
    np.testing.assert_array_equal(commands, reference.trajectory["rudder_command"][1:])
    assert found["return"] == pytest.approx(reference.metrics["return"], rel=1e-12)


def test_a_students_applied_command_becomes_the_oracles_previous_command() -> None:
    env = _env()
    obs, info = env.reset(seed=SEED)
    teacher = OracleTeacher()
    teacher.reset(env, SEED)
    label = teacher.label(obs, info, env)
    own = teacher.oracle.command
    assert own == pytest.approx(float(label[0]) * teacher._rudder_limit, rel=1e-6)
    teacher.observe_applied(label.copy())  # its own label: its own (unrounded) command stands
    assert teacher.oracle.command == own
    student = np.array([-0.25], dtype=np.float32)
    assert not np.isclose(float(label[0]), -0.25)
    env.step(student)
    teacher.observe_applied(student)
    assert teacher.oracle.command == -0.25 * teacher._rudder_limit
    assert teacher.solve_cpu_s() > 0


def test_the_teacher_follows_the_randomised_envs_scenario_of_each_reset() -> None:
    """The randomised training env swaps its scenario at every reset: the teacher's truth
    is the current one's."""
    env = make_env({"distribution": "train"}, "rudder", True, 2)
    teacher = OracleTeacher()
    ships = set()
    for seed in (0, 1, 2, 3, 4, 5):
        env.reset(seed=seed)
        teacher.reset(env, seed)
        truth = teacher.oracle._truth()
        np.testing.assert_array_equal(truth.state, env.unwrapped._env.plant_truth().state)
        assert teacher.oracle.ctx.ship == env.unwrapped.scenario.model.name
        ships.add(teacher.oracle.ctx.ship)
    assert len(ships) >= 2


def test_the_truth_channel_refuses_an_env_without_a_plant() -> None:
    with pytest.raises(ControllerError, match="no plant truth"):
        teacher_truth(gym.make("CartPole-v1"))
    with pytest.raises(Exception, match="rudder"):
        OracleTeacher().reset(make_env({"scenario": SCENARIO}, "guidance", False, 0), 0)


def test_the_factories_pickle() -> None:
    """Process pools pickle the rollout's factories."""
    import pickle

    env = functools.partial(make_env, {"scenario": SCENARIO}, "rudder", True, 4)
    assert pickle.loads(pickle.dumps(env))().observation_space.shape == (16 + 4 * 7,)
    assert isinstance(pickle.loads(pickle.dumps(oracle_teacher))(), OracleTeacher)
