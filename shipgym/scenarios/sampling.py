"""Randomised scenario distributions for training and held-out testing (SPEC §4).

A *distribution* (YAML in ``configs/distributions/``) gives ranges for the ship's nominal
parameters, the path (number of legs, leg lengths, turn angles, polyline or PCHIP), the
parameter jumps (which parameters, how large, when), the current and the sensor noise.
:meth:`ScenarioDistribution.sample` turns a random generator into an ordinary
:class:`~shipgym.scenarios.schema.ScenarioConfig`, so a sampled scenario runs through
exactly the same loader, env and metrics as a catalogue one.

Splits.  Every distribution has a ``split``: ``train`` or ``test``.  Test scenarios are
addressed by name, ``"<distribution>:<index>"`` (e.g. ``heldout:3``), and drawn from
``SeedSequence([TEST_SALT, crc32(name), index])``; training envs draw theirs from the env's
own seeded generator through :func:`train_scenario_seed` and ``SeedSequence([TRAIN_SALT,
seed])``, a seed space disjoint from the test one (tested).  The ``heldout`` distribution
also contains jump types and sizes outside the training ranges (the leaderboard's
generalisation rows); ``validation`` (training ranges, test seed space) is what training
evaluates on to keep its best model.

Units are those of scenario configs: lengths in ship lengths where a key ends in ``_L``,
angles in degrees where it ends in ``_deg``, ship parameters in the model's config units
(nomoto2: d0 in °/s).
"""

from __future__ import annotations

import math
import os
import zlib
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import AfterValidator, Field, model_validator

from shipgym.config import ConfigError, StrictModel, list_names, load_yaml_model, resolve
from shipgym.scenarios.schema import ScenarioConfig

#: salts of the two seed spaces: test scenarios come from SeedSequence([TEST_SALT, ·, i]),
#: training scenarios from SeedSequence([TRAIN_SALT, s]) with s drawn by the env
TRAIN_SALT = 0x5EED_7A1
TEST_SALT = 0x5EED_7E57


def _check_range(r: tuple[float, float]) -> tuple[float, float]:
    if not (math.isfinite(r[0]) and math.isfinite(r[1])) or r[0] > r[1]:
        raise ValueError(f"a range must be finite [low, high] with low ≤ high, got {list(r)}")
    return r


#: a [low, high] interval, validated
Range = Annotated[tuple[float, float], AfterValidator(_check_range)]


class JumpSpec(StrictModel):
    """One parameter's change: new value = base·factor (``factor``), base + x (``add``)
    or x (``value``), x uniform in ``range``."""

    mode: Literal["factor", "add", "value"]
    range: Range


class JumpKind(StrictModel):
    """A named kind of event (e.g. rudder aging) changing one or more parameters together."""

    weight: float = Field(1.0, gt=0)
    params: dict[str, JumpSpec]
    ramp_probability: float = Field(0.0, ge=0, le=1)
    ramp_duration: Range = (2.0, 10.0)


class JumpsConfig(StrictModel):
    probability: float = Field(0.8, ge=0, le=1)  # chance that an episode has a jump
    time: Range = (8.0, 30.0)  # s
    kinds: dict[str, JumpKind] = Field(default_factory=dict)


class PathSampling(StrictModel):
    legs: tuple[int, int] = (2, 4)  # number of legs, inclusive
    leg_length_L: Range = (10.0, 20.0)
    turn_deg: Range = (-90.0, 90.0)  # heading change at each inner waypoint
    start_offset_L: Range = (-1.5, 1.5)  # lateral offset of the first waypoint
    pchip_probability: float = Field(0.0, ge=0, le=1)
    time_factor: float = Field(1.6, gt=1)  # time limit = factor · length / U0 + 10 s


class CurrentSampling(StrictModel):
    probability: float = Field(0.0, ge=0, le=1)
    speed: Range = (0.0, 0.0)  # m/s
    direction_deg: Range = (0.0, 360.0)


class SensorSampling(StrictModel):
    heading_noise_deg: Range = (0.0, 0.0)
    outlier_probability: Range = (0.0, 0.0)


class ShipSampling(StrictModel):
    model: str = "nomoto2"
    unit_reading: str | None = None
    variant: str | None = None
    params: dict[str, float] = Field(default_factory=dict)  # nominal values (config units)
    param_factors: dict[str, Range] = Field(default_factory=dict)  # nominal·U(range)


