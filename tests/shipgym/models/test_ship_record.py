"""A ship is one record (shipgym.models.ship): every shipped ship's record is complete, every
per-ship table is read off the records, and a ship declared in this file alone (a model and
its record, a scenario) runs an episode through gym.make."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
import pytest
import yaml

import shipgym
from shipgym.identification.adaptation import QUANTITIES, Adaptation
from shipgym.models import MODELS, UNSEEN_HULLS
from shipgym.models.base import ParameterRecord, ShipModel
from shipgym.models.hull import Hull
from shipgym.models.loading import HULLS, loading_change
from shipgym.models.ship import (
    DRAUGHT,
    SHIPS,
    EnvId,
    Ship,
    registered,
    rudder_quantity,
    servo_quantity,
)
from shipgym.scenarios.loader import load_scenario
from shipgym.validation import FIGURES, PUBLISHED


# ------------------------------------------------------------------ a ship added in this file
@dataclasses.dataclass(frozen=True)
class Nomoto1Params(ParameterRecord):
    """A first-order Nomoto ship with a rudder servo, SI/radians."""

    K: float = 0.2  # Nomoto gain [1/s]
    T: float = 4.0  # Nomoto time constant [s]
    Tc: float = 0.3  # rudder servo time constant [s]
    u0: float = 1.0  # surge speed [m/s]
    L: float = 4.0  # length [m]

    positive: ClassVar[tuple[str, ...]] = ("K", "T", "Tc", "u0", "L")


class Nomoto1(ShipModel):
    """test_nomoto1: T·ṙ + r = K·δ, Tc·δ̇ + δ = δc, constant speed u0."""

    name = "test_nomoto1"
    state_names = ("x", "y", "psi", "r", "delta")
    disturbance_names = ("current_x", "current_y", "yaw_disturbance")
    params_type = Nomoto1Params
    rudder_limit = 35.0 * math.pi / 180.0
    control_period = 0.5
    fine_step = 0.05
    #: a loading change slows the yaw response as the mass grows
    hull = Hull(L=4.0, B=0.6, T=0.2, C_B=0.7)
    scaled_by: ClassVar[dict[str, str]] = {"T": "mass"}

    def rhs(self, x: Any, u: Any, w: Any, p: Any, ops: SimpleNamespace) -> Any:
        psi, r, delta = x[2], x[3], x[4]
        return ops.stack(
            [
                p.u0 * ops.cos(psi) + w[0],
                p.u0 * ops.sin(psi) + w[1],
                r,
                (p.K * delta - r) / p.T + w[2],
                (u[0] - delta) / p.Tc,
            ]
        )


TEST_ENV_ID = "ShipPathFollow-TestNomoto1-v0"
#: 60 s at Ts = 0.5 s; the servo ages at 20 s
SCENARIO = {
    "name": "test_nomoto1_rudder_aging",
    "description": "A first-order Nomoto ship whose servo ages at 20 s.",
    "ship": {"model": "test_nomoto1"},
    "path": {"type": "waypoints", "waypoints": [[4, 4], [40, 4], [40, 30]]},
    "events": [{"time": 20.0, "params": {"Tc": 1.5}}],
    "time_limit": 60.0,
}


@pytest.fixture
def test_ship(tmp_path: Path) -> Iterator[Ship]:
    """The test ship registered (records and gymnasium id), removed after."""
    path = tmp_path / "test_nomoto1_rudder_aging.yaml"
    path.write_text(yaml.safe_dump(SCENARIO), encoding="utf-8")
    ship = Ship(
        model=Nomoto1,
        adapted=(servo_quantity("Tc"), rudder_quantity("K"), DRAUGHT),
        env_ids=(EnvId(TEST_ENV_ID, str(path), 120),),
    )
    with registered(ship):
        shipgym.register_envs(ship)
        try:
            yield ship
        finally:
            del gym.registry[TEST_ENV_ID]


def test_a_ship_added_in_one_file_is_in_every_table(test_ship: Ship) -> None:
    name = test_ship.name
    assert MODELS[name] is Nomoto1
    assert HULLS[name] == Nomoto1.hull
    assert QUANTITIES[name] == test_ship.adapted
    assert name not in UNSEEN_HULLS and name not in PUBLISHED
    assert shipgym.ENV_IDS[TEST_ENV_ID] == test_ship.env_ids[0].scenario
    assert shipgym.MAX_EPISODE_STEPS[TEST_ENV_ID] == 120
    assert loading_change(name, Nomoto1Params(), 2.0) == {"T": 8.0}
    theta = Adaptation(name, Nomoto1Params()).params(np.array([0.0, math.log(2.0), 0.0]))
    assert theta.tolist() == pytest.approx([0.4, 4.0, 0.3, 1.0, 4.0])


def test_a_ship_added_in_one_file_runs_an_episode(test_ship: Ship) -> None:
    env = gym.make(TEST_ENV_ID, compile=False)
    assert env.spec is not None and env.spec.max_episode_steps == 120
    obs, _ = env.reset(seed=3)
    assert env.unwrapped.scenario.model.name == "test_nomoto1"
    steps, done, info = 0, False, {}
    while not done:
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        assert np.all(np.isfinite(obs)) and math.isfinite(reward)
        done = terminated or truncated
        steps += 1
    assert 0 < steps <= 120
    assert "episode_metrics" in info
    env.close()


def test_no_test_ship_is_left_registered() -> None:
    assert "test_nomoto1" not in SHIPS and "test_nomoto1" not in MODELS
    assert TEST_ENV_ID not in gym.registry and TEST_ENV_ID not in shipgym.ENV_IDS


def test_a_name_is_registered_once() -> None:
    with pytest.raises(ValueError, match="registered already"):
        with registered(SHIPS["nomoto2"]):
            pass
    assert MODELS["nomoto2"] is SHIPS["nomoto2"].model


# --------------------------------------------------------------------- the shipped records
def test_the_shipped_ships_in_their_listing_order() -> None:
    assert list(SHIPS) == ["nomoto2", "mariner", "blanke", "esso_osaka", "kvlcc2"]


@pytest.mark.parametrize("name", list(SHIPS))
def test_every_shipped_record_is_complete(name: str) -> None:
    ship = SHIPS[name]
    assert ship.name == name and issubclass(ship.model, ShipModel)
    assert issubclass(ship.params, ParameterRecord) and ship.params is ship.model.params_type
    ship.params().check_plant()  # the defaults are a real plant
    assert math.isfinite(ship.length) and ship.length > 0.0
    assert math.isfinite(ship.nominal_speed) and ship.nominal_speed > 0.0
    assert ship.adapted and len({q.name for q in ship.adapted}) == len(ship.adapted)
    for quantity in ship.adapted:
        assert set(quantity.params) <= set(ship.params.names()), quantity
        assert quantity.draught == (quantity is DRAUGHT)
    if DRAUGHT in ship.adapted:
        assert ship.hull is not None, "a draught needs a hull for the loading change"
    assert ship.env_ids, "every ship has a gymnasium id"
    for env in ship.env_ids:
        scenario = load_scenario(env.scenario)
        assert scenario.config.ship.model == name
        assert env.max_episode_steps == math.ceil(
            scenario.config.time_limit / scenario.control_period - 1e-9
        )
    for ref in ship.published:
        assert ref.figure.removesuffix("_port").removesuffix("_mean") in FIGURES
        assert ref.source and ref.note


def test_every_table_is_read_off_the_records() -> None:
    assert MODELS == {n: s.model for n, s in SHIPS.items()}
    assert list(MODELS) == list(SHIPS)
    assert HULLS == {n: s.hull for n, s in SHIPS.items() if s.hull is not None}
    assert set(UNSEEN_HULLS) == {n for n, s in SHIPS.items() if s.unseen} == {"kvlcc2"}
    assert QUANTITIES == {n: s.adapted for n, s in SHIPS.items()}
    assert PUBLISHED == {n: s.published for n, s in SHIPS.items() if s.published}
    envs = [e for s in SHIPS.values() for e in s.env_ids]
    assert shipgym.ENV_IDS == {e.id: e.scenario for e in envs}
    steps = {e.id: e.max_episode_steps for e in envs}
    assert shipgym.MAX_EPISODE_STEPS == {**steps, shipgym.RANDOMIZED_ENV_ID: 5104}
    for env in envs:
        spec = gym.spec(env.id)
        assert spec.kwargs == {"scenario": env.scenario, "randomize": True}
        assert spec.max_episode_steps == env.max_episode_steps
