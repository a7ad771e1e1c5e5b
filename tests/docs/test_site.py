"""The docs site builds with warnings as errors, and every env id, catalogue scenario and
controller has its page.  Built from a copy of ``docs/`` in a tmp folder, so that
the generated pages never land in the checkout.  The full build with the API reference is
CI's (``.ci/run``)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import gymnasium as gym
import pytest

import shipgym  # noqa: F401  (registers the env ids)
from shipgym.scenarios.loader import list_scenarios
from shipgym_baselines.learned.policy import shipped_policies
from shipgym_baselines.registry import CONTROLLERS

REPO = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.docs


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The html site built by ``python -m sphinx -W -b html`` from a copy of docs/."""
    root = tmp_path_factory.mktemp("docs")
    src = root / "docs"
    shutil.copytree(REPO / "docs", src, ignore=shutil.ignore_patterns("_build", "_generated"))
    out = root / "html"
    env = {**os.environ, "SHIPGYM_NOTEBOOKS": str(REPO / "notebooks")}
    # the API reference (autodoc of every public module) is left out: it alone costs ≈ 100 CPU
    # seconds; CI's full build (.ci/run) documents it with the same -W
    command = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html"]
    command += ["-D", "shipgym_docs_api=0", "-d", str(root / "doctrees"), str(src), str(out)]
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, env=env, cwd=root)
    print(f"docs build: {time.perf_counter() - start:.1f} s wall")
    assert done.returncode == 0, done.stderr[-5000:]
    return out


def test_every_env_id_has_a_page(site: Path) -> None:
    ids = [i for i in gym.registry if i.startswith("ShipPathFollow")]
    assert len(ids) >= 8
    for env_id in ids:
        page = site / "_generated" / "envs" / f"{env_id}.html"
        text = page.read_text(encoding="utf-8").lower()
        for heading in (
            "Action space",
            "Observation space",
            "Reward",
            "Starting state",
            "Episode end",
            "Arguments",
            "Version history",
        ):
            assert heading.lower() in text, (env_id, heading)


def test_every_catalogue_scenario_has_a_page_and_a_route_figure(site: Path) -> None:
    names = list_scenarios()
    assert len(names) >= 30
    for name in names:
        assert (site / "_generated" / "scenarios" / f"{name}.html").is_file(), name
    images = {p.name for p in (site / "_images").glob("*.png")}
    assert {f"{name}.png" for name in names} <= images


def test_every_controller_and_learned_agent_has_a_page(site: Path) -> None:
    for name in [*CONTROLLERS, *shipped_policies()]:
        assert (site / "_generated" / "controllers" / f"{name}.html").is_file(), name


def test_the_hand_written_pages_and_the_tutorials_are_built(site: Path) -> None:
    for page in (
        "leaderboard",
        "records",
        "plugins",
        "reproduction",
        "identification",
        "learned-agents",
        "architecture",
        "references",
        "ships",
    ):
        assert (site / f"{page}.html").is_file(), page
    for notebook in (REPO / "notebooks").glob("*.ipynb"):
        assert (site / "_generated" / "tutorials" / f"{notebook.stem}.html").is_file()
    ships = (site / "ships.html").read_text(encoding="utf-8")
    assert "esso_osaka" in ships and "[1/s]" not in ships  # units parsed into their column
