"""The KVLCC2 scenarios and ``ShipPathFollow-KVLCC2-v1``.

``kvlcc2_nominal`` and its rudder aging, current shift and manoeuvrability change on the
≈ 20 L three-leg route of the matrix ships, and the rudder aging on the PCHIP curve (the
matrix's layout scaled to this hull; not in any suite).
"""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import shipgym
from shipgym.identification.zigzag import ship_nomoto
from shipgym.models.kvlcc2 import KVLCC2Params
from shipgym.models.loading import loading_change
from shipgym.scenarios.loader import list_scenarios, load_scenario

SCENARIOS = (
    "kvlcc2_nominal",
    "kvlcc2_rudder_aging",
    "kvlcc2_current_shift",
    "kvlcc2_maneuverability_change",
    "kvlcc2_rudder_aging_curved",
)
ENV_ID = "ShipPathFollow-KVLCC2-v1"


def _route_length(name: str) -> float:
    """Approach from the start plus the path's length, in ship lengths."""
    sc = load_scenario(name)
    start = (sc.config.initial_state.x, sc.config.initial_state.y)
    return (math.dist(start, sc.config.path.waypoints[0]) + sc.path.length) / sc.ship_length


@pytest.mark.parametrize("name", SCENARIOS)
def test_scenario_loads_on_the_kvlcc2_with_the_matrix_timing(name: str) -> None:
    """kvlcc2; 15-25 L of route; 200-2000 control steps; the change at 4 L/U."""
    assert name in list_scenarios()
    sc = load_scenario(name)
    assert sc.model.name == "kvlcc2"
    assert 15.0 <= _route_length(name) <= 25.0
    assert 200 <= sc.config.time_limit / sc.control_period <= 2000
    assert sc.config.path.type == ("pchip" if name.endswith("_curved") else "waypoints")
    current = sc.config.disturbances.current
    t_star = sc.change_time or getattr(current, "switch_time", None)
    if name == "kvlcc2_nominal":
        assert t_star is None and sc.schedule.events == []
    else:
        assert t_star == pytest.approx(4.0 * sc.ship_length / sc.model.nominal_speed, rel=0.01)


@pytest.mark.parametrize("name", SCENARIOS)
def test_an_episode_runs_to_its_end_with_a_fixed_rudder(name: str) -> None:
    """A trivial controller (rudder amidships) until the env ends the episode."""
    env = gym.make(ENV_ID, scenario=name)
    obs, _ = env.reset(seed=0)
    done, steps, info = False, 0, {}
    while not done:
        obs, reward, terminated, truncated, info = env.step(np.zeros(1, dtype=np.float32))
        assert env.observation_space.contains(obs) and math.isfinite(reward)
        done = terminated or truncated
        steps += 1
    assert info["termination_reason"] in ("corridor", "time_limit", "goal")
    assert steps <= env.unwrapped.scenario.config.time_limit / env.unwrapped.scenario.control_period
    env.close()


def test_env_id_defaults_to_rudder_aging_and_passes_check_env() -> None:
    assert shipgym.ENV_IDS[ENV_ID] == "kvlcc2_rudder_aging"
    env = gym.make(ENV_ID)
    assert env.unwrapped.scenario.name == "kvlcc2_rudder_aging"
    assert env.unwrapped.model.name == "kvlcc2"
    check_env(env.unwrapped, skip_render_check=True)
    env.close()


def test_maneuverability_change_is_the_loading_model() -> None:
    """The YAML's numbers are shipgym.models.loading's at draught ×0.4 (5 digits)."""
    (event,) = load_scenario("kvlcc2_maneuverability_change").config.events
    expected = loading_change("kvlcc2", KVLCC2Params(), 0.4)
    assert set(event.params) == set(expected)
    for name, value in expected.items():
        assert event.params[name] == pytest.approx(value, rel=1e-4), name


def test_rudder_aging_is_a_fifth_of_the_rate_and_a_lag_of_08_nomoto_t() -> None:
    """The aged gear: rate 15.68/5 °/s, T_servo 0.8 × the ship's first-order Nomoto T (from
    its 20/20 zig-zag, 12.6 s) to 2 %; the curved twin has the same event."""
    for name in ("kvlcc2_rudder_aging", "kvlcc2_rudder_aging_curved"):
        (event,) = load_scenario(name).config.events
        assert event.params["rudder_rate"] == pytest.approx(15.68 / 5.0 * math.pi / 180, rel=1e-4)
        sc = load_scenario(name)
        fit, _ = ship_nomoto(sc.model)
        _, t = fit.first_order()
        assert event.params["T_servo"] == pytest.approx(0.8 * t, rel=0.02)


def test_current_shift_is_three_knots_full_scale_across_the_route() -> None:
    current = load_scenario("kvlcc2_current_shift").config.disturbances.current
    assert current.kind == "two_phase" and current.speed == 0.0 and current.sigma == 0.0
    knots = current.second_speed * math.sqrt(320.0 / 7.0) * 3600.0 / 1852.0
    assert knots == pytest.approx(3.0, rel=2e-3)
    assert current.direction_deg == 90.0
