"""Randomised scenario distributions for training and held-out testing (docs/learned-agents.md).

A *distribution* (YAML in ``configs/distributions/``) lists ships; each ship gives ranges
for its nominal parameters, its own parameter jumps (which parameters, how large, when),
loading-condition changes (a draught ratio, :mod:`shipgym.models.loading`), current shifts
(a current appearing) or a combination of them at one time, its background current and wave
disturbance, its guidance laws and the margin of its time limit.  The path (number of legs,
leg lengths in ship lengths, turn angles, polyline or PCHIP; a ship may give its own) and
the sensor noise are shared.  The time limit is ``time_factor · route length / (U − the
largest current speed) + time_margin``.  :meth:`ScenarioDistribution.sample` turns a random
generator into an ordinary :class:`~shipgym.scenarios.schema.ScenarioConfig`, so a sampled
scenario runs through exactly the same loader, env and metrics as a catalogue one; its
control period and fine step are the ship's own.

Ships.  A train split draws the ship per scenario with probability ∝ its ``weight``; a test
split lists ``count`` named scenarios per ship, interleaved round-robin in the order of
``ships`` (``heldout:0`` the first ship's first scenario, ``heldout:1`` the second ship's
first, …, and when a ship has run out the others continue in turn).

Splits.  Every distribution has a ``split``: ``train`` or ``test``.  Test scenarios are
addressed by name, ``"<distribution>:<index>"`` (e.g. ``heldout:3``); the ``j``-th scenario
of ship ``k`` is drawn from ``SeedSequence([TEST_SALT, crc32(name), j], spawn_key=(k,))``
(no spawn key for the first ship, so that a one-ship distribution keeps the scenarios it
had).  Training envs draw theirs from the env's own seeded generator through
:func:`train_scenario_seed` and ``SeedSequence([TRAIN_SALT, seed])``, a seed space disjoint
from the test one (tested).  The ``heldout`` distribution contains jump kinds and sizes
outside the training ranges, on every ship (the leaderboard's generalisation rows);
``validation`` (training ranges, test seed space) is what tuning scores on and training
evaluates on to keep its best model; ``inrange`` (training ranges, test seed space under
its own name, so none of its scenarios is a validation one) is the leaderboard's in-range
split.  ``heldout`` and ``inrange`` are ``test_only``: tuning and model selection refuse
them.  An unseen hull (:data:`shipgym.models.UNSEEN_HULLS`: the KVLCC2) may be listed only
by a ``test_only`` distribution, so no training or validation trial is ever on it.

Units are those of scenario configs: lengths in ship lengths where a key ends in ``_L``,
angles in degrees where it ends in ``_deg``, times in s, speeds in m/s, ship parameters in
the model's config units (nomoto2: d0 in °/s).
"""

from __future__ import annotations

import functools
import math
import os
import zlib
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import AfterValidator, Field, model_validator

from shipgym.config import (
    ConfigError,
    StrictModel,
    list_names,
    load_yaml_model,
    read_yaml,
    resolve,
)
from shipgym.models import UNSEEN_HULLS
from shipgym.models.loading import HULLS, loading_change
from shipgym.scenarios.schema import ScenarioConfig

#: salts of the two seed spaces: test scenarios come from SeedSequence([TEST_SALT, ·, j]),
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


class CurrentShift(StrictModel):
    """A current appearing at the jump time (calm before): speed [m/s], direction it flows
    to [deg], each uniform in its range."""

    speed: Range
    direction_deg: Range = (0.0, 360.0)


class JumpKind(StrictModel):
    """A named kind of event: a change of one or more parameters together (``params``), a
    loading-condition change (``draught_ratio``: the draught × U(range), every parameter
    it moves by :func:`shipgym.models.loading.loading_change`; 3-DOF ships), a current
    appearing (``current``), or a combination of them at the same time (e.g. rudder aging
    and a current).  ``linked``: one uniform draw places every parameter at the same
    relative point of its range (e.g. both rudder derivatives by one factor)."""

    weight: float = Field(1.0, gt=0)
    params: dict[str, JumpSpec] = Field(default_factory=dict)
    linked: bool = False
    draught_ratio: Range | None = None
    current: CurrentShift | None = None
    ramp_probability: float = Field(0.0, ge=0, le=1)
    ramp_duration: Range = (2.0, 10.0)  # s

    @model_validator(mode="after")
    def _changes_something(self) -> JumpKind:
        if not (self.params or self.draught_ratio is not None or self.current is not None):
            raise ValueError("a jump kind gives 'params', 'draught_ratio' or 'current'")
        if self.draught_ratio is not None and self.draught_ratio[0] <= 0:
            raise ValueError(f"draught_ratio: must be > 0, got {list(self.draught_ratio)}")
        return self


