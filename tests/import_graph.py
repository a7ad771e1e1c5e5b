"""The project's import graph, read from the source with ``ast`` (for the layer tests).

Every import counts: top-level, inside functions (lazy), under ``if TYPE_CHECKING:``, in
``try`` blocks.  ``from a.b import c`` is an edge to the module ``a.b.c`` when that is a
module, else to ``a.b``.  :func:`import_graph` holds the import statements only;
:func:`dynamic_imports` adds what a module imports by name through :mod:`importlib`.
Entry-point strings ``"module:Attr"`` (Gymnasium's, the built-in controllers') are not edges.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator, Mapping
from functools import cache
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: import package -> its folder in the checkout (``baselines/`` installs as shipgym_baselines)
PACKAGES = {"shipgym": "shipgym", "shipgym_baselines": "baselines"}

Edge = tuple[str, str]


def module_name(package: str, path: Path) -> str:
    """The dotted name ``path`` (a file of ``package``'s folder) is imported as."""
    parts = [package, *path.relative_to(ROOT / PACKAGES[package]).with_suffix("").parts]
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


@cache
def files() -> dict[str, Path]:
    """Project module name -> source file."""
    return {
        module_name(package, path): path
        for package, folder in PACKAGES.items()
        for path in sorted((ROOT / folder).rglob("*.py"))
    }


def is_project(name: str) -> bool:
    """Whether the dotted ``name`` lies in one of :data:`PACKAGES`."""
    return name.split(".")[0] in PACKAGES


def nearest_module(name: str) -> str:
    """``name`` if it is a project module, else its longest dotted prefix that is one."""
    parts = name.split(".")
    for i in range(len(parts), 0, -1):
        candidate = ".".join(parts[:i])
        if candidate in files():
            return candidate
    return name


def imported_names(tree: ast.AST, module: str, is_package: bool) -> Iterator[str]:
    """Every name an import statement anywhere in ``tree`` (the source of ``module``)
    imports, relative imports resolved."""
    package = module if is_package else module.rpartition(".")[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from (alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:  # relative import
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*anchor, base] if base else anchor)
            for alias in node.names:
                submodule = f"{base}.{alias.name}"
                yield submodule if submodule in files() else base


@cache
def parsed(module: str) -> ast.Module:
    """The syntax tree of a project module."""
    path = files()[module]
    return ast.parse(path.read_text(), filename=str(path))


@cache
def import_graph() -> dict[str, frozenset[str]]:
    """Project module -> the project modules its import statements import."""
    graph = {}
    for module, path in files().items():
        names = imported_names(parsed(module), module, path.name == "__init__.py")
        graph[module] = frozenset(
            nearest_module(n) for n in names if is_project(n) and nearest_module(n) != module
        )
    return graph


def named_modules(tree: ast.AST, module: str) -> set[str]:
    """The project modules ``tree`` (the source of ``module``) names as dotted strings when
    it imports :mod:`importlib`: what ``importlib.import_module(name)`` of a listed name
    imports, an edge no import statement shows."""
    if not any(n.split(".")[0] == "importlib" for n in imported_names(tree, module, False)):
        return set()
    named = {
        node.value
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant) and isinstance(node.value, str)
    }
    return {n for n in named if "." in n and n in files() and n != module}


@cache
def dynamic_imports() -> dict[str, frozenset[str]]:
    """Project module -> the project modules it imports through :mod:`importlib`
    (:func:`named_modules`); modules without any are left out."""
    graph = {m: frozenset(named_modules(parsed(m), m)) for m in files()}
    return {m: targets for m, targets in graph.items() if targets}


def within(module: str, prefix: str) -> bool:
    """Whether ``module`` is ``prefix`` or lies inside the package ``prefix``."""
    return module == prefix or module.startswith(prefix + ".")


def edges(prefix: str, graph: Mapping[str, frozenset[str]] | None = None) -> Iterator[Edge]:
    """(module, imported module) of every module inside ``prefix``, sorted."""
    for module, imported in sorted((import_graph() if graph is None else graph).items()):
        if within(module, prefix):
            for target in sorted(imported):
                yield module, target


def layer(module: str, layers: Mapping[str, int]) -> int | None:
    """The module's entry in ``layers`` (its own, else its nearest package's)."""
    parts = module.split(".")
    for i in range(len(parts), 1, -1):
        key = ".".join(parts[:i])
        if key in layers:
            return layers[key]
    return layers.get(module)


def find_cycle(graph: Mapping[str, frozenset[str]]) -> list[str] | None:
    """One import cycle (a list of modules, first = last), or None."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(module: str) -> list[str] | None:
        state[module] = 1
        path.append(module)
        for target in sorted(graph.get(module, ())):
            if state.get(target) == 1:
                return [*path[path.index(target) :], target]
            if target not in state and (found := visit(target)):
                return found
        path.pop()
        state[module] = 2
        return None

    for module in sorted(graph):
        if module not in state and (found := visit(module)):
            return found
    return None
