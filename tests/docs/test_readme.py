"""The README is a front door (issue 20): short, its links resolve, and its test command is
the one CI runs."""

from __future__ import annotations

import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
README = (REPO / "README.md").read_text(encoding="utf-8")


def test_the_readme_is_at_most_250_lines() -> None:
    assert len(README.splitlines()) <= 250


def test_every_link_of_the_readme_resolves() -> None:
    links = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", README)
    local = [link for link in links if not link.startswith("http")]
    assert len(local) >= 10
    for link in local:
        assert (REPO / link).is_file(), link


def test_the_readme_test_command_is_what_ci_runs() -> None:
    blocks = re.findall(r"```bash\n(.*?)```", README, flags=re.S)
    (command,) = [b.strip() for b in blocks if "pytest" in b]
    assert command in (REPO / ".ci" / "run").read_text().splitlines()


def test_the_readme_mentions_the_notebooks_and_the_docs_build() -> None:
    for notebook in (REPO / "notebooks").glob("*.ipynb"):
        assert f"notebooks/{notebook.name}" in README
    assert "python -m sphinx -W -b html docs docs/_build/html" in README