class JumpsConfig(StrictModel):
    probability: float = Field(0.8, ge=0, le=1)  # chance that an episode has a jump
    time: Range = (8.0, 30.0)  # s
    kinds: dict[str, JumpKind] = Field(default_factory=dict)
    #: ``random``: the kind drawn by weight; ``cycle`` (test splits): the j-th scenario of
    #: the k-th ship has kind (j + k) mod (number of kinds), so that a few scenarios cover
    #: every kind and the ships' first scenarios show different ones
    order: Literal["random", "cycle"] = "random"


class PathSampling(StrictModel):
    legs: tuple[int, int] = (2, 4)  # number of legs, inclusive
    leg_length_L: Range = (10.0, 20.0)
    turn_deg: Range = (-90.0, 90.0)  # heading change at each inner waypoint
    start_offset_L: Range = (-1.5, 1.5)  # lateral offset of the first waypoint
    pchip_probability: float = Field(0.0, ge=0, le=1)
    #: time limit = time_factor · route length / (U − the scenario's largest current speed)
    #: + the ship's time_margin
    time_factor: float = Field(1.6, gt=1)


class CurrentSampling(StrictModel):
    probability: float = Field(0.0, ge=0, le=1)
    speed: Range = (0.0, 0.0)  # m/s
    direction_deg: Range = (0.0, 360.0)


class WaveSampling(StrictModel):
    """Wind-wave yaw disturbance (Pierson–Moskowitz wave filter,
    :class:`~shipgym.disturbance_config.WaveConfig`) with
    ``probability``; ``wind_speed`` [m/s] uniform in its range, ``gain`` in the model's
    yaw_disturbance unit per metre of filter output."""

    probability: float = Field(0.0, ge=0, le=1)
    wind_speed: Range = (10.0, 10.0)
    gain: float = Field(gt=0)


class SensorSampling(StrictModel):
    heading_noise_deg: Range = (0.0, 0.0)
    outlier_probability: Range = (0.0, 0.0)


class ShipSampling(StrictModel):
    """One ship of a distribution and what is sampled for it."""

    model: str = "nomoto2"
    unit_reading: str | None = None
    variant: str | None = None
    params: dict[str, float] = Field(default_factory=dict)  # nominal values (config units)
    #: nominal·U(range); a parameter not in ``params`` starts from the model's default (for
    #: models whose config units are SI)
    param_factors: dict[str, Range] = Field(default_factory=dict)
    weight: float | None = Field(None, gt=0)  # train split: relative chance per scenario
    count: int | None = Field(None, ge=1)  # test split: number of named scenarios
    time_margin: float = Field(10.0, ge=0)  # s added to the time limit
    path: PathSampling | None = None  # None: the distribution's
    #: guidance law of the scenario, drawn uniformly (its other settings: the defaults)
    guidance_laws: tuple[Literal["los", "lookahead_los", "vf", "tvvf"], ...] = ("los",)
    jumps: JumpsConfig = JumpsConfig()
    current: CurrentSampling = CurrentSampling()
    waves: WaveSampling | None = None