class DistributionConfig(StrictModel):
    name: str
    description: str = ""
    split: Literal["train", "test"]
    size: int | None = Field(None, ge=1)  # test splits: number of named scenarios
    ships: list[ShipSampling] = Field(default_factory=lambda: [ShipSampling()])
    path: PathSampling = PathSampling()
    jumps: JumpsConfig = JumpsConfig()
    current: CurrentSampling = CurrentSampling()
    sensors: SensorSampling = SensorSampling()

    @model_validator(mode="after")
    def _valid(self) -> DistributionConfig:
        if self.split == "test" and self.size is None:
            raise ValueError("a test distribution needs 'size' (number of named scenarios)")
        if not self.ships:
            raise ValueError("'ships' must list at least one ship")
        lo, hi = self.path.legs
        if lo < 1 or hi < lo:
            raise ValueError(f"path.legs must be [low ≥ 1, high ≥ low], got {self.path.legs}")
        from shipgym.models import MODELS, ParameterError

        for i, ship in enumerate(self.ships):
            if ship.model not in MODELS:
                raise ValueError(
                    f"ships.{i}.model: unknown model {ship.model!r}; valid: {sorted(MODELS)}"
                )
            try:
                MODELS[ship.model].from_config(ship.params, ship.unit_reading, ship.variant)
            except ParameterError as exc:
                raise ValueError(f"ships.{i}.params: {exc}") from None
            for pname in ship.param_factors:
                if pname not in ship.params:
                    raise ValueError(
                        f"ships.{i}.param_factors.{pname}: no nominal value in ships.{i}.params"
                    )
            for kind_name, kind in self.jumps.kinds.items():
                for pname, spec in kind.params.items():
                    if spec.mode != "value" and pname not in ship.params:
                        raise ValueError(
                            f"jumps.kinds.{kind_name}.params.{pname}: mode {spec.mode!r} "
                            f"needs a nominal value in ships[].params for {ship.model}"
                        )
        return self


class DistributionError(ConfigError):
    """A distribution cannot be found or is malformed (names the file and key)."""


def list_distributions() -> list[str]:
    """Names of the packaged distributions (``configs/distributions``)."""
    return list_names("distributions")


def _uniform(rng: np.random.Generator, r: Range) -> float:
    return float(r[0]) if r[0] == r[1] else float(rng.uniform(r[0], r[1]))


class ScenarioDistribution:
    """Samples :class:`ScenarioConfig` objects from a :class:`DistributionConfig`."""

    def __init__(self, config: DistributionConfig) -> None:
        self.config = config

    @property
    def name(self) -> str:
        return self.config.name

    @property
    def split(self) -> str:
        return self.config.split

    def __len__(self) -> int:
        if self.config.size is None:
            raise TypeError(f"distribution {self.name!r} (train split) has no fixed size")
        return self.config.size

    def sample(self, rng: np.random.Generator, name: str | None = None) -> ScenarioConfig:
        """One scenario config drawn with ``rng`` (all randomness from it, in a fixed order)."""
        c = self.config
        ship = c.ships[int(rng.integers(len(c.ships)))]
        params = dict(ship.params)
        for pname, r in ship.param_factors.items():  # validated at load
            params[pname] = params[pname] * _uniform(rng, r)
        length, speed = _ship_scale(ship)
        waypoints, path_length = _sample_waypoints(c.path, length, rng)
        pchip = rng.random() < c.path.pchip_probability
        events = []
        kinds = list(c.jumps.kinds.items())
        if kinds and rng.random() < c.jumps.probability:
            weights = np.array([k.weight for _, k in kinds])
            _, kind = kinds[int(rng.choice(len(kinds), p=weights / weights.sum()))]
            changed = {}
            for pname, spec in kind.params.items():
                x = _uniform(rng, spec.range)
                base = params.get(pname, 0.0)
                changed[pname] = (
                    base * x if spec.mode == "factor" else base + x if spec.mode == "add" else x
                )
            event: dict[str, Any] = {"time": round(_uniform(rng, c.jumps.time), 2)}
            event["params"] = changed
            if rng.random() < kind.ramp_probability:
                event["kind"] = "ramp"
                event["duration"] = round(_uniform(rng, kind.ramp_duration), 2)
            events.append(event)
        current = {"speed": 0.0, "direction_deg": 0.0}
        if rng.random() < c.current.probability:
            current = {
                "speed": _uniform(rng, c.current.speed),
                "direction_deg": _uniform(rng, c.current.direction_deg),
            }
        sensors = {
            "heading_noise_deg": _uniform(rng, c.sensors.heading_noise_deg),
            "outlier_probability": _uniform(rng, c.sensors.outlier_probability),
        }
        time_limit = math.ceil(c.path.time_factor * path_length / speed + 10.0)
        data = {
            "name": name or f"{c.name}:sample",
            "description": f"sampled from distribution {c.name!r} ({c.split} split)",
            "source": "shipgym.scenarios.sampling",
            "ship": {
                "model": ship.model,
                "unit_reading": ship.unit_reading,
                "variant": ship.variant,
                "params": params,
            },
            "initial_state": {"x": 0.0, "y": 0.0, "heading_deg": 0.0},
            "path": {"type": "pchip" if pchip else "waypoints", "waypoints": waypoints},
            "disturbances": {"current": current},
            "sensors": sensors,
            "events": events,
            "time_limit": float(time_limit),
        }
        return ScenarioConfig.model_validate(data)

    def test_scenario(self, index: int) -> ScenarioConfig:
        """The ``index``-th named scenario of a test split (``"<name>:<index>"``)."""
        if self.split != "test":
            raise DistributionError(
                f"{self.name!r} is a {self.split} distribution; only test splits have named "
                "scenarios"
            )
        if not 0 <= index < len(self):
            raise DistributionError(
                f"{self.name}: index {index} out of range; valid: 0 … {len(self) - 1}"
            )
        return self.sample(test_rng(self.name, index), name=f"{self.name}:{index}")

    def test_names(self) -> list[str]:
        return [f"{self.name}:{i}" for i in range(len(self))]


