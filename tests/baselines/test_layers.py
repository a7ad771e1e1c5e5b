"""The import graph of ``baselines/`` (``shipgym_baselines``) follows its layers, ground up:
ground floor → records → controllers → evaluation → scoring → tuning, training,
reproduce → plots → page → leaderboard → studies → cli.  Each folder sits on one layer.  A
module imports only modules of its own layer or a lower one, and no import cycle runs
through baselines: there is no exception to either rule.

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

#: The layer of every folder of baselines and of every module at its top, lowest first.  An
#: entry for a folder covers every module in it: no folder spans two layers.
LAYERS: dict[str, int] = {
    # 0 — ground floor: error types, signal handling, JSON output, names written as text,
    #     optional extras, the executor (local pool or Ray), the shipped reference data
    f"{B}.errors": 0,
    f"{B}.signals": 0,
    f"{B}.jsonout": 0,
    f"{B}.escaping": 0,
    f"{B}.extras": 0,
    f"{B}.executor": 0,
    f"{B}.reference_data": 0,
    # 1 — what a run leaves on disk
    f"{B}.records": 1,
    # 2 — controllers: what a controller is, the table of built-ins, how it enters, its
    #     privileged channel, the references' tables, the classical controllers and the
    #     learned policies (loading and acting; their training sits in layer 5)
    f"{B}.policy": 2,
    f"{B}.controllers": 2,
    f"{B}.plugins": 2,
    f"{B}.registry": 2,
    f"{B}.privileged": 2,
    f"{B}.references": 2,
    f"{B}.classical": 2,
    f"{B}.learned": 2,
    # 3 — the evaluation loop, a controller's own process for it, and a suite file (its
    #     trials are what ``evaluate(suite=...)`` draws)
    f"{B}.evaluation": 3,
    f"{B}.isolation": 3,
    f"{B}.suite": 3,
    # 4 — scoring: the cost ratio, intervals, headroom, change share, ranking, rows, splits
    f"{B}.scoring": 4,
    # 5 — tuning, training the learned agents, the papers' reproductions
    f"{B}.tuning": 5,
    f"{B}.training": 5,
    f"{B}.reproduce": 5,
    # 6 — the figures, then 7 — the pages and tables that embed them
    f"{B}.plots": 6,
    f"{B}.page": 7,
    # 8 — running the leaderboard: jobs, the run, its outputs, reports, summaries
    f"{B}.leaderboard": 8,
    # 9 — one-off studies beside the leaderboard
    f"{B}.studies": 9,
    # 10 — the command line, and the package itself
    f"{B}.cli": 10,
    B: 10,
}


def _graph() -> dict[str, frozenset[str]]:
    """Baselines module -> the baselines modules it imports (statements and importlib)."""
    dynamic = dynamic_imports()
    return {
        module: frozenset(t for t in targets | dynamic.get(module, frozenset()) if within(t, B))
        for module, targets in import_graph().items()
        if within(module, B)
    }


def _upward(found: Iterable[Edge], layers: Mapping[str, int] = LAYERS) -> list[str]:
    """The edges of ``found`` that import a higher layer."""
    return [
        f"{m} (layer {layer(m, layers)}) imports {t} (layer {layer(t, layers)})"
        for m, t in found
        if (layer(t, layers) or 0) > (layer(m, layers) or 0)
    ]


# ------------------------------------------------------------------------------- tests
def test_the_graph_sees_lazy_and_importlib_imports() -> None:
    """A lazy import and a module imported by name are edges; a new upward edge fails, an
    exception passes."""
    source = (
        "import importlib\n"
        'BUILTIN = ("shipgym_baselines.classical.pid",)\n'
        "def f():\n"
        "    from shipgym_baselines.scoring import ranking\n"
        "for name in BUILTIN:\n"
        "    importlib.import_module(name)\n"
    )
    tree = ast.parse(source)
    assert f"{B}.scoring.ranking" in set(imported_names(tree, f"{B}.registry", False))
    assert named_modules(tree, f"{B}.registry") == {f"{B}.classical.pid"}
    assert named_modules(ast.parse("X = 'shipgym_baselines.classical.pid'\n"), B) == set()
    # an entry point "module:Attr" (the built-in controllers', Gymnasium's) is no edge
    entry_point = "import importlib\nX = 'shipgym_baselines.classical.pid:PIDLOS'\n"
    assert named_modules(ast.parse(entry_point), f"{B}.registry") == set()
    assert _upward([(f"{B}.records.episodes", f"{B}.scoring.ranking")])
    assert _upward([(f"{B}.classical.pid", f"{B}.cli")])
    assert not _upward([(f"{B}.cli.run", f"{B}.records.runlog")])  # downward


def test_each_layer_is_a_folder_or_a_module_at_the_top() -> None:
    """No entry of LAYERS lies inside a folder: a folder sits on one layer as a whole."""
    inside = [name for name in LAYERS if name.count(".") > 1]
    assert not inside, f"a layer of its own inside a folder: {inside}"
    top = {m.split(".")[1] for m in files() if within(m, B) and m != B}
    assert {name.split(".")[1] for name in LAYERS if name != B} == top


def test_every_baselines_module_has_a_layer() -> None:
    missing = [m for m in files() if within(m, B) and layer(m, LAYERS) is None]
    assert not missing, f"add these modules to LAYERS: {missing}"


def test_modules_import_only_their_own_or_lower_layers() -> None:
    bad = _upward(edges(B, _graph()))
    assert not bad, "layering broken:\n" + "\n".join(bad)


def test_no_import_cycles_in_baselines() -> None:
    cycle = find_cycle(_graph())
    assert cycle is None, "import cycle: " + " -> ".join(cycle or [])