class DistributionConfig(StrictModel):
    name: str
    description: str = ""
    split: Literal["train", "test"]
    #: test splits the leaderboard ranks and nothing else reads: tuning and model selection
    #: refuse them (``heldout``, ``inrange``)
    test_only: bool = False
    #: test splits: number of named scenarios (one ship; else each ship's ``count``)
    size: int | None = Field(None, ge=1)
    #: test splits: the ships, path and sensors of this distribution (the training ranges
    #: in the test seed space), ``count_per_ship`` named scenarios of each ship
    ranges_of: str | None = None
    count_per_ship: int | None = Field(None, ge=1)
    #: with ``ranges_of``: every ship's ``jumps.order`` (``cycle``: the named scenarios step
    #: through the change kinds, so that a few cover every family; None: the train split's)
    jump_order: Literal["random", "cycle"] | None = None
    #: with ``ranges_of``: every ship's ``jumps.probability`` (1: every named scenario has
    #: its change; None: the train split's)
    jump_probability: float | None = Field(None, ge=0, le=1)
    ships: list[ShipSampling] = Field(default_factory=lambda: [ShipSampling()])
    path: PathSampling = PathSampling()
    sensors: SensorSampling = SensorSampling()

    @model_validator(mode="before")
    @classmethod
    def _ranges_of(cls, data: Any) -> Any:
        """Fill ``ships``, ``path`` and ``sensors`` from the ``ranges_of`` distribution."""
        if not isinstance(data, dict) or data.get("ranges_of") is None:
            return data
        own = [key for key in ("ships", "path", "sensors") if key in data]
        if own:
            raise ValueError(f"{own[0]}: comes from ranges_of ({data['ranges_of']!r})")
        if data.get("split") != "test":
            raise ValueError("ranges_of: only a test split takes another distribution's ranges")
        if data.get("count_per_ship") is None:
            raise ValueError("count_per_ship: ranges_of needs the named scenarios per ship")
        file = resolve("distributions", data["ranges_of"], error=DistributionError)
        if not isinstance(raw := read_yaml(file, DistributionError), dict) or (
            raw.get("split") != "train"
        ):
            raise ValueError(f"ranges_of: {data['ranges_of']!r} is not a train split")
        base = load_yaml_model(file, DistributionConfig, DistributionError)
        ships = [
            {**ship.model_dump(exclude={"weight", "count"}), "count": data["count_per_ship"]}
            for ship in base.ships
        ]
        jumps = {
            key: data[field]
            for key, field in (("order", "jump_order"), ("probability", "jump_probability"))
            if data.get(field) is not None
        }
        for ship in ships:
            ship["jumps"] = {**ship["jumps"], **jumps}
        return {
            **data,
            "ships": ships,
            "path": base.path.model_dump(),
            "sensors": base.sensors.model_dump(),
        }

    @model_validator(mode="after")
    def _valid(self) -> DistributionConfig:
        if not self.ships:
            raise ValueError("'ships' must list at least one ship")
        for key, path in [("path", self.path)] + [
            (f"ships.{i}.path", ship.path) for i, ship in enumerate(self.ships) if ship.path
        ]:
            lo, hi = path.legs
            if lo < 1 or hi < lo:
                raise ValueError(f"{key}.legs must be [low ≥ 1, high ≥ low], got {path.legs}")
        self._check_split()
        for i, ship in enumerate(self.ships):
            _check_ship(ship, f"ships.{i}", self.split, self.path)
            if ship.model in UNSEEN_HULLS and not self.test_only:
                raise ValueError(
                    f"ships.{i}.model: {ship.model} is an unseen hull (no controller is tuned "
                    "or trained on it): only a test_only distribution may list it"
                )
        return self

    def _check_split(self) -> None:
        if self.count_per_ship is not None and self.ranges_of is None:
            raise ValueError("count_per_ship: only with ranges_of (else each ship's 'count')")
        for field in ("jump_order", "jump_probability"):
            if getattr(self, field) is not None and self.ranges_of is None:
                raise ValueError(f"{field}: only with ranges_of (else each ship's jumps)")
        if self.split == "train":
            if self.test_only:
                raise ValueError("test_only: only a test split is kept for testing")
            for i, ship in enumerate(self.ships):
                if ship.count is not None:
                    raise ValueError(f"ships.{i}.count: a train split draws ships by 'weight'")
            if self.size is not None:
                raise ValueError("size: only test splits have named scenarios")
            return
        for i, ship in enumerate(self.ships):
            if ship.weight is not None:
                raise ValueError(f"ships.{i}.weight: a test split lists 'count' per ship")
        counts = [ship.count for ship in self.ships]
        if len(self.ships) == 1 and counts[0] is None:
            if self.size is None:
                raise ValueError("a test distribution needs 'size' (number of named scenarios)")
            return
        missing = [i for i, c in enumerate(counts) if c is None]
        if missing:
            raise ValueError(
                f"ships.{missing[0]}.count: a test split with several ships "
                "gives each ship's number of named scenarios"
            )
        if self.size is not None and self.size != sum(counts):
            raise ValueError(
                f"size: {self.size} is not the sum of the ships' counts ({sum(counts)})"
            )

    def ship_counts(self) -> list[int]:
        """Named scenarios per ship (test splits)."""
        if len(self.ships) == 1 and self.ships[0].count is None:
            return [int(self.size or 0)]
        return [int(ship.count or 0) for ship in self.ships]


