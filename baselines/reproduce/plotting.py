"""Matplotlib for the reproductions' figures: headless, each figure saved and closed."""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

from shipgym_baselines.records.outfiles import write_bytes


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the non-interactive Agg backend (imported on first use)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(fig: Any, path: Path, dpi: int = 90) -> None:
    """Write ``fig`` to ``path`` (PNG, ``dpi`` dots per inch; through no link:
    :func:`~shipgym_baselines.records.outfiles.write_bytes`) and close it."""
    image = io.BytesIO()
    fig.savefig(image, format="png", dpi=dpi)
    pyplot().close(fig)
    write_bytes(path, image.getvalue())
