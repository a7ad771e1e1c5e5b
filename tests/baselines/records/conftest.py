"""The records tests' tiny suite (2 scenarios × 2 controllers × 2 seeds: 8 quick episodes)
and one clean run of it."""

from __future__ import annotations

import contextlib
import json
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml

from shipgym_baselines.jsonout import dumps
from shipgym_baselines.leaderboard.run import run_leaderboard

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


#: a process that holds a file's lock (:func:`~shipgym_baselines.records.locking.file_lock`)
#: until it is killed: argv[1] the file, argv[2] the option that names it
HOLD_FILE_LOCK = """
import sys, time
from shipgym_baselines.records.locking import file_lock
with file_lock(sys.argv[1], "2026-01-02T03:04:05+00:00", sys.argv[2]):
    print("locked", flush=True)
    time.sleep(600)
"""


@contextlib.contextmanager
def file_held_elsewhere(file: Path, option: str) -> Iterator[subprocess.Popen[str]]:
    """Another process holding ``file``'s lock (named by ``option``) for the ``with`` body;
    killed at its end (the kernel then releases the lock, the lock file stays)."""
    root = Path(__file__).resolve().parents[3]
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLD_FILE_LOCK, str(file), option],
        cwd=root,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline() == "locked\n"
        yield holder
    finally:
        holder.kill()
        holder.wait()
