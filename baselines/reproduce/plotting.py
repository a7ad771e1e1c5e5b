"""Matplotlib for the reproductions' figures: headless, each figure saved and closed."""

from __future__ import annotations

from pathlib import Path
from typing import Any


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the non-interactive Agg backend (imported on first use)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(fig: Any, path: Path, dpi: int = 90) -> None:
    """Write ``fig`` to ``path`` (PNG, ``dpi`` dots per inch) and close it."""
    fig.savefig(path, dpi=dpi)
    pyplot().close(fig)
