"""The records tests' tiny suite (2 scenarios × 2 controllers × 2 seeds: 8 quick episodes)
and one clean run of it."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from shipgym_baselines.jsonout import dumps
from shipgym_baselines.leaderboard import run_leaderboard

TINY = {
    "name": "tiny",
    "scenarios": ["nominal", "rudder_aging"],
    "controllers": ["pid_los", "zero_rudder"],
    "seeds": 2,
}
TIMING = ("compute_ms", "compute_ms_std", "compute_ms_max")


def write_suite(folder: Path, **changes: object) -> str:
    file = folder / "tiny.yaml"
    file.write_text(yaml.safe_dump({**TINY, **changes}))
    return str(file)


def resume_tiny(folder: Path, out: Path) -> tuple[list[object], list[dict]]:
    """The tiny suite (written in ``folder``) resumed in ``out``: the episodes it ran and
    the table's rows."""
    ran: list[object] = []
    rows = run_leaderboard(
        write_suite(folder),
        out_dir=out,
        workers=1,
        show_progress=False,
        resume=True,
        on_episode=ran.append,
    )
    return ran, rows


def untimed(rows: list[dict]) -> list[dict]:
    """Rows as leaderboard.json holds them, wall-clock timings aside."""
    return [
        {k: v for k, v in r.items() if not k.startswith(TIMING)} for r in json.loads(dumps(rows))
    ]


@pytest.fixture(scope="session")
def clean_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The tiny suite run once, uninterrupted."""
    root = tmp_path_factory.mktemp("clean")
    run_leaderboard(write_suite(root), out_dir=root / "out", workers=1, show_progress=False)
    return root / "out"


def copy_run(source: Path, target: Path) -> Path:
    """A copy of a finished run folder (its record and episodes)."""
    target.mkdir()
    for name in ("run.json", "episodes.jsonl"):
        (target / name).write_bytes((source / name).read_bytes())
    return target
