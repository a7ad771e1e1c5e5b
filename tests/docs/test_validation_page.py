"""docs/validation.md: the generated tables hold every ship's figures and every published
value with its source, and the page includes each of them."""

from __future__ import annotations

import sys
from pathlib import Path

from shipgym.models import MODELS
from shipgym.validation import published

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "docs" / "_ext"))

from shipgym_docs import validation  # noqa: E402


def test_every_ship_has_a_table_with_its_sources_and_the_page_includes_it(
    tmp_path: Path,
) -> None:
    written = {p.name: p.read_text(encoding="utf-8") for p in validation.write(tmp_path)}
    page = (REPO / "docs" / "validation.md").read_text(encoding="utf-8")
    for name in [f"{ship}.inc.md" for ship in MODELS] + ["esso_osaka_options.inc.md"]:
        assert f"_generated/validation/{name}" in page
        assert name in written
    for ship in MODELS:
        for ref in published(ship):
            assert ref.source.split(" (")[0] in written[f"{ship}.inc.md"]
