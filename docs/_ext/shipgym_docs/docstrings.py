"""Docstrings as the API reference shows them: as written.

The package's docstrings are plain text with aligned equations (``|e|`` is an absolute value,
``X_|u|u`` a coefficient's name), not reStructuredText; parsed as reST they would break into
substitutions, hyperlink targets and block quotes.  :func:`as_written` shows each one as a
literal block, with the roles' markup reduced to their targets; a docstring written as reST
on purpose (one with a ``.. rubric::`` or ``.. list-table::``: the env classes, whose docstring
is their page) is left to reST.  :func:`skip_foreign` leaves out module attributes that are
not the package's (``numerics.any`` is ``numpy.any``).
"""

from __future__ import annotations

import re
from typing import Any

from sphinx.application import Sphinx

#: ``:role:`~a.b.C``` or ``:role:`text <target>``` → the name a reader looks for
ROLE = re.compile(r":[\w:.-]+:`~?([^`<]*?)\s*(?:<[^>]*>)?`")
#: what marks a docstring written as reStructuredText on purpose
REST = (".. rubric::", ".. list-table::")


def as_written(lines: list[str]) -> list[str]:
    """The docstring's lines as a literal block (unless it is reST on purpose)."""
    if not any(line.strip() for line in lines) or any(m in "\n".join(lines) for m in REST):
        return lines
    body = [("    " + ROLE.sub(r"\1", line)).rstrip() for line in lines]
    return ["::", "", *body, ""]


def process_docstring(
    app: Sphinx, what: str, name: str, obj: Any, options: Any, lines: list[str]
) -> None:
    lines[:] = as_written(lines)


def skip_foreign(
    app: Sphinx, what: str, name: str, obj: Any, skip: bool, options: Any
) -> bool | None:
    """Skip a member defined outside the package (``numerics.any`` is ``numpy.any``)."""
    module = getattr(obj, "__module__", None)
    if callable(obj) and isinstance(module, str) and not module.startswith("shipgym"):
        return True
    return None
