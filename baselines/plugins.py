"""Controllers from outside the package: specs, files and installed plug-ins (docs/plugins.md).

A controller that is not built in enters the benchmark by one of

* a **spec** ``module.path:Attr`` (an importable module; a module in the working directory
  is found too) or ``path/to/file.py:Attr`` (a file, loaded once per process under a module
  name derived from its path), accepted wherever a controller name is;
* an **entry point** of an installed distribution in the group :data:`ENTRY_POINT_GROUP`
  (``name = "module:factory"``), loaded when its name is first asked for;
* the **long form** of a suite's ``controllers:`` list, :class:`ControllerEntry`
  (``{controller: SPEC, name: DISPLAY_NAME, settings: {keyword: value}}``), so that one
  controller can enter twice under two names with different settings.

This module only finds and loads the objects; :mod:`shipgym_baselines.registry` turns them into
controller records.  A run passes the spec *string* to its worker processes, never the
loaded object, and each process resolves it again.
"""

from __future__ import annotations

import dataclasses
import hashlib
import importlib
import importlib.util
import os
import re
import sys
from importlib.metadata import EntryPoint, entry_points
from pathlib import Path
from types import ModuleType
from typing import Any

from pydantic import Field

from shipgym.config import StrictModel
from shipgym_baselines.errors import ControllerError

#: the entry-point group an installed package declares its controllers in
ENTRY_POINT_GROUP = "shipgym.controllers"

#: file suffixes that make a controller string a path (a file spec, a model zip)
PATH_SUFFIXES = (".py", ".zip")


class ControllerEntry(StrictModel):
    """The long form of a controller in a suite.

    ``controller``: what any short form accepts (a registered name, an installed plug-in,
    a spec, a learned policy or a trained agent's path); ``name``: its table name (default:
    the controller's own); ``settings``: keyword arguments of its factory.
    """

    controller: str = Field(min_length=1)
    name: str | None = Field(None, min_length=1)
    settings: dict[str, Any] = Field(default_factory=dict)


#: a controller as runs accept it: the short form (a string) or the long form
ControllerSpec = str | ControllerEntry


def as_entry(controller: ControllerSpec) -> ControllerEntry:
    """The long form of ``controller`` (a string has no display name and no settings)."""
    if isinstance(controller, ControllerEntry):
        return controller
    if not isinstance(controller, str) or not controller:
        raise ControllerError(f"a controller is a non-empty string, got {controller!r}")
    return ControllerEntry(controller=controller)


# --------------------------------------------------------------------- specs


@dataclasses.dataclass(frozen=True)
class Spec:
    """A parsed ``target:attr``: ``target`` is a dotted module or a ``.py`` file path,
    ``attr`` a dotted attribute of it."""

    target: str
    attr: str

    @property
    def is_file(self) -> bool:
        return looks_like_path(self.target)

    def __str__(self) -> str:
        return f"{self.target}:{self.attr}"


def looks_like_path(text: str) -> bool:
    """Whether ``text`` names a file or folder rather than a registered name: it contains a
    path separator or ends in ``.py`` / ``.zip``."""
    separators = {"/", os.sep, os.altsep} - {None}
    return text.endswith(PATH_SUFFIXES) or any(s in text for s in separators)


def _dotted(text: str) -> bool:
    return bool(text) and all(part.isidentifier() for part in text.split("."))


def parse_spec(text: str) -> Spec | None:
    """``module.path:Attr`` or ``path/to/file.py:Attr`` as a :class:`Spec`, else None."""
    target, colon, attr = text.rpartition(":")
    if not colon or not _dotted(attr) or not target:
        return None
    if looks_like_path(target):
        return Spec(target, attr) if target.endswith(".py") else None
    return Spec(target, attr) if _dotted(target) else None


def anchored(controller: str, folder: Path) -> str:
    """``controller`` with a relative file part (a spec's ``.py`` file, a model's path)
    read against ``folder`` (a suite's); names and module specs are unchanged."""
    spec = parse_spec(controller)
    if spec is not None:
        if spec.is_file and not Path(spec.target).expanduser().is_absolute():
            return str(Spec(str(folder / spec.target), spec.attr))
        return controller
    path = Path(controller).expanduser()
    if looks_like_path(controller) and not path.is_absolute():
        return str(folder / path)
    return controller


