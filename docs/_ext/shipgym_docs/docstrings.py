"""Docstrings as the API reference reads them.

The package's docstrings are written as plain text with reStructuredText roles: ``|e|`` is an
absolute value, not a substitution.  :func:`escape_bars` escapes every ``|`` outside inline
literals and literal blocks before autodoc parses a docstring; :func:`skip_foreign` leaves out
module attributes that are not the package's (``numerics.min`` is ``builtins.min``).
"""

from __future__ import annotations

import re
from typing import Any

from sphinx.application import Sphinx

LITERAL = re.compile(r"(``.*?``)")
ROLE = re.compile(r"(:[\w:.-]+:`[^`]*`)")


def _escape(text: str) -> str:
    """``|`` → ``\\|`` outside ``inline literals`` and role targets."""
    parts = []
    for piece in LITERAL.split(text):
        if piece.startswith("``") and piece.endswith("``") and len(piece) >= 4:
            parts.append(piece)
            continue
        parts.append(
            "".join(
                p if ROLE.fullmatch(p) else re.sub(r"(?<!\\)\|", r"\\|", p)
                for p in ROLE.split(piece)
            )
        )
    return "".join(parts)


def escape_bars(lines: list[str]) -> list[str]:
    """The docstring's lines with bars escaped, except in literal blocks (after ``::``) and
    in table rows (lines starting with ``|`` or ``+``)."""
    out = []
    block_indent: int | None = None  # indentation of the line that opened a literal block
    for line in lines:
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if block_indent is not None and stripped and indent <= block_indent:
            block_indent = None
        if (
            block_indent is not None
            or stripped.startswith(("|", "+"))
            or ".. " in line[: indent + 3]
        ):
            out.append(line)
        else:
            out.append(_escape(line))
        if block_indent is None and line.rstrip().endswith("::"):
            block_indent = indent
    return out


def process_docstring(
    app: Sphinx, what: str, name: str, obj: Any, options: Any, lines: list[str]
) -> None:
    lines[:] = escape_bars(lines)


def skip_foreign(
    app: Sphinx, what: str, name: str, obj: Any, skip: bool, options: Any
) -> bool | None:
    """Skip a module's attribute defined outside the package (an alias of a builtin)."""
    module = getattr(obj, "__module__", None)
    if what == "module" and callable(obj) and isinstance(module, str):
        if not module.startswith(("shipgym", "shipgym_baselines")):
            return True
    return None