def _check_ship(ship: ShipSampling, key: str, split: str, path: PathSampling) -> None:
    """A known model with valid nominal parameters, currents below its speed, and jumps a
    real plant can take within the shortest route's time limit (module doc)."""
    from shipgym.models import MODELS
    from shipgym.models.base import ParameterError

    if ship.model not in MODELS:
        raise ValueError(f"{key}.model: unknown model {ship.model!r}; valid: {sorted(MODELS)}")
    try:
        model = MODELS[ship.model].from_config(ship.params, ship.unit_reading, ship.variant)
    except ParameterError as exc:
        raise ValueError(f"{key}.params: {exc}") from None
    if not ship.guidance_laws:
        raise ValueError(f"{key}.guidance_laws: list at least one law")
    currents = [("current.speed", ship.current.speed)] + [
        (f"jumps.kinds.{name}.current.speed", kind.current.speed)
        for name, kind in ship.jumps.kinds.items()
        if kind.current is not None
    ]
    for where, r in currents:
        if r[1] >= model.nominal_speed:
            raise ValueError(
                f"{key}.{where}: a current of {r[1]} m/s is not below the ship's speed "
                f"({model.nominal_speed:.4g} m/s): the route could not be finished"
            )
    for pname in ship.param_factors:
        _check_param(ship, f"{key}.param_factors.{pname}", pname, f"{key}.params")
    _check_jumps(ship, key, split, _shortest_time_limit(ship.path or path, ship, model))


def _check_jumps(ship: ShipSampling, key: str, split: str, shortest: float) -> None:
    """Jump times before ``shortest`` [s]; each parameter change at both ends of its range
    builds the model."""
    from shipgym.models import MODELS
    from shipgym.models.base import ParameterError

    jumps = ship.jumps
    if jumps.kinds and jumps.time[1] >= shortest:
        raise ValueError(
            f"{key}.jumps.time: a jump at {jumps.time[1]} s would come after the shortest "
            f"route's time limit ({shortest:.0f} s)"
        )
    if jumps.order == "cycle" and split != "test":
        raise ValueError(f"{key}.jumps.order: 'cycle' is for test splits (named scenarios)")
    for kind_name, kind in jumps.kinds.items():
        where = f"{key}.jumps.kinds.{kind_name}"
        if kind.draught_ratio is not None and ship.model not in HULLS:
            raise ValueError(
                f"{where}.draught_ratio: no loading-condition model for {ship.model}; "
                f"valid: {sorted(HULLS)}"
            )
        for end in (0, 1):
            changed = dict(ship.params)
            if kind.draught_ratio is not None:
                changed.update(_loading(ship, changed, kind.draught_ratio[end]))
            for pname, spec in kind.params.items():
                if spec.mode != "value":
                    _check_param(ship, f"{where}.params.{pname}", pname, f"{key}.params")
                base = _nominal(ship, pname) or 0.0
                changed[pname] = _changed(spec, base, spec.range[end])
            try:
                MODELS[ship.model].from_config(changed, ship.unit_reading, ship.variant)
            except ParameterError as exc:
                key_at_fault = "draught_ratio" if kind.draught_ratio is not None else "params"
                raise ValueError(f"{where}.{key_at_fault}: {exc}") from None


def _shortest_time_limit(path: PathSampling, ship: ShipSampling, model: Any) -> float:
    """Time limit [s] of the shortest route (fewest, shortest legs) in calm water."""
    route = (path.legs[0] * path.leg_length_L[0] + 1.0) * model.length
    return path.time_factor * route / model.nominal_speed + ship.time_margin


