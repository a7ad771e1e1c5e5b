"""The API reference: one autodoc page per public module of ``shipgym`` and
``shipgym_baselines`` (a module is public unless a part of its dotted name starts with ``_``;
``__main__`` modules and the paper reproductions' inner modules are left to their package)."""

from __future__ import annotations

import pkgutil
from pathlib import Path

import shipgym
import shipgym_baselines
from shipgym_docs.pages import write_text

PACKAGES = (shipgym, shipgym_baselines)


def public_modules() -> list[str]:
    """Every public module of the two packages, sorted."""
    names = []
    for package in PACKAGES:
        names.append(package.__name__)
        for info in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
            parts = info.name.split(".")
            if any(p.startswith("_") for p in parts):
                continue
            names.append(info.name)
    return sorted(names)


def page(module: str) -> str:
    return f"# `{module}`\n\n```{{eval-rst}}\n.. automodule:: {module}\n```\n"


def write(root: Path) -> list[Path]:
    folder = root / "api"
    modules = public_modules()
    index = (
        "# API reference\n\n"
        "Every public module of `shipgym` (the environments, ships, scenarios, "
        "identification) and `shipgym_baselines` (controllers, evaluation, leaderboard, "
        "command line), from their docstrings.\n\n"
        "```{toctree}\n:maxdepth: 1\n\n" + "\n".join(modules) + "\n```\n"
    )
    out = [write_text(folder / "index.md", index)]
    out += [write_text(folder / f"{m}.md", page(m)) for m in modules]
    return out


def write_placeholder(root: Path) -> list[Path]:
    """The API index of a build without the API reference (``-D shipgym_docs_api=0``)."""
    text = (
        "# API reference\n\n"
        "Left out of this build (`-D shipgym_docs_api=0`); the full build documents every "
        "public module of `shipgym` and `shipgym_baselines`.\n"
    )
    return [write_text(root / "api" / "index.md", text)]
