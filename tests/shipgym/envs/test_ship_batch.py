"""The per-ship trial env: a fresh trial per env at every reset, drawn as the distribution
draws them, each env's episode that of a single env on its trial."""

from __future__ import annotations

import numpy as np
import pytest
from gymnasium.utils import seeding

from shipgym.envs.path_follow import ShipPathFollowEnv
from shipgym.envs.ship_batch import ShipTrialsVectorEnv
from shipgym.scenarios.sampling import (
    DistributionError,
    load_distribution,
    train_rng,
    train_scenario_seed,
)

N = 3


def expected_draws(seed: int, ship: int, resets: int) -> list[tuple[dict, int]]:
    """(config dump, episode seed) of the first ``resets`` trials of an env seeded ``seed``,
    from the distribution directly (the randomised env's order with the ship fixed)."""
    dist = load_distribution("train")
    rng, _ = seeding.np_random(seed)
    out = []
    for _ in range(resets):
        scenario_seed = train_scenario_seed(rng)
        config = dist.sample(
            train_rng(scenario_seed), name=f"train:train-{scenario_seed}", ship_index=ship
        )
        out.append((config.model_dump(), int(rng.integers(0, 2**31 - 1))))
    return out


@pytest.mark.parametrize("ship", ["nomoto2", "blanke"])
def test_per_reset_draws_equal_the_distribution_draws(ship: str) -> None:
    env = ShipTrialsVectorEnv(N, "train", ship=ship)
    k = env.ship_index
    want = [expected_draws(11 + i, k, 3) for i in range(N)]
    env.reset(seed=11)
    count = np.zeros(N, dtype=int)
    for mask in ([True, False, True], [False, True, True], None):
        for i in range(N):
            assert env.trial_scenarios[i].config.model_dump() == want[i][count[i]][0]
        if mask is not None:  # the masked envs draw their next trial, the others keep theirs
            env.reset(options={"reset_mask": np.array(mask)})
            count += np.array(mask)


def test_each_env_runs_the_single_env_episode_of_its_trial() -> None:
    """Same actions: env i's observations, rewards and ends equal those of a
    ShipPathFollowEnv on its drawn trial reset with its episode seed, bit for bit."""
    for ship, mode in (("nomoto2", "rudder"), ("esso_osaka", "guidance")):
        env = ShipTrialsVectorEnv(N, "train", ship=ship, action_mode=mode, context_features=True)
        k = env.ship_index
        draws = [expected_draws(5 + i, k, 1)[0] for i in range(N)]
        singles = []
        obs, _ = env.reset(seed=5)
        for i in range(N):
            single = ShipPathFollowEnv(
                env.trial_scenarios[i], action_mode=mode, context_features=True
            )
            o, _ = single.reset(seed=draws[i][1])
            np.testing.assert_array_equal(obs[i], o)
            singles.append(single)
        rng = np.random.default_rng(0)
        done_single = [False] * N
        for _ in range(60):
            action = rng.uniform(-1, 1, (N, env.single_action_space.shape[0]))
            obs, rew, term, trunc, _ = env.step(action.astype(np.float32))
            for i in range(N):
                if done_single[i]:
                    continue
                o, r, te, tr, _ = singles[i].step(action[i].astype(np.float32))
                np.testing.assert_array_equal(obs[i], o)
                assert rew[i] == r and term[i] == te and trunc[i] == tr
                done_single[i] = te or tr


def test_bad_ship_and_test_split_are_refused() -> None:
    with pytest.raises(DistributionError, match="valid: nomoto2"):
        ShipTrialsVectorEnv(2, "train", ship="titanic")
    with pytest.raises(DistributionError, match="train split"):
        ShipTrialsVectorEnv(2, "validation", ship=0)


def test_the_plant_runs_on_the_calling_thread() -> None:
    """Training processes run one per core with one torch thread: the rows' plant call
    must not start a second thread (it waited for a core: ≈ 2.5 ms per call instead of
    ≈ 0.1 ms with two training jobs on two cores, docs/training.md "Throughput")."""
    env = ShipTrialsVectorEnv(2, "train", ship="nomoto2")
    assert env._integrator.threads == 1