def _max_episode_steps(ship: ShipSampling, path: PathSampling) -> int:
    """Control periods of the ship's longest episode: its time limit (as
    :meth:`ScenarioDistribution.sample` sets it) on the longest route (most, longest legs)
    against the strongest current it can draw (background or shift), over its Ts."""
    from shipgym.models import MODELS

    model = MODELS[ship.model].from_config(ship.params, ship.unit_reading, ship.variant)
    route = (path.legs[1] * path.leg_length_L[1] + 1.0) * model.length
    currents = [ship.current.speed[1]]
    currents += [k.current.speed[1] for k in ship.jumps.kinds.values() if k.current is not None]
    # the relative 1e-9: the drawn legs' float sum may round above the product
    over = path.time_factor * route / (model.nominal_speed - max(currents)) * (1.0 + 1e-9)
    time_limit = math.ceil(over + ship.time_margin)
    return math.ceil(time_limit / model.control_period - 1e-9)  # as StepConstants.max_steps


def _check_param(ship: ShipSampling, where: str, pname: str, params_key: str) -> None:
    """A parameter of the ship's model with a known nominal value (factor and add modes)."""
    from shipgym.models import MODELS

    names = MODELS[ship.model].params_type.names()
    if pname not in names:
        raise ValueError(f"{where}: {ship.model} has no parameter {pname!r}; valid: {list(names)}")
    if _nominal(ship, pname) is None:
        raise ValueError(
            f"{where}: needs a nominal value in {params_key} ({ship.model}'s config units "
            "are not SI)"
        )


@functools.cache
def _defaults(model: str) -> dict[str, float]:
    from shipgym.models import MODELS

    return MODELS[model].params_type().as_dict()


def _nominal(ship: ShipSampling, pname: str) -> float | None:
    """The nominal value of a parameter in config units: listed, or the model's default
    when its config units are SI (one unit reading); None if unknown."""
    from shipgym.models import MODELS

    if pname in ship.params:
        return ship.params[pname]
    model_cls = MODELS[ship.model]
    if len(model_cls.unit_readings) == 1:
        return _defaults(ship.model).get(pname)
    return None


def _loading(ship: ShipSampling, params: dict[str, float], ratio: float) -> dict[str, float]:
    """The parameters (config units = SI for the 3-DOF ships) a draught × ``ratio`` moves,
    from the ship's parameters ``params`` before the change."""
    from shipgym.models import MODELS

    record = MODELS[ship.model].from_config(params, ship.unit_reading, ship.variant).params
    return loading_change(ship.model, record, ratio)


def _changed(spec: JumpSpec, base: float, x: float) -> float:
    return base * x if spec.mode == "factor" else base + x if spec.mode == "add" else x


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
        if self.config.split != "test":
            raise TypeError(f"distribution {self.name!r} (train split) has no fixed size")
        return sum(self.config.ship_counts())

    def ship_probabilities(self) -> np.ndarray:
        """Chance of each ship per training scenario (∝ ``weight``, default 1)."""
        weights = np.array([ship.weight or 1.0 for ship in self.config.ships])
        return weights / weights.sum()

    @functools.cached_property
    def test_layout(self) -> list[tuple[int, int]]:
        """(ship index k, the ship's scenario index j) of each named test scenario: the ships
        round-robin in list order, each while it has scenarios left."""
        counts = self.config.ship_counts()
        layout = []
        for j in range(max(counts)):
            layout += [(k, j) for k, count in enumerate(counts) if j < count]
        return layout

    def max_episode_steps(self) -> int:
        """The most control periods an episode of this distribution can last: the longest
        time limit any ship can draw (its longest route against its strongest current,
        module doc) over that ship's control period."""
        return max(
            _max_episode_steps(ship, ship.path or self.config.path) for ship in self.config.ships
        )

    def sample(
        self, rng: np.random.Generator, name: str | None = None, ship_index: int | None = None
    ) -> ScenarioConfig:
        """One scenario config drawn with ``rng`` (all randomness from it, in a fixed order);
        ``ship_index``: this ship of the list (None: drawn by weight)."""
        c = self.config
        if ship_index is None:
            ship_index = (
                0
                if len(c.ships) == 1
                else int(rng.choice(len(c.ships), p=self.ship_probabilities()))
            )
        return self._sample_ship(rng, c.ships[ship_index], name)

    def _sample_ship(
        self,
        rng: np.random.Generator,
        ship: ShipSampling,
        name: str | None,
        kind_index: int | None = None,
    ) -> ScenarioConfig:
        c = self.config
        params = dict(ship.params)
        for pname, r in ship.param_factors.items():  # validated at load
            params[pname] = _nominal(ship, pname) * _uniform(rng, r)
        length, speed = _ship_scale(ship)
        path = ship.path or c.path
        waypoints, path_length = _sample_waypoints(path, length, rng)
        pchip = rng.random() < path.pchip_probability
        events, shift = _sample_jump(ship, params, rng, kind_index)
        current: dict[str, Any] = {"speed": 0.0, "direction_deg": 0.0}
        if shift is not None:
            current = shift
        elif rng.random() < ship.current.probability:
            current = {
                "speed": _uniform(rng, ship.current.speed),
                "direction_deg": _uniform(rng, ship.current.direction_deg),
            }
        sensors = {
            "heading_noise_deg": _uniform(rng, c.sensors.heading_noise_deg),
            "outlier_probability": _uniform(rng, c.sensors.outlier_probability),
        }
        disturbances: dict[str, Any] = {"current": current}
        if ship.waves is not None and rng.random() < ship.waves.probability:
            disturbances["waves"] = {
                "spectrum": "pierson_moskowitz",
                "wind_speed": _uniform(rng, ship.waves.wind_speed),
                "gain": ship.waves.gain,
            }
        laws = ship.guidance_laws
        law = laws[0] if len(laws) == 1 else laws[int(rng.integers(len(laws)))]
        current_speed = max(current["speed"], current.get("second_speed", 0.0))
        time_limit = math.ceil(
            path.time_factor * path_length / (speed - current_speed) + ship.time_margin
        )
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
            "guidance": {"law": law},
            "disturbances": disturbances,
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
        k, j = self.test_layout[index]
        ship = self.config.ships[k]
        kind_index = None
        if ship.jumps.order == "cycle" and ship.jumps.kinds:
            kind_index = (j + k) % len(ship.jumps.kinds)
        rng = test_rng(self.name, j, k)
        return self._sample_ship(rng, ship, f"{self.name}:{index}", kind_index)

    def test_names(self) -> list[str]:
        return [f"{self.name}:{i}" for i in range(len(self))]