def test_rng(distribution: str, index: int) -> np.random.Generator:
    """Generator of the ``index``-th scenario of a test distribution (test seed space)."""
    key = zlib.crc32(distribution.encode())
    return np.random.default_rng(np.random.SeedSequence([TEST_SALT, key, index]))


def train_scenario_seed(rng: np.random.Generator) -> int:
    """A training scenario seed drawn from an env's generator (train seed space)."""
    return int(rng.integers(0, 2**62))


def train_rng(scenario_seed: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence([TRAIN_SALT, scenario_seed]))


def _ship_scale(ship: ShipSampling) -> tuple[float, float]:
    """Length [m] and nominal speed [m/s] of the sampled ship (with its nominal params)."""
    from shipgym.models import MODELS

    if ship.model not in MODELS:
        raise DistributionError(f"unknown ship model {ship.model!r}; valid: {sorted(MODELS)}")
    model = MODELS[ship.model].from_config(ship.params, ship.unit_reading, ship.variant)
    return model.length, model.nominal_speed


def _sample_waypoints(
    p: PathSampling, length: float, rng: np.random.Generator
) -> tuple[list[tuple[float, float]], float]:
    """Waypoints starting ≈ 1 L ahead of the ship (which starts at the origin, heading 0)."""
    n_legs = int(rng.integers(p.legs[0], p.legs[1] + 1))
    x, y = length, _uniform(rng, p.start_offset_L) * length
    points = [(round(x, 3), round(y, 3))]
    heading, total = 0.0, 0.0
    for i in range(n_legs):
        if i > 0:
            heading += math.radians(_uniform(rng, p.turn_deg))
        leg = _uniform(rng, p.leg_length_L) * length
        x += leg * math.cos(heading)
        y += leg * math.sin(heading)
        total += leg
        points.append((round(x, 3), round(y, 3)))
    return points, total + length


def load_distribution(name_or_path: str | os.PathLike) -> ScenarioDistribution:
    """A distribution by name (``configs/distributions/<name>.yaml``) or YAML path."""
    file = resolve("distributions", name_or_path, error=DistributionError)
    return ScenarioDistribution(load_yaml_model(file, DistributionConfig, DistributionError))


def sampled_scenario_config(name: str) -> ScenarioConfig:
    """The config of a named test scenario ``"<distribution>:<index>"``."""
    dist_name, _, index = name.partition(":")
    if not index.isdigit():
        raise DistributionError(f"sampled scenario names look like 'heldout:3', got {name!r}")
    return load_distribution(dist_name).test_scenario(int(index))
