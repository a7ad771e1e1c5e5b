"""The notebooks (``notebooks/*.ipynb``) as tutorials, rendered as stored (not executed:
the tests execute them)."""

from __future__ import annotations

import os
from pathlib import Path

from shipgym_docs.pages import write_bytes, write_text

#: the checkout's notebooks; ``SHIPGYM_NOTEBOOKS`` points elsewhere (a docs build from a copy)
NOTEBOOKS = Path(
    os.environ.get("SHIPGYM_NOTEBOOKS", Path(__file__).resolve().parents[3] / "notebooks")
)


def write(root: Path) -> list[Path]:
    folder = root / "tutorials"
    notebooks = sorted(NOTEBOOKS.glob("*.ipynb"))
    out = [write_bytes(folder / nb.name, nb.read_bytes()) for nb in notebooks]
    index = (
        "# Tutorials\n\n"
        "The notebooks of `notebooks/`, rendered as stored (the tests execute them: "
        "`tests/test_notebooks.py`).\n\n"
        "```{toctree}\n:glob:\n\n*\n```\n"
    )
    out.append(write_text(folder / "index.md", index))
    return out
