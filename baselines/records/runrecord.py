"""A run's record, ``run.json``: what ran (``command``, the resolved ``suite``), with what
(:func:`versions`, :func:`git_commit`), when (:func:`now`, ISO 8601 UTC) and how it ended
(``status``); :func:`read_run` reads it back, checked."""

from __future__ import annotations

import contextlib
import datetime
import os
import platform
import subprocess
from importlib import metadata
from pathlib import Path
from typing import Any

from shipgym_baselines.errors import RunError
from shipgym_baselines.records.jsonfiles import read_json, short_json

RUN_FILE = "run.json"
#: distributions whose versions ``run.json`` records (those installed)
PACKAGES = (
    "numpy",
    "scipy",
    "gymnasium",
    "casadi",
    "pydantic",
    "stable-baselines3",
    "sb3-contrib",
    "torch",
)


def now() -> str:
    """The current time, ISO 8601 UTC (seconds)."""
    return datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")


def versions() -> dict[str, str]:
    """Python's and the installed main packages' versions (shipgym's own included)."""
    import shipgym

    found = {"python": platform.python_version(), "shipgym": shipgym.__version__}
    for name in PACKAGES:
        with contextlib.suppress(metadata.PackageNotFoundError):
            found[name] = metadata.version(name)
    return found


def git_commit() -> str | None:
    """``git rev-parse HEAD`` of the checkout the package runs from; None when it is not a
    git checkout (an installed wheel) or git is missing."""
    root = Path(__file__).resolve().parents[2]  # baselines/records/runrecord.py -> the checkout
    if not (root / ".git").exists():
        return None
    try:
        done = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True, timeout=10
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return (done.stdout.strip() or None) if done.returncode == 0 else None


def read_run(folder: str | os.PathLike) -> dict[str, Any]:
    """A run folder's ``run.json``; a :class:`RunError` naming the folder if it has none,
    or naming the file and the line or key where it is not a run record."""
    file = Path(folder) / RUN_FILE
    if not file.is_file():
        raise RunError(f"{folder}: not a run folder (no {RUN_FILE})")
    record = read_json(file)
    problem = _run_record_problem(record)
    if problem:
        raise RunError(f"{file}: not a run record ({problem})")
    return record


def _run_record_problem(record: Any) -> str | None:
    """What makes ``record`` no run record (the key and the problem), or None."""
    if not isinstance(record, dict) or not isinstance(record.get("suite"), dict):
        return "no 'suite'"
    suite = record["suite"]
    checks = (
        ("seeds", list, lambda v: all(type(x) is int for x in v), "a list of integers"),
        ("scenarios", dict, lambda v: all(isinstance(x, dict) for x in v.values()), "settings"),
        ("controllers", list, _controller_entries, "entries of name, kind, training_seeds"),
        ("does_not_apply", list, _pairs, "[scenario, controller] pairs"),
    )
    for key, kind, valid, what in checks:
        value = suite.get(key)
        if not isinstance(value, kind) or not valid(value):
            return f"key 'suite.{key}' is {short_json(value)}, not {what}"
    if not isinstance(suite.get("randomize"), dict | None):
        return f"key 'suite.randomize' is {short_json(suite.get('randomize'))}, not ranges or null"
    return None


def _controller_entries(value: list) -> bool:
    return all(
        isinstance(c, dict)
        and isinstance(c.get("name"), str)
        and isinstance(c.get("kind"), str)
        and isinstance(c.get("training_seeds"), list)
        and all(s is None or type(s) is int for s in c["training_seeds"])
        for c in value
    )


def _pairs(value: list) -> bool:
    return all(
        isinstance(p, list) and len(p) == 2 and all(isinstance(x, str) for x in p) for p in value
    )


__all__ = ["PACKAGES", "RUN_FILE", "git_commit", "now", "read_run", "versions"]
