"""Sphinx configuration of the shipgym docs (MyST Markdown, Furo).

Build: ``python -m sphinx -W -b html docs docs/_build/html``.  The env, scenario, controller
and ship pages and the tutorials are generated at build time into ``_generated/`` (ignored by
git) by the local extension :mod:`shipgym_docs` (``_ext/``).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))

import shipgym  # noqa: E402

project = "shipgym"
author = "The shipgym developers"
copyright = "2026, The shipgym developers"
release = version = shipgym.__version__

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinxcontrib.bibtex",
    "shipgym_docs",
]

source_suffix = {".md": "myst-nb", ".ipynb": "myst-nb"}
exclude_patterns = [
    "_build",
    "Thumbs.db",
    ".DS_Store",
    "**.ipynb_checkpoints",
    "_generated/ships",
]
myst_enable_extensions = ["colon_fence", "dollarmath", "deflist"]
myst_heading_anchors = 3
# ref.python: a name documented in two modules (a re-export) is an ambiguous target
suppress_warnings = ["myst.header", "ref.python"]

# the notebooks are executed by the tests (tests/test_notebooks.py), rendered here as stored
nb_execution_mode = "off"

bibtex_bibfiles = ["references.bib"]
bibtex_default_style = "plain"
bibtex_reference_style = "author_year"

autodoc_default_options = {"members": True, "show-inheritance": True, "ignore-module-all": True}
autodoc_member_order = "bysource"
autodoc_typehints = "none"
# an override without a docstring shows none (not Gymnasium's own Env.step text)
autodoc_inherit_docstrings = False
autodoc_mock_imports: list[str] = []

# -D shipgym_docs_api=0 leaves the API reference out (a quicker build)
shipgym_docs_api = True

html_theme = "furo"
html_title = f"shipgym {release}"
