"""Controller names -> factories (the names used by suites, the CLI and the leaderboard).

A controller declares itself once, where it is defined::

    @register_controller("pid_los")
    class PIDLOS: ...

    register_controller("pid_los_fast", make_fast_pid)  # a factory function

The registration is the single record of the controller's name, the action mode it drives
and the ships it applies to; the instances made by :func:`make_controller` carry that name
and action mode (a class as class attributes, a factory function's policy as attributes
set on it).
The built-in controllers register when their modules are imported, which this module does
(so the registry is full once ``baselines.registry`` is imported).
"""

from __future__ import annotations

import dataclasses
import importlib
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from types import MappingProxyType
from typing import Any, TypeVar, overload

from baselines.errors import ControllerError
from baselines.policy import Policy
from shipgym.envs.core import ACTION_MODES
from shipgym.models import MODELS

#: modules whose controllers register themselves on import
BUILTIN_MODULES = (
    "baselines.classical.pid",
    "baselines.classical.lqr",
    "baselines.classical.l1_backstepping",
    "baselines.classical.nmpc",
    "baselines.classical.reference",
)

Factory = TypeVar("Factory", bound=Callable[..., Any])


@dataclasses.dataclass(frozen=True)
class ControllerRecord:
    """One registered controller.

    ``factory(**settings)`` makes a fresh :class:`~baselines.policy.Policy`;
    ``action_mode`` is the env mode it drives; ``applies_to`` the ship ids it runs on
    (None: every ship); ``kind`` is ``"classical"`` unless the factory says otherwise.
    """

    name: str
    factory: Callable[..., Policy]
    action_mode: str = "rudder"
    applies_to: tuple[str, ...] | None = None
    kind: str = "classical"


_RECORDS: dict[str, ControllerRecord] = {}
#: read-only view: name -> record, in registration order
CONTROLLERS: Mapping[str, ControllerRecord] = MappingProxyType(_RECORDS)


@overload
def register_controller(
    name: str,
    factory: None = None,
    *,
    action_mode: str = "rudder",
    applies_to: Sequence[str] | None = None,
) -> Callable[[Factory], Factory]: ...


@overload
def register_controller(
    name: str,
    factory: Factory,
    *,
    action_mode: str = "rudder",
    applies_to: Sequence[str] | None = None,
) -> Factory: ...


def register_controller(
    name: str,
    factory: Factory | None = None,
    *,
    action_mode: str = "rudder",
    applies_to: Sequence[str] | None = None,
) -> Factory | Callable[[Factory], Factory]:
    """Register ``factory`` (a Policy class or a function returning a Policy) as ``name``.

    As a call, ``register_controller(name, factory)`` returns ``factory``; without a
    factory it returns a decorator for a class or function.  A class gets ``name`` and
    ``action_mode`` as class attributes (so it must not declare different ones: register
    an alias through a factory function).  ``action_mode``: "rudder" | "guidance";
    ``applies_to``: the ship ids of :data:`shipgym.models.MODELS` the controller runs on
    (None: every ship).  A name registered to another factory is an error.
    """
    if factory is None:

        def decorate(f: Factory) -> Factory:
            return register_controller(name, f, action_mode=action_mode, applies_to=applies_to)

        return decorate
    if not (isinstance(name, str) and name):
        raise ValueError(f"a controller name must be a non-empty string, got {name!r}")
    if action_mode not in ACTION_MODES:
        raise ValueError(
            f"controller {name!r}: action_mode must be one of {ACTION_MODES}, got {action_mode!r}"
        )
    record = ControllerRecord(
        name=name,
        factory=factory,
        action_mode=action_mode,
        applies_to=_ships(name, applies_to),
        kind=getattr(factory, "kind", "classical"),
    )
    existing = _RECORDS.get(name)
    if existing is not None and existing != record:
        raise ValueError(
            f"controller name {name!r} is taken: {_qualname(existing.factory)} is registered "
            f"under it, so {_qualname(factory)} cannot be; choose another name"
        )
    if isinstance(factory, type):
        declared = {"name": name, "action_mode": action_mode}
        for attr, value in declared.items():
            own = factory.__dict__.get(attr, value)
            if own != value:
                raise ValueError(
                    f"{_qualname(factory)} declares {attr} = {own!r} but is registered "
                    f"with {value!r}: drop the class attribute (the registration sets it)"
                )
        for attr, value in declared.items():
            setattr(factory, attr, value)
    _RECORDS[name] = record
    return factory


def _ships(name: str, applies_to: Sequence[str] | None) -> tuple[str, ...] | None:
    """``applies_to`` as a tuple of known ship ids; a clear error for anything else."""
    if applies_to is None:
        return None
    if isinstance(applies_to, str):
        raise TypeError(f"controller {name!r}: applies_to is a list of ship ids, not a string")
    unknown = [s for s in applies_to if s not in MODELS]
    if unknown:
        raise ValueError(
            f"controller {name!r}: unknown ship(s) {unknown} in applies_to; "
            f"valid: {', '.join(sorted(MODELS))}"
        )
    return tuple(applies_to)


def _qualname(factory: Callable[..., Any]) -> str:
    module = getattr(factory, "__module__", None)
    qualname = getattr(factory, "__qualname__", repr(factory))
    return f"{module}.{qualname}" if module else qualname


def applies_to(controller: str, ship: str) -> bool:
    """Whether ``controller`` runs on ``ship`` (learned agents and the rest: every ship)."""
    record = _RECORDS.get(controller)
    return record is None or record.applies_to is None or ship in record.applies_to


def controller_kind(controller: str) -> str:
    """``"classical"`` for a registered controller (unless it says otherwise), else
    ``"learned"``."""
    record = _RECORDS.get(controller)
    return record.kind if record is not None else "learned"


def is_controller(name: str) -> bool:
    """Whether ``name`` is a registered controller, a shipped learned policy or a path."""
    return name in _RECORDS or _learned_policy_path(name) is not None


def _learned_policy_path(name: str) -> Path | None:
    """The folder or zip of the learned policy ``name`` means (a shipped policy's name
    before a path of the same name); None when it is neither."""
    from baselines.learned.policy import POLICY_DIR, shipped_policies

    if name in shipped_policies():
        return POLICY_DIR / name
    return Path(name) if Path(name).exists() else None


def unknown_controller(name: str) -> str:
    """The error message for a name :func:`is_controller` rejects: the valid names."""
    from baselines.learned.policy import shipped_policies

    return (
        f"unknown controller {name!r}; valid: {', '.join(sorted(_RECORDS))}, the learned "
        f"policies {', '.join(shipped_policies())} or a trained agent's path"
    )


def make_controller(name: str, **settings: Any) -> tuple[Policy, str]:
    """A fresh controller and the action mode it needs; unknown names list the valid ones.

    ``name`` is a registered controller (made with ``settings``), a shipped learned policy
    (``ppo``, …, in ``baselines/learned/policies``) or the path of a trained agent.
    """
    record = _RECORDS.get(name)
    if record is not None:
        policy = record.factory(**settings)
        for attr in ("name", "action_mode"):  # a factory function's policy learns them here
            if getattr(policy, attr, None) != getattr(record, attr):
                setattr(policy, attr, getattr(record, attr))
        if not hasattr(policy, "kind"):
            policy.kind = record.kind
        return policy, record.action_mode
    path = _learned_policy_path(name)
    if path is not None:
        from baselines.learned.policy import LearnedPolicy

        policy = LearnedPolicy(path)
        return policy, policy.action_mode
    raise ControllerError(unknown_controller(name))


for _module in BUILTIN_MODULES:
    importlib.import_module(_module)
