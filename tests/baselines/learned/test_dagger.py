"""DAgger (baselines/learned/dagger.py) on a small linear plant with an LQR teacher: the
student reaches the teacher's cost, the label cache resumes a killed run without
relabelling, round 0 is the teacher's own rollouts, the student is an SB3 zip the
data-only loader reads."""

from __future__ import annotations

import concurrent.futures
import json
import pickle
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
import scipy.linalg
from gymnasium import spaces

from shipgym_baselines.errors import RunError
from shipgym_baselines.learned.dagger import (
    DATA_KEYS,
    MODEL_FILE,
    ROUND_KEYS,
    ROUNDS_FILE,
    DaggerSettings,
    RolloutJob,
    build_student,
    evaluate,
    fit_student,
    load_dataset,
    load_student,
    policy_actions,
    run_dagger,
    save_student,
    state_digest,
    student_state,
)

pytest.importorskip("stable_baselines3")

DT = 0.1  # s
U_MAX = 2.0  # m/s², the acceleration of the action 1
HORIZON = 60  # steps
NOISE = 0.02  # standard deviation of the process noise per step (m, m/s)
A = np.array([[1.0, DT], [0.0, 1.0]])
B = np.array([[DT * DT / 2.0], [DT]]) * U_MAX
Q = np.diag([1.0, 0.1])
R = np.array([[0.05]])
P = scipy.linalg.solve_discrete_are(A, B, Q, R)
K = np.linalg.solve(R + B.T @ P @ B, B.T @ P @ A)


class DoubleIntegrator(gym.Env):
    """x = (position m, velocity m/s), the action the normalised acceleration; a random
    initial state in [-1, 1]², Gaussian process noise, cost x'Qx + a'Ra per step (the
    reward its negative), 60 steps."""

    observation_space = spaces.Box(-np.inf, np.inf, (2,), np.float32)
    action_space = spaces.Box(-1.0, 1.0, (1,), np.float32)

    def reset(self, *, seed: int | None = None, options: Any = None) -> tuple[np.ndarray, dict]:
        super().reset(seed=seed)
        self.x = self.np_random.uniform(-1.0, 1.0, 2)
        self.t = 0
        return self.x.astype(np.float32), {}

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict]:
        a = np.clip(np.asarray(action, dtype=np.float64).reshape(1), -1.0, 1.0)
        cost = float(self.x @ Q @ self.x + a @ R @ a)
        self.x = A @ self.x + B @ a + NOISE * self.np_random.normal(size=2)
        self.t += 1
        return self.x.astype(np.float32), -cost, False, self.t >= HORIZON, {}


#: every label the teachers of this module made, and (in ``FAIL_AFTER``) the count at which
#: the next label raises, a killed labelling run
CALLS: list[int] = [0]
FAIL_AFTER: list[int | None] = [None]
#: the actions the teachers were told were applied, per rollout
OBSERVED: list[list[np.ndarray]] = []


class _Killed(Exception):
    pass


class LQRTeacher:
    """The saturated LQR law on the env's true state (privileged: read from the env)."""

    def reset(self, env: gym.Env, seed: int) -> None:
        self.applied: list[np.ndarray] = []
        OBSERVED.append(self.applied)

    def label(self, obs: np.ndarray, info: dict, env: gym.Env) -> np.ndarray:
        if FAIL_AFTER[0] is not None and CALLS[0] >= FAIL_AFTER[0]:
            raise _Killed
        CALLS[0] += 1
        return np.clip(-K @ env.unwrapped.x, -1.0, 1.0)

    def observe_applied(self, action: np.ndarray) -> None:
        self.applied.append(np.array(action))


def lqr(obs: np.ndarray) -> np.ndarray:
    """The teacher's law on the observation (the plant observes its state)."""
    return np.clip(-K @ obs.astype(np.float64), -1.0, 1.0).astype(np.float32)


@pytest.fixture(autouse=True)
def _counters() -> None:
    CALLS[0], FAIL_AFTER[0] = 0, None
    OBSERVED.clear()