def load_spec(spec: Spec) -> Any:
    """The object ``spec`` names: its module imported (a file loaded), the attribute read.

    A missing module, file or attribute is a :class:`ControllerError`, and so is a module
    that exits while it runs (``SystemExit``); an exception raised by the module's own
    code while it runs is that module's, and keeps its traceback.
    """
    try:
        module = _load_file(Path(spec.target)) if spec.is_file else _import(spec.target)
    except SystemExit as exc:
        raise ControllerError(f"controller {str(spec)!r}: {_exited(exc)}") from None
    return _attribute(module, spec.attr, f"controller {str(spec)!r}", spec.target)


def _exited(exc: SystemExit) -> str:
    """What a module that called ``sys.exit`` while it was loaded did, in words."""
    return f"its module exits while it is loaded (SystemExit: {exc.code!r:.60})"


def _attribute(module: ModuleType, dotted: str, origin: str, where: str) -> Any:
    """``module.<dotted>``; a missing name is an error naming ``where`` (the module or
    file) and listing its public names."""
    obj: Any = module
    for part in dotted.split("."):
        if not hasattr(obj, part):
            public = sorted(n for n in dir(module) if not n.startswith("_"))
            raise ControllerError(
                f"{origin}: {where} has no attribute {dotted!r} "
                f"(it has: {', '.join(public) or 'nothing public'})"
            )
        obj = getattr(obj, part)
    return obj


def _import(module: str) -> ModuleType:
    """``import module``; a module of the working directory is found when the console
    script's ``sys.path`` does not hold the working directory."""
    for attempt in range(2):
        try:
            return importlib.import_module(module)
        except ModuleNotFoundError as exc:
            missing = exc.name or ""
            if not (module == missing or module.startswith(f"{missing}.")):
                raise  # the module itself imports something missing: its error
            cwd = os.getcwd()
            if attempt == 1 or cwd in sys.path:
                raise ControllerError(
                    f"controller module {module!r} not found (no module named {missing!r} "
                    "on sys.path or in the working directory)"
                ) from None
            sys.path.append(cwd)
            importlib.invalidate_caches()
    raise AssertionError("unreachable")


def _load_file(path: Path) -> ModuleType:
    """The module of a ``.py`` file, executed once per process (cached by absolute path)."""
    path = path.expanduser().resolve()
    if not path.is_file():
        raise ControllerError(f"controller file not found: {path}")
    digest = hashlib.sha1(str(path).encode()).hexdigest()[:10]
    name = f"shipgym_plugin_{re.sub(r'[^0-9A-Za-z_]', '_', path.stem)}_{digest}"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise ControllerError(f"controller file {path} cannot be imported as a Python module")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # before running it: dataclasses and pickle look it up
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    return module


# --------------------------------------------------------------------- entry points


def entry_point_names() -> list[str]:
    """Names of the controllers installed packages declare (not loaded)."""
    return sorted(set(entry_points(group=ENTRY_POINT_GROUP).names))


def find_entry_point(name: str) -> EntryPoint | None:
    """The installed entry point ``name`` of the group; two distributions declaring it with
    different targets is an error naming both."""
    found = {ep.value: ep for ep in entry_points(group=ENTRY_POINT_GROUP, name=name)}
    if len(found) > 1:
        raise ControllerError(
            f"controller {name!r} is declared by several installed packages "
            f"({', '.join(sorted(found))}); uninstall one"
        )
    return next(iter(found.values()), None)


def load_entry_point(ep: EntryPoint) -> Any:
    """The object an entry point names; a missing module or attribute is a clear error."""
    origin = f"entry point {ep.name!r} = {ep.value!r} ({ENTRY_POINT_GROUP})"
    try:
        module = importlib.import_module(ep.module)
    except SystemExit as exc:
        raise ControllerError(f"{origin}: {_exited(exc)}") from None
    except ModuleNotFoundError as exc:
        if not (exc.name and (ep.module == exc.name or ep.module.startswith(f"{exc.name}."))):
            raise  # the plug-in's module imports something missing: its error
        raise ControllerError(f"{origin}: no module named {exc.name!r}") from None
    return _attribute(module, ep.attr, origin, ep.module) if ep.attr else module
