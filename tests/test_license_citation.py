"""LICENSE (MIT) and CITATION.cff agree with pyproject.toml."""

from __future__ import annotations

import tomllib
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parents[1]


def test_license_is_mit_with_our_copyright() -> None:
    text = (REPO / "LICENSE").read_text()
    assert text.startswith("MIT License")
    assert "Copyright (c) 2026 The shipgym developers" in text
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    assert project["license"] == {"text": "MIT"}


def test_citation_names_this_version_and_the_five_source_papers() -> None:
    cff = yaml.safe_load((REPO / "CITATION.cff").read_text())
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    assert cff["cff-version"] == "1.2.0"
    assert str(cff["version"]) == project["version"]
    assert cff["license"] == "MIT"
    assert cff["authors"] == [{"name": "The shipgym developers"}]
    years = sorted(ref["year"] for ref in cff["references"])
    assert years == [2013, 2018, 2020, 2021, 2021]
    assert all(ref["type"] == "article" and ref["title"] for ref in cff["references"])
