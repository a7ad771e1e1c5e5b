"""docs/validation.md holds its tables in its Markdown source: every ship's figures and every
published value with its source, as the code computes them now."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from shipgym.models import MODELS
from shipgym.validation import published

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "docs" / "_ext"))

from shipgym_docs import validation  # noqa: E402


@pytest.fixture(scope="module")
def tables() -> dict[str, str]:
    return validation.tables()


def test_the_pages_tables_are_what_the_code_computes_now(tables: dict[str, str]) -> None:
    page = validation.PAGE.read_text(encoding="utf-8")
    assert validation.inline(page, tables) == page, (
        "the tables of docs/validation.md differ from what shipgym.validation computes now: "
        f"run `{validation.COMMAND}` from the checkout and commit the page"
    )


def test_every_ship_has_a_table_with_its_sources(tables: dict[str, str]) -> None:
    assert list(tables) == [*MODELS, "esso_osaka_options"]
    for ship in MODELS:
        for ref in published(ship):
            assert ref.source.split(" (")[0] in tables[ship]


def test_a_table_without_its_markers_is_named() -> None:
    with pytest.raises(ValueError, match="'mariner'"):
        validation.inline("# a page\n", {"mariner": "| a |\n|---|\n"})
