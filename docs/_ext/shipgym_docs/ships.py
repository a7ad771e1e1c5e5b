"""The ship models' parameter tables: every parameter's name, unit, value and meaning.

Read from the parameter records themselves (:mod:`shipgym.models`): the default value of each
field and the comment the code gives it (``# meaning [unit]``), so that the table is the code.
The hand-written part (sources, checks, unit readings) is ``docs/ships.md``, which includes
the generated ``_generated/ships/parameters.inc.md``.
"""

from __future__ import annotations

import ast
import dataclasses
import inspect
import io
import re
import tokenize
from pathlib import Path

from shipgym.models import MODELS
from shipgym.models.base import ParameterRecord
from shipgym_docs.pages import number, table, write_text

#: the unit of a field comment: its first ``[...]``
UNIT = re.compile(r"\s*\[([^\]]*)\]")


def field_comments(record: type[ParameterRecord]) -> dict[str, str]:
    """Field name -> the comment on its line in the record's class body."""
    source = inspect.getsource(record)
    lines: dict[int, str] = {}
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type == tokenize.COMMENT:
            lines[token.start[0]] = token.string.lstrip("#").strip()
    out = {}
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            out[node.target.id] = lines.get(node.end_lineno or node.lineno, "")
    return out


def rows(record: type[ParameterRecord]) -> list[tuple[str, str, str, str]]:
    """(name, unit, default value, meaning) of every field of ``record``."""
    comments = field_comments(record)
    defaults = record()
    out = []
    for field in dataclasses.fields(record):
        comment = comments.get(field.name, "")
        match = UNIT.search(comment)
        unit = match.group(1) if match else ""
        meaning = UNIT.sub("", comment, count=1).strip() if match else comment
        out.append((f"`{field.name}`", unit, number(getattr(defaults, field.name)), meaning))
    return out


def section(name: str) -> str:
    model = MODELS[name]
    doc = inspect.getdoc(inspect.getmodule(model)) or ""
    source = doc.split("\n\n", 1)[0].replace("\n", " ")
    record = model.params_type
    return "\n".join(
        [
            f"(ship-{name})=\n### `{name}` parameters\n",
            f"`{record.__module__}.{record.__name__}` — {source}\n",
            f"Control period Ts = {model.control_period:g} s, fine step h = "
            f"{model.fine_step:g} s; states `{', '.join(model.state_names)}`; disturbances "
            f"`{', '.join(model.disturbance_names)}`.\n",
            table(["parameter", "unit", "value", "meaning and source"], rows(record)),
        ]
    )


def write(root: Path) -> list[Path]:
    text = "\n".join(section(name) for name in MODELS)
    return [write_text(root / "ships" / "parameters.inc.md", text)]