def _sample_jump(
    ship: ShipSampling, params: dict[str, float], rng: np.random.Generator, kind_index: int | None
) -> tuple[list[dict[str, Any]], dict[str, Any] | None]:
    """(parameter events, current of a current shift or None) of one scenario."""
    jumps = ship.jumps
    kinds = list(jumps.kinds.values())
    if not kinds or not rng.random() < jumps.probability:
        return [], None
    if kind_index is None:
        weights = np.array([k.weight for k in kinds])
        kind_index = int(rng.choice(len(kinds), p=weights / weights.sum()))
    kind = kinds[kind_index]
    changed = {}
    if kind.draught_ratio is not None:
        changed.update(_loading(ship, params, _uniform(rng, kind.draught_ratio)))
    u = rng.random() if kind.linked and kind.params else None
    for pname, spec in kind.params.items():
        lo, hi = spec.range
        x = _uniform(rng, spec.range) if u is None else lo + u * (hi - lo)
        changed[pname] = _changed(spec, params.get(pname, _nominal(ship, pname) or 0.0), x)
    shift = None
    if kind.current is not None:
        shift = {
            "kind": "two_phase",
            "speed": 0.0,
            "second_speed": _uniform(rng, kind.current.speed),
            "direction_deg": _uniform(rng, kind.current.direction_deg),
            "sigma": 0.0,
        }
    time = round(_uniform(rng, jumps.time), 2)
    ramp = rng.random() < kind.ramp_probability
    duration = round(_uniform(rng, kind.ramp_duration), 2) if ramp else 0.0
    if shift is not None:
        shift.update(switch_time=time, transition_time=duration)
    if not changed:
        return [], shift
    event: dict[str, Any] = {"time": time, "params": changed}
    if ramp:
        event.update(kind="ramp", duration=duration)
    return [event], shift


def test_rng(distribution: str, index: int, ship: int = 0) -> np.random.Generator:
    """Generator of the ``index``-th scenario of ship ``ship`` of a test distribution (test
    seed space; the first ship has no spawn key)."""
    key = zlib.crc32(distribution.encode())
    spawn_key = (ship,) if ship else ()
    return np.random.default_rng(
        np.random.SeedSequence([TEST_SALT, key, index], spawn_key=spawn_key)
    )


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
