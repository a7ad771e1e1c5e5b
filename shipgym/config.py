"""Config files: where they are (one resolver) and how they are read (one YAML loader).

The packaged catalogue is the repository's top-level ``configs/``, installed as the package
data ``shipgym.configs`` and found through :mod:`importlib.resources` (from a wheel or an
editable install alike).  Its folders are the *kinds*: ``scenarios``, ``distributions``,
``suites``, ``agents``.

Name or path.  A bare name (``rudder_aging``) is the packaged file
``configs/<kind>/<name>.yaml``.  Anything that looks like a path (it contains a separator or
ends in ``.yaml``/``.yml``) is that file; a relative path is read against ``relative_to``
when given (a suite's folder, for the scenario files it lists), else against the working
directory.

Every config model derives from :class:`StrictModel` (unknown keys rejected, frozen) and is
read by :func:`load_yaml_model`, whose errors name the file, the line where the YAML fails,
and the bad key.
"""

from __future__ import annotations

import difflib
import os
import types
from collections.abc import Iterable, Mapping
from importlib.resources import files
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Annotated, Any, Self, TypeVar, Union, get_args, get_origin

import yaml
from pydantic import AfterValidator, BaseModel, ConfigDict, ValidationError
from yaml.composer import ComposerError

from shipgym.errors import ShipgymError
from shipgym.limits import MAX_CONFIG_BYTES, MAX_CONFIG_DEPTH, MAX_CONFIG_NODES, name_problem

#: kind (folder of configs/) -> what one file of it is called in messages
KINDS: dict[str, str] = {
    "agents": "agent config",
    "distributions": "distribution",
    "scenarios": "scenario",
    "suites": "suite",
    "tuning": "tuning space",
}

#: a config file: a filesystem path, or a packaged resource
ConfigFile = Path | Traversable

#: a validated config model
M = TypeVar("M", bound=BaseModel)


class ConfigError(ShipgymError, ValueError):
    """A config file cannot be found or is malformed; the message names the file and key."""


def check_name(value: str) -> str:
    """``value`` if it can name a scenario or suite (:func:`shipgym.limits.name_problem`:
    length, control characters), else a ValueError saying why."""
    problem = name_problem(value)
    if problem is not None:
        raise ValueError(f"the name {problem}")
    return value


#: a scenario's or suite's ``name`` (figures and tables are files named after it)
Name = Annotated[str, AfterValidator(check_name)]


