"""The import graph of shipgym and baselines follows the layering of docs/architecture.md.

Every module is parsed with ``ast`` and every import counts: top-level, inside functions
(lazy), under ``if TYPE_CHECKING:``, in ``try`` blocks.  ``from a.b import c`` is an edge to
the module ``a.b.c`` when that is a module, else to ``a.b``.  Dynamic imports
(``importlib.import_module``) and gymnasium's entry-point strings are not edges.
"""

from __future__ import annotations

import ast
import importlib
from collections.abc import Iterator
from functools import cache
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: import package -> its folder in the checkout (``baselines/`` installs as shipgym_baselines)
PACKAGES = {"shipgym": "shipgym", "shipgym_baselines": "baselines"}

#: The layer of every shipgym module, lowest first; an entry for a package covers its
#: submodules unless they have their own.  A module imports only modules of its own or a
#: lower layer.
LAYERS: dict[str, int] = {
    # 0 — foundations: the error base, config files, scalar/array operation sets, angle
    #     arithmetic, path geometry, the terminal's notice lines
    "shipgym.errors": 0,
    "shipgym.limits": 0,
    "shipgym.notices": 0,
    "shipgym.config": 0,
    "shipgym.numerics": 0,
    "shipgym.angles": 0,
    "shipgym.paths": 0,
    # 1 — ship models: one right-hand side per ship, parameter records, RK4
    "shipgym.models": 1,
    # 2 — integration: the unrolled CasADi control period, compiled to C
    "shipgym.models.integrator": 2,
    "shipgym.codegen": 2,
    # 3 — standard manoeuvres (zig-zag, turning circle) simulated on a model
    "shipgym.manoeuvres": 3,
    # the IMO manoeuvring criteria (MSC.137(76)) a manoeuvre is measured against
    "shipgym.manoeuvring_standards": 3,
    # 4 — identification: LS-SVM fits, online identifiers, nominal models from zig-zags
    "shipgym.identification": 4,
    # 5 — guidance laws, heading autopilots, path tracking, disturbances and sensors (and
    #     their validated settings)
    "shipgym.guidance": 5,
    "shipgym.autopilot": 5,
    "shipgym.tracking": 5,
    "shipgym.disturbances": 5,
    "shipgym.disturbance_config": 5,
    # 6 — scenarios: config schema, loader, events, distributions
    "shipgym.scenarios": 6,
    # 7 — an episode's metrics and rendering
    "shipgym.metrics": 7,
    "shipgym.rendering": 7,
    "shipgym.animation": 7,
    # 8 — the environments, and the package itself (it registers them)
    "shipgym.envs": 8,
    "shipgym": 8,
}

#: What the ship models (the equations) must never depend on.
ABOVE_MODELS = (
    "shipgym.identification",
    "shipgym.envs",
    "shipgym.scenarios",
    "shipgym.guidance",
    "shipgym.autopilot",
    "shipgym.manoeuvres",
    "shipgym.tracking",
    "shipgym.disturbances",
)

#: The pydantic config schema is the boundary of the scenario layer: the loader turns it
#: into SI objects, and no other shipgym module reads it.
CONFIG_SCHEMA = "shipgym.scenarios.schema"

#: Edges that break the rules above and are being fixed.  Empty this set as
#: they go: a listed edge that no longer exists fails ``test_known_pending_edges_exist``.
#: (The two edges it listed, shipgym.disturbances and shipgym.envs.context reading
#: ``shipgym.scenarios.schema``, are fixed.)
KNOWN_PENDING: set[tuple[str, str]] = set()


def _module_name(package: str, path: Path) -> str:
    parts = [package, *path.relative_to(ROOT / PACKAGES[package]).with_suffix("").parts]
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


@cache
def _files() -> dict[str, Path]:
    """Project module name -> source file."""
    return {
        _module_name(package, path): path
        for package, folder in PACKAGES.items()
        for path in sorted((ROOT / folder).rglob("*.py"))
    }


def _is_project(name: str) -> bool:
    return name.split(".")[0] in PACKAGES


def _nearest_module(name: str) -> str:
    """``name`` if it is a project module, else its longest dotted prefix that is one."""
    parts = name.split(".")
    for i in range(len(parts), 0, -1):
        candidate = ".".join(parts[:i])
        if candidate in _files():
            return candidate
    return name


def _imported_names(tree: ast.AST, module: str, is_package: bool) -> Iterator[str]:
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
                yield submodule if submodule in _files() else base


