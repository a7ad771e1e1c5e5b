"""The import graph of shipgym follows the layering of docs/architecture.md; every error
class of shipgym and baselines is a ShipgymError.

The graph (:mod:`tests.import_graph`) counts every import statement: top-level, inside
functions (lazy), under ``if TYPE_CHECKING:``, in ``try`` blocks.  Dynamic imports
(``importlib.import_module``) and gymnasium's entry-point strings are not edges here.
``baselines/``'s layers: tests/baselines/test_layers.py.
"""

from __future__ import annotations

import ast
import importlib

from tests.import_graph import edges, files, find_cycle, import_graph, imported_names, layer, within

#: The layer of every folder of shipgym and of every module at its top, lowest first; an
#: entry for a folder covers every module in it (no folder spans two layers).  A module
#: imports only modules of its own or a lower layer.
LAYERS: dict[str, int] = {
    # 0 — foundations: the error base, config files, scalar/array operation sets, angle
    #     arithmetic, path geometry, the terminal's notice lines, CasADi functions compiled
    #     to C
    "shipgym.errors": 0,
    "shipgym.limits": 0,
    "shipgym.notices": 0,
    "shipgym.config": 0,
    "shipgym.numerics": 0,
    "shipgym.angles": 0,
    "shipgym.paths": 0,
    "shipgym.codegen": 0,
    # 1 — ship models: each ship's record and right-hand side, parameter records, RK4, the
    #     unrolled CasADi control period
    "shipgym.models": 1,
    # 2 — standard manoeuvres (zig-zag, turning circle) simulated on a model
    "shipgym.manoeuvres": 2,
    # the IMO manoeuvring criteria (MSC.137(76)) a manoeuvre is measured against
    "shipgym.manoeuvring_standards": 2,
    # every ship's standard manoeuvres beside the published values of its hull
    "shipgym.validation": 2,
    # 3 — identification: LS-SVM fits, online identifiers, nominal models from zig-zags
    "shipgym.identification": 3,
    # 4 — guidance laws, heading autopilots, path tracking, disturbances and sensors (and
    #     their validated settings)
    "shipgym.guidance": 4,
    "shipgym.autopilot": 4,
    "shipgym.tracking": 4,
    "shipgym.disturbances": 4,
    "shipgym.disturbance_config": 4,
    # 5 — scenarios: change families, config schema, loader, events, distributions
    "shipgym.scenarios": 5,
    # 6 — an episode's metrics and rendering
    "shipgym.metrics": 6,
    "shipgym.rendering": 6,
    "shipgym.animation": 6,
    # 7 — the environments, and the package itself (it registers them)
    "shipgym.envs": 7,
    "shipgym": 7,
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
    names = set(imported_names(ast.parse(source), "shipgym.models.nomoto2", False))
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
        m: frozenset(t for t in targets if within(t, "shipgym"))
        for m, targets in import_graph().items()
        if within(m, "shipgym")
    }
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(cycle or [])


def test_shipgym_never_imports_baselines() -> None:
    bad = [(m, t) for m, t in edges("shipgym") if within(t, "shipgym_baselines")]
    assert not bad, f"shipgym imports baselines: {bad}"


def test_models_import_nothing_above_them() -> None:
    bad = [
        (m, t)
        for m, t in edges("shipgym.models")
        if any(within(t, above) for above in ABOVE_MODELS)
    ]
    assert not bad, f"ship models import higher layers: {bad}"


def test_each_layer_is_a_folder_or_a_module_at_the_top() -> None:
    """No entry of LAYERS lies inside a folder: a folder sits on one layer as a whole."""
    inside = [name for name in LAYERS if name.count(".") > 1]
    assert not inside, f"a layer of its own inside a folder: {inside}"


def test_every_shipgym_module_has_a_layer() -> None:
    missing = [m for m in import_graph() if within(m, "shipgym") and layer(m, LAYERS) is None]
    assert not missing, f"add these modules to LAYERS: {missing}"


def test_modules_import_only_their_own_or_lower_layers() -> None:
    bad = [
        f"{m} (layer {layer(m, LAYERS)}) imports {t} (layer {layer(t, LAYERS)})"
        for m, t in edges("shipgym")
        if (layer(t, LAYERS) or 0) > (layer(m, LAYERS) or 0)
    ]
    assert not bad, "layering broken:\n" + "\n".join(bad)


def test_only_the_scenario_layer_reads_the_config_schema() -> None:
    bad = [
        (m, t)
        for m, t in edges("shipgym")
        if t == CONFIG_SCHEMA and not within(m, "shipgym.scenarios")
    ]
    assert not bad, f"schema read outside scenarios: {bad}"


def test_every_project_error_is_a_shipgym_error() -> None:
    """Each ``class …Error`` of shipgym and baselines derives from ShipgymError: the CLI
    prints those as one line."""
    from shipgym.errors import ShipgymError

    errors = {
        (module, node.name)
        for module, path in files().items()
        for node in ast.walk(ast.parse(path.read_text()))
        if isinstance(node, ast.ClassDef) and node.name.endswith("Error")
    }
    assert ("shipgym.identification.errors", "IdentificationError") in errors
    for module, name in sorted(errors):
        cls = getattr(importlib.import_module(module), name)
        assert issubclass(cls, ShipgymError), f"{module}.{name} is not a ShipgymError"
