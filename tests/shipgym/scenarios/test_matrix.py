"""The scenario matrix (docs/scenario-matrix.md): every ship faces every change.

For esso_osaka, mariner and blanke: ``{ship}_nominal`` and, for each family (rudder aging,
current shift, manoeuvrability change), ``{ship}_{family}`` and ``{ship}_{family}_curved``.
Whether each change *matters* is tested in tests/baselines/studies/test_change_effect.py.
"""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import shipgym
from shipgym.models import MODELS
from shipgym.models.loading import loading_change
from shipgym.scenarios import families
from shipgym.scenarios.loader import list_scenarios, load_scenario
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET, run_episode
from shipgym_baselines.registry import make_controller

SHIPS = ("esso_osaka", "mariner", "blanke")
#: the families with a change (shipgym.scenarios.families)
FAMILIES = families.CHANGES
CHANGES = [f"{s}_{f}{v}" for s in SHIPS for f in FAMILIES for v in ("", "_curved")]
MATRIX = [f"{s}_nominal" for s in SHIPS] + CHANGES
#: kept as it was (ShipPathFollow-Blanke-v0's default): its own 85 L route, 700 s
KEPT = "blanke_current_shift"
V1_IDS = {
    "ShipPathFollow-EssoOsaka-v1": "esso_osaka",
    "ShipPathFollow-Mariner-v1": "mariner",
    "ShipPathFollow-Blanke-v1": "blanke",
}
#: the env ids of the ships (the -v1 ids; a scenario= keyword replaces the default)
SHIP_ID = {ship: env_id for env_id, ship in V1_IDS.items()}
#: draught ratio of each ship's manoeuvrability change (its YAML says why)
DRAUGHT = {"esso_osaka": 0.4, "mariner": 1.3, "blanke": 1.35}


def _route_length(name: str) -> float:
    """Approach from the start plus the path's length, in ship lengths."""
    sc = load_scenario(name)
    start = (sc.config.initial_state.x, sc.config.initial_state.y)
    first = sc.config.path.waypoints[0]
    return (math.dist(start, first) + sc.path.length) / sc.ship_length


def test_the_matrix_is_in_the_catalogue_with_the_old_names() -> None:
    names = set(list_scenarios())
    assert set(MATRIX) <= names
    kept = {"nominal", "rudder_aging", "current_shift", "maneuverability_change"}
    kept |= {f"{f}_{v}" for f in FAMILIES for v in ("long", "smooth")}
    kept |= {"osaka_curved", "osaka_stochastic_current", "mariner_track", KEPT}
    assert kept <= names


def test_each_matrix_scenario_is_filed_under_its_family() -> None:
    """``{ship}_{family}[_curved]`` has ``family: {family}``; ``{ship}_nominal`` nominal."""
    for ship in SHIPS:
        assert load_scenario(f"{ship}_nominal").family == families.NOMINAL
        for family in FAMILIES:
            for variant in ("", "_curved"):
                assert load_scenario(f"{ship}_{family}{variant}").family == family


@pytest.mark.parametrize("name", MATRIX)
def test_matrix_scenario_is_a_few_hundred_steps_on_its_ship(name: str) -> None:
    """The right ship; 15-25 L of route; a time limit of at most 2000 steps (2 × the
    route's time against the current); the change (if any) at 4 L/U, on the first leg;
    curved = PCHIP."""
    sc = load_scenario(name)
    ship = next(s for s in SHIPS if name.startswith(s))
    assert sc.model.name == ship
    if name == KEPT:
        return
    assert 15.0 <= _route_length(name) <= 25.0
    steps = sc.config.time_limit / sc.control_period
    assert 200 <= steps <= 2000
    assert sc.config.path.type == ("pchip" if name.endswith("_curved") else "waypoints")
    current = sc.config.disturbances.current
    t_star = sc.change_time or getattr(current, "switch_time", None)
    if name.endswith("_nominal"):
        assert t_star is None and sc.schedule.events == []
        return
    # 4 L/U with U the ship's speed as the YAML states it (Mariner 7.7 m/s: S/f = 7.86 m/s)
    assert t_star == pytest.approx(4.0 * sc.ship_length / sc.model.nominal_speed, rel=0.03)