@cache
def import_graph() -> dict[str, frozenset[str]]:
    """Project module -> the project modules it imports."""
    graph = {}
    for module, path in _files().items():
        tree = ast.parse(path.read_text(), filename=str(path))
        names = _imported_names(tree, module, path.name == "__init__.py")
        graph[module] = frozenset(
            _nearest_module(n) for n in names if _is_project(n) and _nearest_module(n) != module
        )
    return graph


def _edges(prefix: str) -> Iterator[tuple[str, str]]:
    for module, imported in sorted(import_graph().items()):
        if _within(module, prefix):
            for target in sorted(imported):
                yield module, target


def _within(module: str, prefix: str) -> bool:
    return module == prefix or module.startswith(prefix + ".")


def layer(module: str) -> int | None:
    """The module's entry in :data:`LAYERS` (its own, else its nearest package's)."""
    parts = module.split(".")
    for i in range(len(parts), 1, -1):
        key = ".".join(parts[:i])
        if key in LAYERS:
            return LAYERS[key]
    return LAYERS.get(module)


def _find_cycle(graph: dict[str, frozenset[str]]) -> list[str] | None:
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


# ------------------------------------------------------------------------------- tests
def test_the_graph_sees_lazy_relative_and_type_checking_imports() -> None:
    source = (
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n"
        "    from shipgym.models.base import ShipModel\n"
        "from . import mariner\n"
        "def f():\n"
        "    from shipgym.identification import zigzag\n"
        "    import shipgym.paths\n"
    )
    names = set(_imported_names(ast.parse(source), "shipgym.models.nomoto2", False))
    assert names == {
        "typing",
        "shipgym.models.base",
        "shipgym.models.mariner",
        "shipgym.identification.zigzag",
        "shipgym.paths",
    }
    # the zig-zag fit runs the manoeuvre: an edge of the real graph
    assert "shipgym.manoeuvres" in import_graph()["shipgym.identification.zigzag"]


def test_no_import_cycles_in_shipgym() -> None:
    graph = {
        m: frozenset(t for t in targets if _within(t, "shipgym"))
        for m, targets in import_graph().items()
        if _within(m, "shipgym")
    }
    cycle = _find_cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(cycle or [])


def test_shipgym_never_imports_baselines() -> None:
    bad = [(m, t) for m, t in _edges("shipgym") if _within(t, "shipgym_baselines")]
    assert not bad, f"shipgym imports baselines: {bad}"


def test_models_import_nothing_above_them() -> None:
    bad = [
        (m, t)
        for m, t in _edges("shipgym.models")
        if any(_within(t, above) for above in ABOVE_MODELS)
    ]
    assert not bad, f"ship models import higher layers: {bad}"


def test_every_shipgym_module_has_a_layer() -> None:
    missing = [m for m in import_graph() if _within(m, "shipgym") and layer(m) is None]
    assert not missing, f"add these modules to LAYERS: {missing}"


def test_modules_import_only_their_own_or_lower_layers() -> None:
    bad = [
        f"{m} (layer {layer(m)}) imports {t} (layer {layer(t)})"
        for m, t in _edges("shipgym")
        if (layer(t) or 0) > (layer(m) or 0) and (m, t) not in KNOWN_PENDING
    ]
    assert not bad, "layering broken:\n" + "\n".join(bad)


def test_only_the_scenario_layer_reads_the_config_schema() -> None:
    bad = [
        (m, t)
        for m, t in _edges("shipgym")
        if t == CONFIG_SCHEMA and not _within(m, "shipgym.scenarios")
    ]
    assert not [e for e in bad if e not in KNOWN_PENDING], f"schema read outside scenarios: {bad}"


def test_every_project_error_is_a_shipgym_error() -> None:
    """Each ``class …Error`` of shipgym and baselines derives from ShipgymError: the CLI
    prints those as one line."""
    from shipgym.errors import ShipgymError

    errors = {
        (module, node.name)
        for module, path in _files().items()
        for node in ast.walk(ast.parse(path.read_text()))
        if isinstance(node, ast.ClassDef) and node.name.endswith("Error")
    }
    assert ("shipgym.identification.errors", "IdentificationError") in errors
    for module, name in sorted(errors):
        cls = getattr(importlib.import_module(module), name)
        assert issubclass(cls, ShipgymError), f"{module}.{name} is not a ShipgymError"


def test_known_pending_edges_exist() -> None:
    """A fixed edge leaves KNOWN_PENDING (so the set only shrinks)."""
    gone = [(m, t) for m, t in KNOWN_PENDING if t not in import_graph().get(m, ())]
    assert not gone, f"fixed: remove from KNOWN_PENDING: {gone}"
