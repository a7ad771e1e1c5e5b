"""Controller names -> records (the names used by suites, the CLI and the leaderboard).

A record holds a controller's name, its entry point (how any process finds its factory) and
its traits: the action mode it drives, the ships it applies to, its kind, training seeds,
whether it reads the true plant (``privileged``) and how the figures draw it (its family and
look, :mod:`shipgym_baselines.policy`).  The built-in controllers are a table of entry
points ``"package.module:Attr"`` and traits (:data:`shipgym_baselines.controllers.BUILTINS`):
this module imports no controller, answers every trait from the table, and imports a
controller's module only when its factory is first needed (:attr:`ControllerRecord.factory`,
:func:`make_controller`).  A controller from outside registers at runtime::

    @register_controller("my_policy", family="PID", look=Style("#1f77b4", "-", "o"))
    class MyPolicy: ...

    register_controller("my_policy_fast", make_fast_policy)  # a factory function

The instances made by :func:`make_controller` carry the table name and action mode (a
registered class gets them as class attributes, a factory function's policy as attributes
set on it).

Every other controller is found by :func:`resolve_controller` (all that :func:`make_controller`
accepts): an installed plug-in's entry point, a spec ``module.path:Attr`` or
``path/to/file.py:Attr`` (:mod:`shipgym_baselines.plugins`), the long form of a suite (a display
name and settings), a learned policy or SB3 model zip (:mod:`shipgym_baselines.learned.policy`).
A run resolves each controller once and hands the record to its jobs: a record crosses a
process pool as its entry point, settings and traits, and the process that makes the
controller loads the factory again.  A controller only ever gets ``reset(context, seed)`` and
``act(obs, info)`` from the evaluation loop, whatever its origin.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib.util
import inspect
import types
from collections.abc import Callable, Iterator, Mapping, Sequence
from importlib.metadata import EntryPoint
from pathlib import Path
from typing import Any, TypeVar, overload

from shipgym.envs.core import ACTION_MODES
from shipgym.models import MODELS
from shipgym_baselines.controllers import BUILTINS
from shipgym_baselines.errors import ControllerError
from shipgym_baselines.plugins import (
    ControllerEntry,
    ControllerSpec,
    as_entry,
    entry_point_names,
    find_entry_point,
    load_entry_point,
    load_spec,
    looks_like_path,
    parse_spec,
)
from shipgym_baselines.policy import FAMILIES, Policy, Style

#: the controller every other is compared with: the leaderboard's probability of improvement
#: over it, and a learned agent's selection reference where the oracle's table has none
BASELINE = "pid_los"

Factory = TypeVar("Factory", bound=Callable[..., Any])

#: what a controller is; a "reference" (zero_rudder, random, oracle, oracle_frozen) is shown on
#: every scenario but never ranked as a competitor
KINDS = ("classical", "learned", "reference")


@dataclasses.dataclass(frozen=True)
class ControllerRecord:
    """One controller as a run knows it: its table name, where its factory is and its traits.

    ``controller``: the string it was resolved from (a registered name, a spec, a learned
    policy's name or path; a long form's ``controller``).  ``entry_point``: how any process
    finds the factory: ``"module:Attr"`` or
    ``"path/to/file.py:Attr"`` (a Policy class, a factory function or a Policy instance), or
    the name a factory was registered under in this process (:func:`register_controller`;
    a worker forked from it has it too).  ``settings``: keyword arguments bound to the factory
    (a suite's long form).  :attr:`factory` loads it on first use.  ``action_mode`` is the
    env mode it drives; ``applies_to`` the ship ids it runs on (None: every ship); ``kind``
    one of :data:`KINDS`; ``training_seeds``: a learned policy's (the factory takes
    ``training_seed=k``), else ``(None,)``; ``privileged``: a built-in reference named as
    such, which reads the env's true plant (:mod:`shipgym_baselines.privileged`).
    ``family`` (one of :data:`~shipgym_baselines.policy.FAMILIES`) and ``look``: how the
    figures draw it, as declared (None: not declared; the figures derive them from the kind
    and name).  A record pickles without its loaded factory (it crosses process pools).
    """

    name: str
    controller: str
    entry_point: str
    action_mode: str = "rudder"
    applies_to: tuple[str, ...] | None = None
    kind: str = "classical"
    training_seeds: tuple[int | None, ...] = (None,)
    family: str | None = None
    look: Style | None = None
    privileged: bool = False
    settings: Mapping[str, Any] = dataclasses.field(default_factory=dict, hash=False)
    #: the factory once loaded in this process (not compared, not pickled)
    loaded: Callable[..., Policy] | None = dataclasses.field(
        default=None, compare=False, repr=False
    )

    @property
    def factory(self) -> Callable[..., Policy]:
        """``factory(**settings)`` makes a fresh Policy: the entry point's factory (loaded
        once per process) with :attr:`settings` bound."""
        if self.loaded is None:
            object.__setattr__(self, "loaded", _load_factory(self.entry_point))
        assert self.loaded is not None
        return functools.partial(self.loaded, **self.settings) if self.settings else self.loaded

    def __getstate__(self) -> dict[str, Any]:
        return {**self.__dict__, "loaded": None}


#: a controller as a run refers to it: a name or spec, the long form, or its resolved record
ControllerRef = ControllerSpec | ControllerRecord

_RECORDS: dict[str, ControllerRecord] = {}
#: whether :func:`_read_builtins` has read the table of built-in controllers
_BUILTINS_READ = False


def _read_builtins() -> None:
    """Register the built-in controllers of :data:`~shipgym_baselines.controllers.BUILTINS`,
    once per process, importing none: a reader calls it before reading the records."""
    global _BUILTINS_READ
    if _BUILTINS_READ:
        return
    for builtin in BUILTINS:
        _RECORDS[builtin.name] = ControllerRecord(
            name=builtin.name,
            controller=builtin.name,
            entry_point=builtin.entry_point,
            action_mode=builtin.action_mode,
            applies_to=builtin.applies_to,
            kind=builtin.kind,
            training_seeds=_listed_seeds(builtin.seeds),
            family=builtin.family,
            look=builtin.look,
            privileged=builtin.privileged,
        )
    _BUILTINS_READ = True


def _listed_seeds(lister: str | None) -> tuple[int | None, ...]:
    """The training seeds the function at entry point ``lister`` lists (none, or no lister:
    ``(None,)``)."""
    if lister is None:
        return (None,)
    spec = parse_spec(lister)
    assert spec is not None, lister
    return tuple(load_spec(spec)()) or (None,)


def _load_factory(entry_point: str) -> Callable[..., Policy]:
    """The factory at ``entry_point`` (:class:`ControllerRecord`): a spec's object as a
    factory, or the factory registered under a name (an installed plug-in's is loaded)."""
    spec = parse_spec(entry_point)
    if spec is not None:
        return _traits(load_spec(spec), f"controller {entry_point!r}").factory
    _read_builtins()
    record = _RECORDS.get(entry_point) or _record_of(entry_point)
    # registered under this name, so with its factory: it never loads itself again
    assert record.loaded is not None or record.entry_point != entry_point, entry_point
    return record.factory


class _Registered(Mapping[str, ControllerRecord]):
    """The registrations, read-only, the table of built-in controllers read on first read."""

    def __getitem__(self, name: str) -> ControllerRecord:
        _read_builtins()
        return _RECORDS[name]

    def __iter__(self) -> Iterator[str]:
        _read_builtins()
        return iter(_RECORDS)

    def __len__(self) -> int:
        _read_builtins()
        return len(_RECORDS)

    def __repr__(self) -> str:
        return f"CONTROLLERS({list(self)})"


#: read-only view: name -> record, in registration order
CONTROLLERS: Mapping[str, ControllerRecord] = _Registered()


@overload
def register_controller(
    name: str,
    factory: None = None,
    *,
    action_mode: str = "rudder",
    applies_to: Sequence[str] | None = None,
    family: str | None = None,
    look: Style | None = None,
) -> Callable[[Factory], Factory]: ...


@overload
def register_controller(
    name: str,
    factory: Factory,
    *,
    action_mode: str = "rudder",
    applies_to: Sequence[str] | None = None,
    family: str | None = None,
    look: Style | None = None,
) -> Factory: ...


def register_controller(
    name: str,
    factory: Factory | None = None,
    *,
    action_mode: str = "rudder",
    applies_to: Sequence[str] | None = None,
    family: str | None = None,
    look: Style | None = None,
) -> Factory | Callable[[Factory], Factory]:
    """Register ``factory`` (a Policy class or a function returning a Policy) as ``name``.

    As a call, ``register_controller(name, factory)`` returns ``factory``; without a
    factory it returns a decorator for a class or function.  A class gets ``name`` and
    ``action_mode`` as class attributes (so it must not declare different ones: register
    an alias through a factory function).  ``action_mode``: "rudder" | "guidance";
    ``applies_to``: the ship ids of :data:`shipgym.models.MODELS` the controller runs on
    (None: every ship).  ``family``: the figures' column, one of
    :data:`~shipgym_baselines.policy.FAMILIES` (every built-in declares one); ``look``: its
    :class:`~shipgym_baselines.policy.Style` in every figure (None: the figures derive
    both from the kind and name, :mod:`shipgym_baselines.plots.style`).  A name
    registered to another factory is an error.
    """
    if factory is None:

        def decorate(f: Factory) -> Factory:
            return register_controller(
                name, f, action_mode=action_mode, applies_to=applies_to, family=family, look=look
            )

        return decorate
    _read_builtins()
    if not (isinstance(name, str) and name):
        raise ValueError(f"a controller name must be a non-empty string, got {name!r}")
    if action_mode not in ACTION_MODES:
        raise ValueError(
            f"controller {name!r}: action_mode must be one of {ACTION_MODES}, got {action_mode!r}"
        )
    if family is not None and family not in FAMILIES:
        raise ValueError(f"controller {name!r}: family must be one of {FAMILIES}, got {family!r}")
    if look is not None and not isinstance(look, Style):
        raise TypeError(
            f"controller {name!r}: look is a shipgym_baselines.policy.Style, not {look!r}"
        )
    record = ControllerRecord(
        name=name,
        controller=name,
        entry_point=name,
        action_mode=action_mode,
        applies_to=_ships(f"controller {name!r}", applies_to),
        kind=getattr(factory, "kind", "classical"),
        training_seeds=tuple(getattr(factory, "training_seeds", (None,))),
        family=family,
        look=look,
        loaded=factory,
    )
    existing = _RECORDS.get(name)
    if existing is not None and existing.factory is factory:  # again: keep what it declared
        record = dataclasses.replace(
            record,
            entry_point=existing.entry_point,
            training_seeds=existing.training_seeds,
            privileged=existing.privileged,
            family=family or existing.family,
            look=look or existing.look,
        )
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


def _ships(who: str, applies_to: Sequence[str] | None) -> tuple[str, ...] | None:
    """``applies_to`` as a tuple of known ship ids; a clear error (naming ``who``) for
    anything else."""
    if applies_to is None:
        return None
    if isinstance(applies_to, str):
        raise TypeError(f"{who}: applies_to is a list of ship ids, not a string")
    unknown = [s for s in applies_to if s not in MODELS]
    if unknown:
        raise ValueError(
            f"{who}: unknown ship(s) {unknown} in applies_to; valid: {', '.join(sorted(MODELS))}"
        )
    return tuple(applies_to)


def _qualname(factory: Callable[..., Any]) -> str:
    module = getattr(factory, "__module__", None)
    qualname = getattr(factory, "__qualname__", repr(factory))
    return f"{module}.{qualname}" if module else qualname


# --------------------------------------------------------------------- any controller

#: table name -> record of the controllers resolved in this process that are not
#: registered (specs, learned policies), so that a table name finds its ships and kind
_RESOLVED: dict[str, ControllerRecord] = {}


def resolve_controller(controller: ControllerRef) -> ControllerRecord:
    """The record of any controller a run accepts, its ``name`` the table name (a record
    is its own).

    ``controller`` (short form, a string, or the long form :class:`ControllerEntry`) is
    looked up as, in turn: a registered controller; a shipped learned policy (``ppo``, …);
    a spec ``module.path:Attr`` / ``path/to/file.py:Attr`` naming a Policy class, a factory
    function or a Policy instance; an installed plug-in (entry point group
    ``shipgym.controllers``, loaded and registered on first use); a trained agent's folder
    or an SB3 model zip.  The long form's ``name`` renames it and its ``settings`` are
    bound to the factory (checked against its signature here, before any episode).
    Anything else is a :class:`ControllerError` that lists the valid names.  Only a
    built-in reference named as such, without settings, stays ``privileged``.
    """
    if isinstance(controller, ControllerRecord):
        return controller
    _read_builtins()
    entry = as_entry(controller)
    base = _record_of(entry.controller)
    name = entry.name or base.name
    record = base  # the short form: its record (its factory loaded once per process)
    if name != base.name or entry.settings or entry.controller != base.controller:
        _check_settings(base, entry)
        record = dataclasses.replace(
            base,
            name=name,
            controller=entry.controller,
            settings={**base.settings, **entry.settings},
            look=base.look if name == base.name else None,  # another name: not its look
            privileged=False,  # only a built-in reference named as such reads the truth
        )
    if "training_seed" in entry.settings:  # a long form naming one training seed
        seed = entry.settings["training_seed"]
        record = dataclasses.replace(record, training_seeds=(_check_seed(base, seed),))
    registered = _RECORDS.get(record.name)
    if registered is None:
        _RESOLVED[record.name] = record
    elif registered is not base:
        raise ControllerError(
            f"controller {entry.controller!r} would be shown as {record.name!r}, the name of "
            f"a registered controller ({_qualname(registered.factory)}): give it another "
            "name (its name attribute, or the suite's long form {controller: ..., name: ...})"
        )
    return record


def _record_of(text: str) -> ControllerRecord:
    """The record a controller string means (see :func:`resolve_controller`)."""
    from shipgym_baselines.learned.policy import shipped_policies

    record = _RECORDS.get(text)
    if record is not None:
        return record
    if text in shipped_policies():
        return _learned_record(text)
    spec = parse_spec(text)
    if spec is not None:
        origin, default_name = f"controller {text!r}", spec.attr.split(".")[-1]
        return _plugin_record(load_spec(spec), text, origin, default_name)
    entry_point = None if looks_like_path(text) else find_entry_point(text)
    if entry_point is not None:
        return _entry_point_record(entry_point)
    if text.endswith(".py"):
        raise ControllerError(
            f"controller {text!r} is a Python file: name the Policy in it, {text}:ClassName"
        )
    if Path(text).expanduser().exists():
        return _learned_record(text)
    if looks_like_path(text):
        raise ControllerError(
            f"controller {text!r}: no such file or folder ({Path(text).expanduser().absolute()})"
        )
    raise ControllerError(unknown_controller(text))


def _learned_record(name_or_path: str) -> ControllerRecord:
    """A shipped policy, trained agent's folder or model zip, the files of every training
    seed checked now (one action mode for all)."""
    from shipgym_baselines.learned.policy import (
        AGENT_LOOKS,
        LearnedPolicy,
        policy_label,
        read_policy,
    )
    from shipgym_baselines.learned.policy import training_seeds as policy_seeds

    seeds = policy_seeds(name_or_path)
    files = [read_policy(name_or_path, seed) for seed in seeds]
    modes = {f.model.action_mode: f.model.path for f in files}
    if len(modes) > 1:
        found = ", ".join(f"{path} acts in {mode!r} mode" for mode, path in modes.items())
        raise ControllerError(f"{name_or_path!r}: its training seeds disagree: {found}")
    label = policy_label(name_or_path)
    return ControllerRecord(
        name=label,
        controller=name_or_path,
        entry_point=f"{LearnedPolicy.__module__}:{LearnedPolicy.__qualname__}",
        settings={"path": name_or_path, "name": label},
        loaded=LearnedPolicy,
        action_mode=files[0].model.action_mode,
        kind=LearnedPolicy.kind,
        training_seeds=tuple(seeds),
        family="learned",
        look=AGENT_LOOKS.get(label),
    )


def _entry_point_record(entry_point: EntryPoint) -> ControllerRecord:
    """An installed plug-in, loaded and registered under its entry point's name, with the
    traits its object carries (``action_mode``, ``applies_to``, ``kind``)."""
    origin = f"entry point {entry_point.name!r} = {entry_point.value!r}"
    obj = load_entry_point(entry_point)
    if entry_point.name not in _RECORDS:  # its module may register it itself on import
        traits = _traits(obj, origin)
        try:
            register_controller(
                entry_point.name,
                traits.factory,
                action_mode=traits.action_mode,
                applies_to=traits.applies_to,
            )
        except (TypeError, ValueError) as exc:
            raise ControllerError(f"{origin}: {exc}") from None
    return _RECORDS[entry_point.name]


def _plugin_record(obj: Any, spec: str, origin: str, default_name: str) -> ControllerRecord:
    """The record of the object ``obj`` the spec ``spec`` names: its registration if it has
    one, else one made from its traits, named by its own ``name`` or ``default_name``."""
    registered = next((r for r in _RECORDS.values() if _defines(r, obj)), None)
    if registered is not None:
        return registered
    traits = _traits(obj, origin)
    return ControllerRecord(
        name=traits.name or default_name,
        controller=spec,
        entry_point=spec,
        loaded=traits.factory,
        action_mode=traits.action_mode,
        applies_to=traits.applies_to,
        kind=traits.kind,
    )


def _defines(record: ControllerRecord, obj: Any) -> bool:
    """Whether the registered ``record`` is ``obj``'s (:func:`_same_definition`); a built-in
    not loaded yet is compared by its entry point, without importing it."""
    if record.loaded is not None:
        return _same_definition(record.loaded, obj)
    module, _, attr = record.entry_point.partition(":")
    if getattr(obj, "__qualname__", None) != attr:
        return False
    if getattr(obj, "__module__", None) == module:
        return True
    try:
        found = importlib.util.find_spec(module)
        where = Path(inspect.getfile(obj)).resolve()
    except (ImportError, TypeError, OSError, ValueError):
        return False
    return found is not None and found.origin is not None and Path(found.origin).resolve() == where


def _same_definition(factory: Any, obj: Any) -> bool:
    """Whether ``obj`` is ``factory``, or the same class or function loaded from the same
    source file under another module name (a file spec of an installed plug-in)."""
    if factory is obj:
        return True
    if not (isinstance(obj, type | types.FunctionType) and type(obj) is type(factory)):
        return False
    try:
        files = {Path(inspect.getfile(f)).resolve() for f in (factory, obj)}
    except (TypeError, OSError):  # built-in, or defined without a file
        return False
    return len(files) == 1 and factory.__qualname__ == obj.__qualname__


@dataclasses.dataclass(frozen=True)
class _Traits:
    """What a plug-in object says about itself."""

    factory: Callable[..., Policy]
    name: str | None
    action_mode: str
    applies_to: tuple[str, ...] | None
    kind: str


def _traits(obj: Any, origin: str) -> _Traits:
    """The factory and traits of a Policy class, a factory function or a Policy instance;
    anything else, and bad traits, are a :class:`ControllerError` naming ``origin``."""
    is_policy = all(callable(getattr(obj, method, None)) for method in ("reset", "act"))
    if isinstance(obj, type):
        if not is_policy:
            raise ControllerError(
                f"{origin}: class {obj.__qualname__} is not a Policy (it needs reset(context, "
                "seed=None) and act(obs, info))"
            )
        factory, name = obj, vars(obj).get("name")  # an inherited name is its parent's
    elif is_policy:
        factory, name = _returning(obj), getattr(obj, "name", None)
    elif callable(obj):
        factory, name = obj, getattr(obj, "name", None)
    else:
        raise ControllerError(
            f"{origin} is a {type(obj).__name__}, not a Policy class, a factory function or a "
            "Policy instance"
        )
    action_mode = getattr(obj, "action_mode", "rudder")
    kind = getattr(obj, "kind", "classical")
    ships = getattr(obj, "applies_to", None)
    if action_mode not in ACTION_MODES:
        raise ControllerError(
            f"{origin}: action_mode must be one of {ACTION_MODES}, got {action_mode!r}"
        )
    if kind not in KINDS:
        raise ControllerError(f"{origin}: kind must be one of {KINDS}, got {kind!r}")
    if not (ships is None or isinstance(ships, list | tuple)):
        raise ControllerError(f"{origin}: applies_to is a list of ship ids, got {ships!r}")
    try:
        applies = _ships(origin, ships)
    except ValueError as exc:
        raise ControllerError(str(exc)) from None
    return _Traits(
        factory=factory,
        name=name if isinstance(name, str) and name else None,
        action_mode=action_mode,
        applies_to=applies,
        kind=kind,
    )


def _returning(policy: Policy) -> Callable[[], Policy]:
    """A factory that returns the Policy instance ``policy`` (reset before every episode)."""

    def factory() -> Policy:
        return policy

    factory.kind = getattr(policy, "kind", "classical")  # type: ignore[attr-defined]
    return factory


def _check_settings(record: ControllerRecord, entry: ControllerEntry) -> None:
    """Raise unless the factory of ``record`` accepts ``entry.settings`` as keywords (the
    rest may come with :func:`make_controller`); none: nothing is loaded."""
    if not entry.settings:
        return
    try:
        signature = inspect.signature(record.factory)
    except (TypeError, ValueError):  # a builtin or extension callable: nothing to check
        return
    try:
        signature.bind_partial(**entry.settings)
    except TypeError as exc:
        raise ControllerError(
            f"controller {entry.controller!r}: settings {dict(entry.settings)} do not fit "
            f"{_qualname(record.factory)}{signature}: {exc}"
        ) from None


def controller_label(controller: ControllerRef) -> str:
    """The table name of a controller: its registered name or its own ``name`` (a spec's
    attribute name when it has none), the long form's ``name``, a learned policy's name
    (a trained agent's folder name; for a zip the folder holding it, plus the zip's stem
    unless it is ``model``)."""
    return resolve_controller(controller).name


def _known(controller: ControllerRef) -> ControllerRecord | None:
    """The record of a table name or controller resolved before, else resolved now (None
    when it is none)."""
    _read_builtins()
    if isinstance(controller, str):
        record = _RECORDS.get(controller) or _RESOLVED.get(controller)
        if record is not None:
            return record
    try:
        return resolve_controller(controller)
    except ControllerError:
        return None


def applies_to(controller: ControllerRef, ship: str) -> bool:
    """Whether ``controller`` (a controller or a table name) runs on ``ship`` (learned
    agents and the rest: every ship)."""
    record = _known(controller)
    return record is None or record.applies_to is None or ship in record.applies_to


def controller_kind(controller: ControllerRef) -> str:
    """``"classical"`` for a registered or plug-in controller (unless it says otherwise),
    ``"learned"`` for learned policies and anything unknown."""
    record = _known(controller)
    return record.kind if record is not None else "learned"


def is_controller(name: ControllerRef) -> bool:
    """Whether :func:`resolve_controller` accepts ``name``."""
    try:
        resolve_controller(name)
    except ControllerError:
        return False
    return True


def unknown_controller(name: str) -> str:
    """The error message for a name :func:`is_controller` rejects: the valid names."""
    from shipgym_baselines.learned.policy import shipped_policies

    _read_builtins()
    plugins = [n for n in entry_point_names() if n not in _RECORDS]
    installed = f", the installed plug-ins {', '.join(plugins)}" if plugins else ""
    return (
        f"unknown controller {name!r}; valid: {', '.join(sorted(_RECORDS))}{installed}, the "
        f"learned policies {', '.join(shipped_policies())}, a spec module.path:Attr or "
        "path/to/file.py:Attr, or a trained agent's folder or model zip"
    )


def training_seeds(controller: ControllerRef) -> list[int | None]:
    """The training seeds ``controller`` has: a learned policy's (a shipped name or a
    trained agent's folder with ``seed_<k>`` folders: every k, in order; one model: its
    meta's seed), ``[None]`` for the rest (classical controllers, plug-ins, a model without
    a seed).  Each is a ``training_seed`` for :func:`make_controller`."""
    return list(resolve_controller(controller).training_seeds)


def _check_seed(record: ControllerRecord, seed: Any) -> int | None:
    """``seed`` if it is one of the training seeds of ``record``, else a clear error."""
    if seed in record.training_seeds and not isinstance(seed, bool | float):
        return seed
    if record.training_seeds == (None,):
        raise ControllerError(
            f"controller {record.name!r} has no training seeds (it is not a trained agent, "
            f"or its files name none): training_seed={seed!r}"
        )
    raise ControllerError(
        f"controller {record.name!r} was trained with seeds "
        f"{', '.join(map(str, record.training_seeds))}: no training seed {seed!r}"
    )


def make_controller(
    name: ControllerRef, training_seed: int | None = None, **settings: Any
) -> tuple[Policy, str]:
    """A fresh controller and the action mode it needs; unknown names list the valid ones.

    ``name``: anything :func:`resolve_controller` accepts (made with ``settings``, after
    the long form's own); the policy carries the table name and the action mode.
    ``training_seed``: one of :func:`training_seeds` (None: a learned policy's first); the
    policy carries it as ``training_seed``.
    """
    record = resolve_controller(name)
    if training_seed is not None:
        settings["training_seed"] = _check_seed(record, training_seed)
    policy = record.factory(**settings)
    for attr in ("name", "action_mode"):  # a factory function's policy learns them here
        if getattr(policy, attr, None) != getattr(record, attr):
            setattr(policy, attr, getattr(record, attr))
    if not hasattr(policy, "kind"):
        policy.kind = record.kind
    return policy, record.action_mode


def declared_traits(name: str) -> tuple[str | None, Style | None]:
    """(family, look) the figures draw the table name ``name`` with, as declared: by its
    registration, or for a learned agent by
    :data:`shipgym_baselines.learned.policy.AGENT_LOOKS` (family ``"learned"``); each None
    where nothing declares it (the figures derive it from the kind and name)."""
    _read_builtins()
    record = _RECORDS.get(name)
    if record is not None:
        return record.family, record.look
    from shipgym_baselines.learned.policy import AGENT_LOOKS

    if name in AGENT_LOOKS:
        return "learned", AGENT_LOOKS[name]
    return None, None