def small(**kwargs: Any) -> DaggerSettings:
    defaults = {"episodes_per_round": 3, "net_arch": [16], "epochs": 3, "batch_size": 64}
    return DaggerSettings(**{**defaults, **kwargs})


def test_student_reaches_the_lqr_teachers_cost(tmp_path: Path) -> None:
    settings = DaggerSettings(
        episodes_per_round=10, net_arch=[32, 32], epochs=30, batch_size=64, learning_rate=3e-3
    )
    run = run_dagger(tmp_path / "run", DoubleIntegrator, LQRTeacher, settings, n_rounds=4)
    seeds = range(10_000, 10_030)  # held out: training used env seeds 0…39
    teacher = -evaluate(lqr, DoubleIntegrator, seeds).mean()
    calls = CALLS[0]
    student = -evaluate(policy_actions(run.student), DoubleIntegrator, seeds).mean()
    assert CALLS[0] == calls  # the student's evaluation never asked the teacher
    untrained = build_student(
        DoubleIntegrator.observation_space, DoubleIntegrator.action_space, settings
    )
    untrained_cost = -evaluate(policy_actions(untrained), DoubleIntegrator, seeds).mean()
    assert untrained_cost > 1.5 * teacher  # the comparison can fail
    assert abs(student / teacher - 1.0) <= 0.05, (student, teacher)
    assert [r["round"] for r in run.rounds] == [0, 1, 2, 3]
    assert [r["beta"] for r in run.rounds] == [1.0, 0.0, 0.0, 0.0]
    assert all(set(r) == set(ROUND_KEYS) for r in run.rounds)
    assert run.rounds[-1]["labels_total"] == 4 * 10 * HORIZON == CALLS[0]
    summary = run.summary()
    assert summary["labels"] == 2400 and summary["teacher_cpu_s"] > 0
    assert summary["labels_per_teacher_cpu_s"] == pytest.approx(2400 / summary["teacher_cpu_s"])
    assert json.loads((tmp_path / "run" / ROUNDS_FILE).read_text()) == run.rounds


def test_round_zero_is_the_teachers_own_rollouts(tmp_path: Path) -> None:
    settings = small(env_seed_start=7)
    run_dagger(tmp_path / "run", DoubleIntegrator, LQRTeacher, settings, n_rounds=1)
    data = load_dataset(tmp_path / "run")
    assert set(data) == set(DATA_KEYS)
    assert data["by_teacher"].all() and np.array_equal(data["applied"], data["label"])
    for episode in range(settings.episodes_per_round):
        env = DoubleIntegrator()
        obs, _ = env.reset(seed=7 + episode)
        states, actions, rewards = [], [], []
        for _ in range(HORIZON):
            action = np.clip(-K @ env.x, -1.0, 1.0).astype(np.float32)
            states.append(obs)
            actions.append(action)
            obs, reward, _, _, _ = env.step(action)
            rewards.append(reward)
        rows = data["episode"] == episode
        assert np.array_equal(data["obs"][rows], np.stack(states))
        assert np.array_equal(data["label"][rows], np.stack(actions))
        assert np.array_equal(data["reward"][rows], np.array(rewards))
        assert np.array_equal(data["step"][rows], np.arange(HORIZON))
        assert (data["seed"][rows] == 7 + episode).all() and (data["round"][rows] == 0).all()


def test_the_mixture_executes_the_teacher_with_probability_beta(tmp_path: Path) -> None:
    settings = small(beta_schedule="exponential", beta_decay=0.5)
    assert [settings.beta(i) for i in range(4)] == [1.0, 0.5, 0.25, 0.125]
    assert [small().beta(i) for i in range(3)] == [1.0, 0.0, 0.0]
    run_dagger(tmp_path / "run", DoubleIntegrator, LQRTeacher, settings, n_rounds=2)
    data = load_dataset(tmp_path / "run")
    mixed = data["round"] == 1
    share = data["by_teacher"][mixed].mean()
    assert 0.4 < share < 0.6  # 180 coin flips of β = 0.5
    teacher = data["by_teacher"]
    assert np.array_equal(data["applied"][teacher], data["label"][teacher])
    assert not np.array_equal(data["applied"][~teacher], data["label"][~teacher])
    # each teacher was told the applied action of every step, its own or the student's
    told = np.concatenate([np.stack(a) for a in OBSERVED])
    assert np.array_equal(told, data["applied"])


