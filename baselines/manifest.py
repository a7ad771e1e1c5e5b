"""What a run wrote into its folder: the manifest that ``--force`` deletes by.

Every ``leaderboard`` / ``evaluate`` / ``report`` run lists each path it writes in
:data:`MANIFEST_FILE` (one folder-relative path a line, appended *before* the file is
written, so a run killed while writing a file still lists it; the tables and figures,
whose names the drawing code chooses, are listed as they appear).  ``--force`` deletes
exactly the listed paths and refuses, before deleting anything, a folder that holds
anything else: a user's file, a directory of their own, a file of an earlier shipgym
version that kept no manifest.  The lock file (:mod:`shipgym_baselines.locking`) is never listed
and never deleted.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterable, Iterator
from pathlib import Path

from shipgym_baselines.errors import RunError
from shipgym_baselines.locking import LOCK_FILE

#: the list of paths the runs in a folder wrote
MANIFEST_FILE = "manifest.txt"


def snapshot(folder: str | os.PathLike) -> set[str]:
    """Every path below ``folder`` (files, links and directories, relative, ``/``-separated;
    symbolic links are not followed), the lock file aside."""
    root = Path(folder)
    found: set[str] = set()
    for top, dirs, files in os.walk(root):
        for name in [*dirs, *files]:
            rel = (Path(top) / name).relative_to(root).as_posix()
            if rel != LOCK_FILE:
                found.add(rel)
    return found


def read_manifest(folder: str | os.PathLike) -> set[str]:
    """The paths ``folder``'s manifest lists (empty without one); the manifest itself
    included once it exists."""
    file = Path(folder) / MANIFEST_FILE
    if not file.is_file():
        return set()
    listed = {line for line in file.read_text(errors="replace").splitlines() if line}
    return listed | {MANIFEST_FILE}


class Manifest:
    """The manifest of an open run folder: :meth:`claim` a path before writing it,
    :meth:`claiming` around code that writes files it names itself."""

    def __init__(self, folder: str | os.PathLike):
        self.folder = Path(folder)
        self.listed = read_manifest(self.folder)

    def claim(self, *paths: str) -> None:
        """List ``paths`` (relative to the folder) unless listed; flushed at once."""
        new = [p for p in dict.fromkeys(paths) if p not in self.listed]
        if not new:
            return
        with open(self.folder / MANIFEST_FILE, "a", encoding="utf-8") as fh:
            fh.write("".join(f"{p}\n" for p in new))
        self.listed |= {*new, MANIFEST_FILE}

    @contextlib.contextmanager
    def claiming(self) -> Iterator[None]:
        """List every path that appears in the folder during the ``with`` body (also when
        it ends with an error)."""
        before = snapshot(self.folder)
        try:
            yield
        finally:
            self.claim(*sorted(snapshot(self.folder) - before))

    def compact(self, keep: Iterable[str] = ()) -> None:
        """Rewrite the manifest, when a run finishes, to list only the listed paths that
        exist and ``keep`` (what a later run in the folder may write again, e.g. the run
        record and its temporary): a run that wrote and removed thousands of trajectory
        files and their temporaries lists only those it kept (issue 20).  Never lists
        anything unlisted, so ``--force`` still deletes only what runs wrote.  Atomic
        (a listed temporary renamed over the manifest); on a full disk left as it was."""
        file = self.folder / MANIFEST_FILE
        tmp = f".{MANIFEST_FILE}.tmp"
        self.claim(tmp)  # a kill while it is written leaves it listed
        kept = sorted((self.listed & snapshot(self.folder)) | {*keep, tmp} - {MANIFEST_FILE})
        try:
            (self.folder / tmp).write_text("".join(f"{p}\n" for p in kept), encoding="utf-8")
            os.replace(self.folder / tmp, file)
        except OSError:
            (self.folder / tmp).unlink(missing_ok=True)
            return
        self.listed = {*kept, MANIFEST_FILE}


def clear_listed(folder: str | os.PathLike, option: str = "--force") -> None:
    """Delete what the manifest of ``folder`` lists; a :class:`RunError`, before deleting
    anything, when the folder holds anything the manifest does not list."""
    path = Path(folder)
    if not path.is_dir():
        return
    listed = read_manifest(path)
    present = snapshot(path)
    foreign = sorted(present - listed)
    if foreign:
        more = f", … ({len(foreign)} in all)" if len(foreign) > 5 else ""
        shown = ", ".join(foreign[:5]) + more
        why = "" if listed else f" (no {MANIFEST_FILE}: no run of this version wrote it)"
        raise RunError(
            f"{option}: {path} holds files no run wrote{why}: {shown}; move them away or "
            "choose another folder"
        )
    for rel in sorted(present, key=lambda p: p.count("/"), reverse=True):  # deepest first
        entry = path / rel
        if entry.is_dir() and not entry.is_symlink():
            entry.rmdir()  # emptied above: everything in it was listed
        else:
            entry.unlink()


__all__ = ["MANIFEST_FILE", "Manifest", "clear_listed", "read_manifest", "snapshot"]