class StrictModel(BaseModel):
    """Base of every config model: unknown keys are errors, instances are frozen, and every
    float is finite (``.inf`` / ``.nan`` are rejected naming the key)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    def with_overrides(
        self,
        overrides: Mapping[str, Any] | None = None,
        drop: Iterable[str] = (),
        origin: str = "<overrides>",
        error: type[Exception] = ConfigError,
    ) -> Self:
        """A validated copy: the ``drop`` keys (dotted, e.g. ``"sensors"``) removed, so that
        their defaults apply, then ``overrides`` deep-merged (mappings merge key by key,
        any other value replaces).  A field no dump holds (``exclude``) is kept unless
        ``overrides`` sets it.  Errors name ``origin`` and the key."""
        data = self.model_dump()
        for dotted in drop:
            *parents, last = dotted.split(".")
            node: Any = data
            for part in parents:
                node = node.get(part) if isinstance(node, dict) else None
            if not isinstance(node, dict) or last not in node:
                raise error(f"{origin}: cannot drop {dotted!r}: no such key")
            del node[last]
        fields = type(self).model_fields
        data.update({name: getattr(self, name) for name, f in fields.items() if f.exclude})
        return validate_model(deep_merge(data, overrides or {}), type(self), origin, error)


def deep_merge(base: Mapping[str, Any], overrides: Mapping[str, Any]) -> dict[str, Any]:
    """``base`` updated by ``overrides``: nested mappings merge, other values replace."""
    out = dict(base)
    for key, value in overrides.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = deep_merge(out[key], value)
        else:
            out[key] = value
    return out


# --------------------------------------------------------------------- the resolver


def _check_kind(kind: str) -> str:
    if kind not in KINDS:
        raise ConfigError(f"unknown config kind {kind!r}; valid: {', '.join(KINDS)}")
    return KINDS[kind]


def catalogue(kind: str) -> Traversable:
    """The packaged folder ``configs/<kind>``."""
    _check_kind(kind)
    return files("shipgym.configs") / kind


def list_names(kind: str) -> list[str]:
    """Names of the packaged configs of ``kind`` (file stems), sorted."""
    return sorted(
        entry.name.rsplit(".", 1)[0]
        for entry in catalogue(kind).iterdir()
        if entry.is_file() and entry.name.endswith((".yaml", ".yml"))
    )


def is_path(text: str) -> bool:
    """True when ``text`` names a file rather than a packaged config."""
    separators = {"/", os.sep, os.altsep} - {None}
    return text.endswith((".yaml", ".yml")) or any(s in text for s in separators)


def resolve(
    kind: str,
    name_or_path: str | os.PathLike | Traversable,
    relative_to: str | os.PathLike | None = None,
    error: type[Exception] = ConfigError,
) -> ConfigFile:
    """The file of a config: a packaged name or a path (module doc).

    ``relative_to`` (a folder, or a file whose folder is meant) anchors relative paths;
    ``error`` is the exception raised, its message naming the kind, what was asked and, for
    an unknown name, the valid names.
    """
    noun = _check_kind(kind)
    if not isinstance(name_or_path, str | os.PathLike):  # a packaged resource already
        if not name_or_path.is_file():
            raise error(f"{noun} file not found: {name_or_path}")
        return name_or_path
    text = os.fspath(name_or_path)
    if is_path(text):
        path = Path(text).expanduser()
        if relative_to is not None and not path.is_absolute():
            base = Path(relative_to)
            path = (base if base.is_dir() else base.parent) / path
        if not path.is_file():
            raise error(f"{noun} file not found: {path}")
        return path
    for suffix in (".yaml", ".yml"):
        entry = catalogue(kind) / f"{text}{suffix}"
        if entry.is_file():
            return entry
    raise error(f"unknown {noun} {text!r} (configs/{kind}); valid: {', '.join(list_names(kind))}")


# --------------------------------------------------------------------- the loader


def format_validation_error(
    err: ValidationError, origin: str, model: type[BaseModel] | None = None
) -> str:
    """One line per problem, naming the file (``origin``) and the key; an unknown key of
    ``model`` with the close field names (:func:`error_message`)."""
    lines = []
    for item in err.errors():
        key = ".".join(str(part) for part in item["loc"]) or "<top level>"
        lines.append(f"{origin}: key '{key}': {error_message(item, model)}")
    return "\n".join(lines)


def error_message(item: Mapping[str, Any], model: type[BaseModel] | None) -> str:
    """A pydantic error's message; for an unknown key (``extra_forbidden``) of ``model``,
    followed by "did you mean 'K'?" when a field name there is close to it (difflib)."""
    message = str(item["msg"])
    loc = tuple(item.get("loc", ()))
    if model is None or item.get("type") != "extra_forbidden" or not loc:
        return message
    close = difflib.get_close_matches(str(loc[-1]), sorted(_field_names(model, loc[:-1])), n=1)
    return f"{message}; did you mean '{close[0]}'?" if close else message


def _field_names(annotation: Any, loc: tuple[Any, ...]) -> set[str]:
    """The field names (and aliases) of the models at ``loc`` (a pydantic error's place)
    inside ``annotation``: through optional and union types, lists and dicts; a part that
    names no field (a union's tag) is skipped."""
    options = _options(annotation)
    if not loc:
        return {
            name
            for option in options
            if isinstance(option, type) and issubclass(option, BaseModel)
            for field_name, field in option.model_fields.items()
            for name in (field_name, field.alias)
            if name
        }
    part, rest = loc[0], loc[1:]
    found: set[str] = set()
    for option in options:
        if isinstance(option, type) and issubclass(option, BaseModel):
            for field_name, field in option.model_fields.items():
                if part in (field_name, field.alias):
                    found |= _field_names(field.annotation, rest)
        elif get_origin(option) in (list, tuple, set, frozenset) and get_args(option):
            if isinstance(part, int):
                found |= _field_names(get_args(option)[0], rest)
        elif get_origin(option) is dict and len(get_args(option)) == 2:
            found |= _field_names(get_args(option)[1], rest)
    return found or (_field_names(annotation, rest) if isinstance(part, str) else set())


def _options(annotation: Any) -> list[Any]:
    """The types ``annotation`` may be: a union's members, an ``Annotated``'s type."""
    if get_origin(annotation) is Annotated:
        return _options(get_args(annotation)[0])
    if get_origin(annotation) in (Union, types.UnionType):
        return [t for arg in get_args(annotation) for t in _options(arg)]
    return [annotation]


def read_config_text(file: ConfigFile, error: type[Exception] = ConfigError) -> str:
    """The text of a config file; one larger than :data:`shipgym.limits.MAX_CONFIG_BYTES`
    is refused before it is read (parsing it would take minutes), naming the limit."""
    try:
        with file.open("rb") as fh:
            data = fh.read(MAX_CONFIG_BYTES + 1)
    except OSError as exc:
        raise error(f"{file}: cannot read: {exc.strerror or exc}") from None
    if len(data) > MAX_CONFIG_BYTES:
        raise error(f"{file}: larger than the limit of {MAX_CONFIG_BYTES} bytes for a config file")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise error(f"{file}: cannot read: not UTF-8 text ({exc.reason})") from None


class BoundedLoader(yaml.SafeLoader):
    """PyYAML's safe loader, bounded: a node tree nested deeper than
    :data:`~shipgym.limits.MAX_CONFIG_DEPTH` (PyYAML composes it recursively: a deep file
    ends in a RecursionError) or of more than :data:`~shipgym.limits.MAX_CONFIG_NODES`
    values with its aliases expanded (a few lines of nested aliases make billions) is a
    :class:`yaml.composer.ComposerError` at its line, as malformed YAML is."""

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0  # mappings and lists open
        self._total = 0  # values composed so far, aliases expanded
        self._expanded: dict[int, int] = {}  # id(node) -> its values, aliases expanded

    def compose_node(self, parent: yaml.Node | None, index: Any) -> yaml.Node:
        if self.check_event(yaml.AliasEvent):
            mark = self.peek_event().start_mark
            node = super().compose_node(parent, index)
            self._count(self._expanded.get(id(node), 1), mark)
            return node
        self._depth += 1
        if self._depth > MAX_CONFIG_DEPTH:
            raise ComposerError(
                None,
                None,
                f"nested deeper than the limit of {MAX_CONFIG_DEPTH} levels",
                self.peek_event().start_mark,
            )
        before = self._total
        try:
            node = super().compose_node(parent, index)
        finally:
            self._depth -= 1
        self._count(1, node.start_mark)
        self._expanded[id(node)] = self._total - before
        return node

    def _count(self, values: int, mark: Any) -> None:
        self._total += values
        if self._total > MAX_CONFIG_NODES:
            raise ComposerError(
                None,
                None,
                f"more than the limit of {MAX_CONFIG_NODES} values (aliases expanded)",
                mark,
            )


def parse_yaml(text: str) -> Any:
    """``text`` parsed as YAML by :class:`BoundedLoader` (a :class:`yaml.YAMLError` when it
    is malformed or beyond the limits)."""
    return yaml.load(text, Loader=BoundedLoader)  # a SafeLoader: plain data only


def compose_yaml(text: str) -> yaml.Node | None:
    """``text``'s YAML node tree (where each key is written), bounded as :func:`parse_yaml`."""
    return yaml.compose(text, Loader=BoundedLoader)


def read_yaml(file: ConfigFile, error: type[Exception] = ConfigError) -> Any:
    """The parsed YAML of ``file`` (:func:`parse_yaml`); malformed YAML, or YAML beyond the
    limits, fails naming the file and the line."""
    text = read_config_text(file, error)
    try:
        return parse_yaml(text)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f", line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        what = ", ".join(str(p) for p in (exc.context, exc.problem) if p)
        raise error(f"{file}{where}: malformed YAML: {what}") from None
    except yaml.YAMLError as exc:
        raise error(f"{file}: malformed YAML: {exc}") from None


def validate_model(
    data: Any, model: type[M], origin: str, error: type[Exception] = ConfigError
) -> M:
    """``model`` validated from ``data``; errors name ``origin`` and the key."""
    if not isinstance(data, Mapping):
        raise error(f"{origin}: expected a mapping at the top level, got {type(data).__name__}")
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        raise error(format_validation_error(exc, origin, model)) from None


def load_yaml_model(file: ConfigFile, model: type[M], error: type[Exception] = ConfigError) -> M:
    """``model`` validated from the YAML file ``file`` (use :func:`resolve` to find it)."""
    return validate_model(read_yaml(file, error), model, str(file), error)
