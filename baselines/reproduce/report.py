"""The markdown of every reproduction report: one table formatter, one cell formatter."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import Any

from shipgym_baselines.reproduce.protocol import Rows


def cell(value: Any, spec: str = ".4g", inf: str = "inf") -> str:
    """One table cell: "–" where there is no number (None), yes/no for booleans, ``inf``
    for +∞, ``str`` of −∞ and NaN, else ``format(value, spec)``."""
    if value is None:
        return "–"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float) and not math.isfinite(value):
        return inf if value > 0 else str(value)
    return format(value, spec)


def table(head: Sequence[str], body: Iterable[Sequence[str]]) -> list[str]:
    """The lines of a markdown table: header, separator, one line per body row; a "|"
    inside a cell (as in |e|) is escaped."""
    return [_line(head), "|" + "---|" * len(head), *(_line(cells) for cells in body)]


def _line(cells: Sequence[str]) -> str:
    return "| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |"


def index(rows: Rows, *keys: str) -> dict[tuple[Any, ...], dict[str, Any]]:
    """The rows by (case, controller, metric, *keys), e.g. ``keys = ("unit_reading",)``."""
    return {(r["case"], r["controller"], r["metric"], *(r[k] for k in keys)): r for r in rows}


def seeds_of(rows: Rows) -> int:
    """The number of seeds the rows are means over (0 for no rows)."""
    return rows[0]["seeds"] if rows else 0