def test_a_killed_run_resumes_without_relabelling(tmp_path: Path) -> None:
    settings = small()
    labels_per_round = settings.episodes_per_round * HORIZON
    whole = run_dagger(tmp_path / "whole", DoubleIntegrator, LQRTeacher, settings, n_rounds=2)
    assert CALLS[0] == 2 * labels_per_round

    # stopped after round 0, then asked for 2 rounds: round 0 is not rolled out again
    CALLS[0] = 0
    run_dagger(tmp_path / "split", DoubleIntegrator, LQRTeacher, settings, n_rounds=1)
    assert CALLS[0] == labels_per_round
    CALLS[0] = 0
    split = run_dagger(
        tmp_path / "split", DoubleIntegrator, LQRTeacher, settings, n_rounds=2, resume=True
    )
    assert CALLS[0] == labels_per_round

    # killed inside round 1 after its first rollout: the resumed run labels the other two
    CALLS[0] = 0
    run_dagger(tmp_path / "killed", DoubleIntegrator, LQRTeacher, settings, n_rounds=1)
    FAIL_AFTER[0] = labels_per_round + HORIZON + 30
    with pytest.raises(_Killed):
        run_dagger(
            tmp_path / "killed", DoubleIntegrator, LQRTeacher, settings, n_rounds=2, resume=True
        )
    assert len(list((tmp_path / "killed" / "rollouts").glob("r001_*.npz"))) == 1
    FAIL_AFTER[0], CALLS[0] = None, 0
    killed = run_dagger(
        tmp_path / "killed", DoubleIntegrator, LQRTeacher, settings, n_rounds=2, resume=True
    )
    assert CALLS[0] == 2 * HORIZON
    assert killed.rounds[1]["cached_rollouts"] == 1

    # a finished run asked again labels nothing
    CALLS[0] = 0
    again = run_dagger(
        tmp_path / "killed", DoubleIntegrator, LQRTeacher, settings, n_rounds=2, resume=True
    )
    assert CALLS[0] == 0 and len(again.rounds) == 2

    expected = load_dataset(tmp_path / "whole")
    for run in (split, killed, again):
        data = load_dataset(run.out)
        for key in DATA_KEYS:
            assert np.array_equal(data[key], expected[key]), key
        assert state_digest(student_state(run.student)) == state_digest(
            student_state(whole.student)
        )
        steady = ("labels", "labels_total", "mean_return", "train_loss", "student_mse_before")
        for got, want in zip(run.rounds, whole.rounds, strict=True):
            assert {k: got[k] for k in steady} == {k: want[k] for k in steady}


def test_rollouts_in_an_executor_give_the_same_data(tmp_path: Path) -> None:
    settings = small()
    run_dagger(tmp_path / "here", DoubleIntegrator, LQRTeacher, settings, n_rounds=2)
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        run_dagger(
            tmp_path / "pool", DoubleIntegrator, LQRTeacher, settings, n_rounds=2, executor=pool
        )
    here, pool_data = load_dataset(tmp_path / "here"), load_dataset(tmp_path / "pool")
    for key in DATA_KEYS:
        assert np.array_equal(here[key], pool_data[key]), key
    # what a process pool sends: a job pickles (its factories by reference)
    student = load_student(
        tmp_path / "here" / MODEL_FILE,
        DoubleIntegrator.observation_space,
        DoubleIntegrator.action_space,
        settings,
    )
    job = RolloutJob(1, 0, 3, 0.0, 0, DoubleIntegrator, LQRTeacher, {}, student_state(student))
    assert pickle.loads(pickle.dumps(job)).seed == 3


