"""A run's output folder (``--out``): whether it can hold a run (checked before any work)
and removing an earlier run's outputs from it (``--force`` of the commands whose outputs
are named by pattern)."""

from __future__ import annotations

import fnmatch
import os
import shutil
from collections.abc import Sequence
from pathlib import Path

from shipgym_baselines.errors import RunError
from shipgym_baselines.records.episodes import read_episodes
from shipgym_baselines.records.jsonfiles import read_json
from shipgym_baselines.records.locking import LOCK_FILE, in_use, lock_holder
from shipgym_baselines.records.outfiles import check_no_links
from shipgym_baselines.records.runrecord import RUN_FILE


def check_out_usable(out: str | os.PathLike, *, resume: bool = False, force: bool = False) -> Path:
    """``out`` as a Path if it can be a run's folder at all; a :class:`RunError` when it
    cannot: a file, below a file, not writable (checked before the suite is read)."""
    path = Path(out)
    if resume and force:
        raise RunError("--resume and --force exclude each other")
    if path.exists() and not path.is_dir():
        raise RunError(f"--out {path} is a file, not a folder")
    existing = next(p for p in (path, *path.parents) if p.exists() or p == Path(p.anchor))
    if not existing.is_dir():
        raise RunError(f"--out {path}: {existing} is a file, not a folder")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise RunError(f"--out {path}: {existing} is not writable")
    return path


def check_out_dir(
    out: str | os.PathLike, *, resume: bool = False, force: bool = False, note: str = ""
) -> Path:
    """``out`` as a Path once it can hold this run; a :class:`RunError` before any work when
    it cannot: unusable (:func:`check_out_usable`), in use by another run (its lock:
    :mod:`shipgym_baselines.records.locking`), holding a link or a special file
    (:func:`~shipgym_baselines.records.outfiles.check_no_links`: a run writes through none), or
    not empty without ``resume`` / ``force`` (``note`` is added to that message, e.g.
    where a default folder came from; a lock file left by a killed run does not count)."""
    path = check_out_usable(out, resume=resume, force=force)
    holder = lock_holder(path)
    if holder is not None:
        raise in_use(path, holder)
    check_no_links(path)
    entries = sorted(p.name for p in path.iterdir() if not _is_lock(p)) if path.is_dir() else []
    if resume and RUN_FILE not in entries:
        raise RunError(f"--resume: {path} holds no run to resume (no {RUN_FILE})")
    if entries and not (resume or force):
        raise RunError(
            f"--out {path} is not empty ({_describe(path, entries)}){note}; pass --resume to "
            "finish that run, --force to replace it, or another --out"
        )
    return path


def _is_lock(entry: Path) -> bool:
    """Whether ``entry`` is a lock file (:data:`LOCK_FILE`, a regular file, not a link)."""
    return entry.name == LOCK_FILE and entry.is_file() and not entry.is_symlink()


def _describe(path: Path, entries: list[str]) -> str:
    """What an occupied folder holds, for the refusal message."""
    if RUN_FILE in entries:
        try:
            record = read_json(path / RUN_FILE)
            status = record.get("status", "?") if isinstance(record, dict) else "unreadable"
            count = f"{len(read_episodes(path))} episodes"
        except RunError:
            return "an earlier run, unreadable"
        return f"an earlier run, {status}, {count}"
    shown = ", ".join(entries[:3]) + (", …" if len(entries) > 3 else "")
    return f"{len(entries)} entries: {shown}"


def clear_outputs(
    folder: str | os.PathLike, outputs: Sequence[str], option: str = "--force"
) -> None:
    """Remove the earlier outputs (names or glob patterns of ``outputs``) from ``folder``;
    a :class:`RunError`, before removing anything, when it holds anything else (a run's
    lock file, :data:`LOCK_FILE`, is neither)."""
    path = Path(folder)
    if not path.is_dir():
        return
    entries = sorted(p for p in path.iterdir() if not _is_lock(p))  # not an output
    foreign = [p.name for p in entries if not any(fnmatch.fnmatch(p.name, o) for o in outputs)]
    if foreign:
        raise RunError(
            f"{option}: {path} holds files no run wrote ({', '.join(foreign)}): move them "
            "away or choose another folder"
        )
    for entry in entries:
        if entry.is_dir() and not entry.is_symlink():
            shutil.rmtree(entry)
        else:
            entry.unlink()


__all__ = ["check_out_dir", "check_out_usable", "clear_outputs"]