@pytest.mark.parametrize("name", [n for n in CHANGES if "current_shift" not in n])
def test_jumps_reach_the_true_parameters_at_their_time(name: str) -> None:
    """Through the env: the parameter block the plant is integrated with holds the nominal
    values before the event and the event's values from its time on."""
    sc = load_scenario(name)
    (event,) = sc.config.events
    env = gym.make(SHIP_ID[sc.model.name], scenario=name, randomize=False)  # the event's own time
    env.reset(seed=0)
    names = MODELS[sc.model.name].params_type.names()
    nominal = sc.nominal_params.to_vector()
    base = env.unwrapped
    while True:
        t0 = base.time
        env.step(np.zeros(1, dtype=np.float32))
        block = base._p_block
        if t0 + sc.control_period <= event.time:
            np.testing.assert_array_equal(block, np.broadcast_to(nominal, block.shape))
        elif t0 >= event.time:
            break
    for i, pname in enumerate(names):
        expected = event.params.get(pname, nominal[i])
        np.testing.assert_array_equal(block[:, i], expected)
    env.close()


@pytest.mark.parametrize("ship", SHIPS)
def test_maneuverability_change_is_the_loading_model(ship: str) -> None:
    """The YAML's numbers are shipgym.models.loading's at the stated draught (5 digits)."""
    for name in (f"{ship}_maneuverability_change", f"{ship}_maneuverability_change_curved"):
        (event,) = load_scenario(name).config.events
        expected = loading_change(ship, MODELS[ship].params_type(), DRAUGHT[ship])
        assert set(event.params) == set(expected)
        for pname, value in expected.items():
            assert event.params[pname] == pytest.approx(value, rel=1e-4), pname


def test_current_shift_is_a_calm_then_appearing_current() -> None:
    for name in [n for n in CHANGES if "current_shift" in n]:
        current = load_scenario(name).config.disturbances.current
        assert current.kind == "two_phase" and current.speed == 0.0 and current.sigma == 0.0
        assert current.second_speed > 0.0


@pytest.mark.parametrize("name", MATRIX)
def test_pid_los_finishes_each_matrix_scenario(name: str) -> None:
    """Feasible: a classical controller reaches the goal within the time limit (the first
    leaderboard trial), in a few hundred control steps."""
    policy, mode = make_controller("pid_los")
    result = run_episode(policy, name, EVAL_SEED_OFFSET, mode)
    assert result.metrics["termination_reason"] == "goal"
    if name != KEPT:
        assert 150 <= len(result.trajectory["t"]) - 1 <= 1000


def test_per_ship_ids_v1_default_to_rudder_aging_and_v0_keep_theirs() -> None:
    for env_id, ship in V1_IDS.items():
        env = gym.make(env_id)
        assert env.unwrapped.scenario.name == f"{ship}_rudder_aging"
        assert env.unwrapped.scenario.schedule.events  # a changing plant
        env.close()
    assert shipgym.ENV_IDS["ShipPathFollow-EssoOsaka-v0"] == "osaka_stochastic_current"
    assert shipgym.ENV_IDS["ShipPathFollow-Mariner-v0"] == "mariner_track"
    assert shipgym.ENV_IDS["ShipPathFollow-Blanke-v0"] == "blanke_current_shift"
    for env_id in ("ShipPathFollow-EssoOsaka-v0", "ShipPathFollow-Mariner-v0"):
        env = gym.make(env_id)
        assert env.unwrapped.scenario.name == shipgym.ENV_IDS[env_id]
        env.close()


@pytest.mark.parametrize("name", MATRIX)
def test_matrix_scenario_runs_by_name_single_and_batched(name: str) -> None:
    """gym.make(id, scenario=NAME) and the batched env run the same steps, bit for bit."""
    env_id = SHIP_ID[next(s for s in SHIPS if name.startswith(s))]
    single = gym.make(env_id, scenario=name)
    batched = gym.make_vec(env_id, num_envs=2, scenario=name)
    obs, _ = single.reset(seed=3)
    vobs, _ = batched.reset(seed=[3, 4])
    np.testing.assert_array_equal(vobs[0], obs)
    for k in range(5):
        action = np.full(1, 0.1 * k, dtype=np.float32)
        obs, reward, *_ = single.step(action)
        vobs, vreward, *_ = batched.step(np.stack([action, action]))
        np.testing.assert_array_equal(vobs[0], obs)
        assert vreward[0] == reward
    single.close()
    batched.close()
