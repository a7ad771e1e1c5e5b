"""A ship's record: everything the package knows about one ship, declared in its model file.

Each model module ends with its :class:`Ship`: the model class (which itself holds the name,
the parameter record, the hull and the loading change), the gymnasium ids (:class:`EnvId`),
the published values of its hull (:class:`Published`), the quantities an online estimator
adapts (:class:`Quantity`) and whether the ship is held out of tuning and training.
:data:`SHIPS` collects the records (``shipgym.models`` registers the package's own); every
per-ship table (``MODELS``, ``HULLS``, ``UNSEEN_HULLS``, ``QUANTITIES``, ``PUBLISHED``,
``shipgym.ENV_IDS``) is a :class:`ShipTable`, read off the records when it is read, so that a
ship registered later (:func:`registered`) is in every table.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
from abc import abstractmethod
from collections.abc import Callable, Collection, Iterable, Iterator, Mapping, Set
from typing import TypeVar

from shipgym.models.base import ParameterRecord, ShipModel
from shipgym.models.hull import Hull

V = TypeVar("V")


@dataclasses.dataclass(frozen=True)
class EnvId:
    """One gymnasium id of a ship: the id, its default scenario (a catalogue name or a YAML
    path) and its spec's ``max_episode_steps`` (the scenario's ceil(time_limit / Ts))."""

    id: str
    scenario: str
    max_episode_steps: int


@dataclasses.dataclass(frozen=True)
class Published:
    """One published value of a hull: our figure it compares with, the value (in the
    figure's unit), its source and, when asserted, the relative tolerance and why."""

    figure: str  # a key of shipgym.validation.FIGURES, with "_port" or "_mean"
    value: float
    source: str
    tolerance: float | None = None  # relative; None: shown, not asserted (see note)
    note: str = ""


@dataclasses.dataclass(frozen=True)
class Quantity:
    """One quantity an online estimator adapts (:mod:`shipgym.identification.adaptation`):
    η = ln(factor) on ``params`` (or the draught, ``draught``), bounded to
    ``[ln low, ln high]``."""

    name: str
    params: tuple[str, ...]  # the model parameters × e^η (empty for the draught)
    low: float  # factor [-]
    high: float  # factor [-]
    draught: bool = False  # η is ln of the draught ratio (loading_change)

    @property
    def bounds(self) -> tuple[float, float]:
        """(ln low, ln high)."""
        return math.log(self.low), math.log(self.high)


def servo_quantity(param: str) -> Quantity:
    """The servo time constant ``param`` × [1/2, 400]: aging only slows a servo (the
    catalogue's rudder aging is ×3–×60 on four ships and ×200 on the KVLCC2)."""
    return Quantity("servo", (param,), 0.5, 400.0)


def rate_quantity(param: str) -> Quantity:
    """The rudder rate limit ``param`` × [1/10, 2]."""
    return Quantity("rate", (param,), 0.1, 2.0)


def rudder_quantity(*params: str) -> Quantity:
    """The rudder effectiveness ``params`` × [1/3, 3]."""
    return Quantity("rudder", params, 1.0 / 3.0, 3.0)


#: the draught ratio × [0.3, 1.6] (the catalogue's loading changes are ×0.4 and ×1.35)
DRAUGHT = Quantity("draught", (), 0.3, 1.6, draught=True)


def hull_quantities(servo: str, rate: str, *rudder: str) -> tuple[Quantity, ...]:
    """What an estimator adapts on a hull with a steering gear, in this order: the servo time
    constant ``servo``, the rate limit ``rate``, the rudder effectiveness ``rudder`` and the
    draught."""
    return servo_quantity(servo), rate_quantity(rate), rudder_quantity(*rudder), DRAUGHT


@dataclasses.dataclass(frozen=True)
class Ship:
    """One ship: its model class and what the rest of the package reads per ship."""

    model: type[ShipModel]
    #: the quantities an online estimator adapts (their order is the estimator's)
    adapted: tuple[Quantity, ...]
    #: the gymnasium ids of the ship, the first its oldest
    env_ids: tuple[EnvId, ...] = ()
    #: the published values of its hull (``shipgym.validation`` measures ours beside them)
    published: tuple[Published, ...] = ()
    #: no controller is tuned or trained on the ship (the leaderboard's unseen-hull split)
    unseen: bool = False

    @property
    def name(self) -> str:
        """The model id (scenario files' ``ship.model``)."""
        return self.model.name

    @property
    def params(self) -> type[ParameterRecord]:
        """The parameter record (its defaults: the ship's nominal values)."""
        return self.model.params_type

    @property
    def hull(self) -> Hull | None:
        """Main particulars for a loading change (None: the model has no loading change)."""
        return self.model.hull

    @property
    def loading_change(self) -> Callable[..., dict[str, float]]:
        """The model's loading change (``ShipModel.loading_change``)."""
        return self.model.loading_change

    @property
    def length(self) -> float:
        """Length L [m] at the default parameters."""
        return self.model().length

    @property
    def nominal_speed(self) -> float:
        """Nominal speed [m/s] at the default parameters."""
        return self.model().nominal_speed


#: model id -> record, in the order listings show the ships (docs, CLI)
SHIPS: dict[str, Ship] = {}


def register(ship: Ship) -> Ship:
    """Add ``ship`` to :data:`SHIPS` (a ValueError if its name is taken)."""
    if ship.name in SHIPS:
        raise ValueError(f"a ship named {ship.name!r} is registered already")
    SHIPS[ship.name] = ship
    return ship


@contextlib.contextmanager
def registered(ship: Ship) -> Iterator[Ship]:
    """``ship`` in :data:`SHIPS` for the ``with`` block, removed after."""
    register(ship)
    try:
        yield ship
    finally:
        del SHIPS[ship.name]


class _ShipView(Collection[str]):
    """Keys read off :data:`SHIPS` at every access (:meth:`_read`: the current ones)."""

    @abstractmethod
    def _read(self) -> Collection[str]: ...

    def __iter__(self) -> Iterator[str]:
        return iter(self._read())

    def __len__(self) -> int:
        return len(self._read())

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._read()!r})"


class ShipTable(_ShipView, Mapping[str, V]):
    """A per-ship table read off :data:`SHIPS` at every access: ``entries`` gives a record's
    (key, value) pairs (none, one or several)."""

    def __init__(self, entries: Callable[[Ship], Iterable[tuple[str, V]]]) -> None:
        self._entries = entries

    def _read(self) -> dict[str, V]:
        return {key: value for ship in SHIPS.values() for key, value in self._entries(ship)}

    def __getitem__(self, key: str) -> V:
        return self._read()[key]


class ShipSet(_ShipView, Set[str]):
    """The names of the ships whose record satisfies ``test``, read off :data:`SHIPS` at
    every access."""

    def __init__(self, test: Callable[[Ship], bool]) -> None:
        self._test = test

    def _read(self) -> list[str]:
        return [name for name, ship in SHIPS.items() if self._test(ship)]

    def __contains__(self, name: object) -> bool:
        return name in self._read()
