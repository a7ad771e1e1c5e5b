"""The import graph of ``baselines/`` (``shipgym_baselines``) follows its layers, ground up:
ground floor → records → controllers → evaluation → tuning, reproduce → leaderboard →
studies → cli.  A module imports only modules of its
own layer or a lower one, save the edges of :data:`EXCEPTIONS`, and no import cycle runs
through baselines, save through :data:`CYCLE_EXCEPTIONS`.

The graph is :mod:`tests.import_graph`'s: every import statement (top-level, inside
functions, under ``if TYPE_CHECKING:``, in ``try`` blocks) and the modules a module imports
by name through ``importlib``.
"""

from __future__ import annotations

import ast
from collections.abc import Iterable, Mapping

from tests.import_graph import (
    Edge,
    dynamic_imports,
    edges,
    files,
    find_cycle,
    import_graph,
    imported_names,
    layer,
    named_modules,
    within,
)

B = "shipgym_baselines"

#: The layer of every baselines module, lowest first; an entry for a package covers its
#: submodules unless they have their own.
LAYERS: dict[str, int] = {
    # 0 — ground floor: error types, signal handling, JSON output, optional extras, the
    #     executor (local pool or Ray), the shipped reference data (no code)
    f"{B}.errors": 0,
    f"{B}.signals": 0,
    f"{B}.jsonout": 0,
    f"{B}.extras": 0,
    f"{B}.executor": 0,
    f"{B}.reference_data": 0,
    # 1 — what a run leaves on disk
    f"{B}.records": 1,
    # 2 — controllers: what a controller is, the table of built-ins, how it enters, its
    #     privileged channel, the references' tables, the classical controllers and the
    #     learned policies (loading and acting; their training sits in layer 4)
    f"{B}.policy": 2,
    f"{B}.controllers": 2,
    f"{B}.plugins": 2,
    f"{B}.registry": 2,
    f"{B}.privileged": 2,
    f"{B}.references": 2,
    f"{B}.classical": 2,
    f"{B}.learned": 2,
    # 3 — the evaluation loop, and a controller's own process for it
    f"{B}.evaluation": 3,
    f"{B}.isolation": 3,
    # 4 — tuning, training the learned agents (their configs, the trainers, model
    #     selection), the papers' reproductions (with the scenario variants they use)
    f"{B}.tuning": 4,
    f"{B}.learned.agents": 4,
    f"{B}.learned.train": 4,
    f"{B}.learned.announce": 4,
    f"{B}.learned.selection": 4,
    f"{B}.learned.dagger_agent": 4,
    f"{B}.learned.meta": 4,
    f"{B}.learned.plant_id.train": 4,
    f"{B}.reproduce": 4,
    # 5 — the leaderboard
    f"{B}.leaderboard": 5,
    #   its suite file's schema and reader sit with the evaluation loop (3): they import
    #   nothing above it, and ``evaluate(suite=...)`` draws a suite's trials from them
    f"{B}.leaderboard.suite": 3,
    # 6 — one-off studies beside the leaderboard
    f"{B}.studies": 6,
    # 7 — the command line, and the package itself (its lazy ``register_controller``)
    f"{B}.cli": 7,
    B: 7,
}


def _edge_table(text: str) -> dict[Edge, str]:
    """One ``module -> imported: reason`` a line, names relative to shipgym_baselines, as
    {(module, imported): reason}."""
    table = {}
    for line in filter(None, map(str.strip, text.splitlines())):
        edge, reason = line.split(": ", 1)
        module, target = (f"{B}.{name.strip()}" for name in edge.split(" -> "))
        table[module, target] = reason
    return table


#: Upward edges allowed today, with the reason; a name ending in ``.*`` stands for every
#: module inside that package.  A listed edge that no longer exists fails
#: ``test_every_exception_is_still_an_edge``: remove it then.
EXCEPTIONS = _edge_table(
    """
    """
)

