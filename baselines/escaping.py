"""Names written as text: a controller or scenario name is anything its author chose.

Each writer that puts a name where it could be read as markup escapes it here:

* :func:`plain_text`: matplotlib (figures) draws it as typed, never as mathtext;
* :func:`md_cell`: a ``leaderboard.md`` table cell stays one cell;
* :func:`csv_cell`: a ``leaderboard.csv`` cell is never a spreadsheet formula.

(HTML and SVG escape names themselves: :mod:`shipgym_baselines.page.html`, matplotlib's SVG
writer.)
"""

from __future__ import annotations

from typing import Any

#: first characters that make a spreadsheet read a cell as a formula (OWASP CSV injection)
FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")


def plain_text(text: str) -> str:
    """``text`` as matplotlib draws it literally: every ``$`` escaped, so no name is read as
    mathtext (``$\\undefinedmacro{x}$`` is drawn as typed instead of failing the figure)."""
    return text.replace("$", r"\$")


def md_cell(text: str) -> str:
    """``text`` as one Markdown table cell: ``|`` escaped, line breaks as spaces."""
    return " ".join(text.replace("|", r"\|").splitlines())


def csv_cell(value: Any) -> Any:
    """A CSV cell: text that a spreadsheet would run as a formula gets a leading ``'``
    (numbers, negative ones included, are left as they are)."""
    if isinstance(value, str) and value.startswith(FORMULA_STARTS):
        return "'" + value
    return value


__all__ = ["FORMULA_STARTS", "csv_cell", "md_cell", "plain_text"]
