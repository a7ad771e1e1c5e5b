"""Writing generated pages: only when their text changes; Markdown tables and escaping."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path


def write_text(path: Path, text: str) -> Path:
    """Write ``text`` to ``path`` unless it already holds it (keeps mtimes for Sphinx)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")
    return path


def write_bytes(path: Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` unless it already holds it."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_bytes() != data:
        path.write_bytes(data)
    return path


def cell(value: object) -> str:
    """One Markdown table cell: pipes escaped, newlines folded."""
    return " ".join(str(value).split()).replace("|", "\\|")


def table(header: Sequence[str], rows: Iterable[Sequence[object]]) -> str:
    """A Markdown pipe table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def rst_block(text: str) -> str:
    """reStructuredText (a docstring) embedded in a MyST page."""
    return "```{eval-rst}\n" + text.strip() + "\n```\n"


def number(value: float) -> str:
    """A parameter value to 6 significant digits."""
    return f"{float(value):.6g}"