#: Edges left out of the cycle check, with the reason (same form as :data:`EXCEPTIONS`).
CYCLE_EXCEPTIONS = _edge_table(
    """
    """
)


def _graph() -> dict[str, frozenset[str]]:
    """Baselines module -> the baselines modules it imports (statements and importlib)."""
    dynamic = dynamic_imports()
    return {
        module: frozenset(t for t in targets | dynamic.get(module, frozenset()) if within(t, B))
        for module, targets in import_graph().items()
        if within(module, B)
    }


def _covers(pattern: str, module: str) -> bool:
    """``module`` is ``pattern``, or lies inside the package ``pattern`` names as ``p.*``."""
    return within(module, pattern[:-2]) if pattern.endswith(".*") else module == pattern


def _matches(edge: Edge, allowed: Iterable[Edge]) -> bool:
    """Whether an entry of ``allowed`` covers ``edge``."""
    module, target = edge
    return any(_covers(m, module) and _covers(t, target) for m, t in allowed)


def _upward(found: Iterable[Edge], layers: Mapping[str, int] = LAYERS) -> list[str]:
    """The edges of ``found`` that import a higher layer and are no exception."""
    return [
        f"{m} (layer {layer(m, layers)}) imports {t} (layer {layer(t, layers)})"
        for m, t in found
        if (layer(t, layers) or 0) > (layer(m, layers) or 0) and not _matches((m, t), EXCEPTIONS)
    ]


# ------------------------------------------------------------------------------- tests
def test_the_graph_sees_lazy_and_importlib_imports() -> None:
    """A lazy import and a module imported by name are edges; a new upward edge fails, an
    exception passes."""
    source = (
        "import importlib\n"
        'BUILTIN = ("shipgym_baselines.classical.pid",)\n'
        "def f():\n"
        "    from shipgym_baselines.leaderboard import ranking\n"
        "for name in BUILTIN:\n"
        "    importlib.import_module(name)\n"
    )
    tree = ast.parse(source)
    assert f"{B}.leaderboard.ranking" in set(imported_names(tree, f"{B}.registry", False))
    assert named_modules(tree, f"{B}.registry") == {f"{B}.classical.pid"}
    assert named_modules(ast.parse("X = 'shipgym_baselines.classical.pid'\n"), B) == set()
    # an entry point "module:Attr" (the built-in controllers', Gymnasium's) is no edge
    entry_point = "import importlib\nX = 'shipgym_baselines.classical.pid:PIDLOS'\n"
    assert named_modules(ast.parse(entry_point), f"{B}.registry") == set()
    assert _upward([(f"{B}.records.episodes", f"{B}.leaderboard.ranking")])
    assert _upward([(f"{B}.classical.pid", f"{B}.cli")])
    assert not _upward([(f"{B}.cli.run", f"{B}.records.runs")])  # downward
    listed = [(m.replace(".*", ".any"), t.replace(".*", ".any")) for m, t in EXCEPTIONS]
    assert not _upward(listed)


def test_every_baselines_module_has_a_layer() -> None:
    missing = [m for m in files() if within(m, B) and layer(m, LAYERS) is None]
    assert not missing, f"add these modules to LAYERS: {missing}"


def test_modules_import_only_their_own_or_lower_layers() -> None:
    bad = _upward(edges(B, _graph()))
    assert not bad, "layering broken:\n" + "\n".join(bad)


def test_no_import_cycles_in_baselines() -> None:
    graph = {
        m: frozenset(t for t in targets if not _matches((m, t), CYCLE_EXCEPTIONS))
        for m, targets in _graph().items()
    }
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(cycle or [])


def test_every_exception_is_still_an_edge() -> None:
    """A removed edge leaves EXCEPTIONS and CYCLE_EXCEPTIONS (so the lists only shrink)."""
    found = list(edges(B, _graph()))
    gone = [e for e in [*EXCEPTIONS, *CYCLE_EXCEPTIONS] if not any(_matches(f, [e]) for f in found)]
    assert not gone, f"no longer imported: remove from the exceptions: {gone}"
