"""Every name is imported from the module that defines it: no module re-exports a name it
does not define (no alias module, no ``__all__`` of foreign names, no ``import x as x``)."""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

from tests.import_graph import ROOT, files, parsed


def _bound(body: list[ast.stmt]) -> Iterator[str]:
    """The names a module body defines itself (functions, classes, assignments), looking
    into ``if`` and ``try`` blocks."""
    for node in body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            yield node.name
        elif isinstance(node, ast.Assign | ast.AnnAssign | ast.AugAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for target in targets:
                yield from (n.id for n in ast.walk(target) if isinstance(n, ast.Name))
        elif isinstance(node, ast.If):
            yield from _bound(node.body)
            yield from _bound(node.orelse)
        elif isinstance(node, ast.Try):
            yield from _bound(node.body + node.orelse + node.finalbody)
            for handler in node.handlers:
                yield from _bound(handler.body)


def _defined(module: str) -> set[str]:
    return set(_bound(parsed(module).body))


def _sources() -> Iterator[tuple[str, Path, ast.Module]]:
    """(package of relative imports, path, tree) of every Python file of the project and
    its tests."""
    for module, path in files().items():
        package = module if path.name == "__init__.py" else module.rpartition(".")[0]
        yield package, path, parsed(module)
    for path in sorted((ROOT / "tests").rglob("*.py")):
        yield "tests", path, ast.parse(path.read_text(), filename=str(path))


def _imports(package: str, tree: ast.Module) -> Iterator[tuple[ast.ImportFrom, str]]:
    """Each ``from M import ...`` of a project module M, with M resolved."""
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*anchor, base] if base else anchor)
            if base in files():
                yield node, base


def test_every_name_is_imported_from_the_module_that_defines_it() -> None:
    bad = [
        f"{path.relative_to(ROOT)}:{node.lineno}: {alias.name} is not defined in {base}"
        for package, path, tree in _sources()
        for node, base in _imports(package, tree)
        for alias in node.names
        if alias.name != "*"
        and f"{base}.{alias.name}" not in files()
        and alias.name not in _defined(base)
    ]
    assert not bad, "import each name from its own module:\n" + "\n".join(bad)


def test_no_all_lists_a_foreign_name_and_no_import_marks_one_for_export() -> None:
    bad = []
    for _, path, tree in _sources():
        for node in tree.body:
            if isinstance(node, ast.Assign) and any(
                isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets
            ):
                module = next((m for m, p in files().items() if p == path), None)
                names = ast.literal_eval(node.value)
                defined = _defined(module) if module else set()
                bad += [
                    f"{path.relative_to(ROOT)}: __all__ lists {n}"
                    for n in names
                    if n not in defined
                ]
        bad += [
            f"{path.relative_to(ROOT)}:{node.lineno}: import {alias.name} as {alias.name}"
            for node in ast.walk(tree)
            if isinstance(node, ast.ImportFrom | ast.Import)
            for alias in node.names
            if alias.asname == alias.name
        ]
    assert not bad, "\n".join(bad)