def test_the_student_is_an_sb3_zip_the_data_only_loader_reads(tmp_path: Path) -> None:
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import DummyVecEnv

    from shipgym.envs.core import action_space, observation_space
    from shipgym_baselines.learned.loading import SavedModel, load_data_only

    settings = small()
    obs_space, act_space = observation_space(True), action_space("rudder")
    student = build_student(obs_space, act_space, settings)
    rng = np.random.default_rng(0)
    obs = rng.uniform(obs_space.low, obs_space.high, (256, obs_space.shape[0])).astype(np.float32)
    labels = np.tanh(obs[:, :1] - obs[:, 1:2])
    before = policy_actions(student)(obs)
    fit_student(student, obs, labels, settings, round_=0)
    assert not np.array_equal(policy_actions(student)(obs), before)  # it learned
    path = save_student(student, tmp_path / "student.zip")
    loaded = load_data_only(SavedModel(path, "ppo", "rudder", context_features=True), PPO)
    np.testing.assert_array_equal(
        loaded.predict(obs, deterministic=True)[0], student.predict(obs, deterministic=True)[0]
    )
    again = load_student(path, obs_space, act_space, settings)
    np.testing.assert_array_equal(policy_actions(again)(obs), policy_actions(student)(obs))

    # a DAgger run's student loads into PPO for fine-tuning on its env
    run = run_dagger(tmp_path / "run", DoubleIntegrator, LQRTeacher, settings, n_rounds=1)
    venv = DummyVecEnv([DoubleIntegrator])
    ppo = PPO.load(
        run.out / MODEL_FILE, env=venv, device="cpu", n_steps=32, batch_size=32, n_epochs=1
    )
    plant_obs = rng.uniform(-1, 1, (16, 2)).astype(np.float32)
    np.testing.assert_array_equal(
        ppo.predict(plant_obs, deterministic=True)[0], policy_actions(run.student)(plant_obs)
    )
    ppo.learn(32)
    assert ppo.num_timesteps == 32


class WideActions(DoubleIntegrator):
    action_space = spaces.Box(-2.0, 2.0, (1,), np.float32)


def test_folders_and_spaces_that_cannot_hold_the_run_are_refused(tmp_path: Path) -> None:
    out = tmp_path / "run"
    run_dagger(out, DoubleIntegrator, LQRTeacher, small(), n_rounds=1)
    with pytest.raises(RunError, match="resume=True to continue"):
        run_dagger(out, DoubleIntegrator, LQRTeacher, small(), n_rounds=1)
    with pytest.raises(RunError, match=r"other settings \(settings: "):
        run_dagger(out, DoubleIntegrator, LQRTeacher, small(seed=1), n_rounds=2, resume=True)
    with pytest.raises(RunError, match=r"other settings \(identity: "):
        run_dagger(
            out, DoubleIntegrator, LQRTeacher, small(), 2, resume=True, identity={"teacher": "x"}
        )
    replaced = run_dagger(out, DoubleIntegrator, LQRTeacher, small(seed=1), 1, force=True)
    assert json.loads((out / "dagger.json").read_text())["settings"]["seed"] == 1
    assert len(replaced.rounds) == 1

    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("mine")
    with pytest.raises(RunError, match="holds no DAgger run"):
        run_dagger(foreign, DoubleIntegrator, LQRTeacher, small(), 1, resume=True)
    with pytest.raises(RunError, match=r"notes\.txt"):
        run_dagger(foreign, DoubleIntegrator, LQRTeacher, small(), 1, force=True)
    assert (foreign / "notes.txt").read_text() == "mine"

    with pytest.raises(RunError, match=r"box \[-1, 1\]"):
        run_dagger(tmp_path / "wide", WideActions, LQRTeacher, small(), 1)
    with pytest.raises(ValueError, match="net_arch"):
        small(net_arch=[])
