"""What a run wrote into its folder: the manifest that ``--force`` deletes by.

Every ``leaderboard`` / ``evaluate`` / ``report`` / ``run`` lists each path it writes in
:data:`MANIFEST_FILE` (one folder-relative path a line, appended *before* the file is
written, so a run killed while writing a file still lists it).  A run lists what it
writes itself, never what it finds: each file goes through
:func:`shipgym_baselines.records.outfiles.write_bytes`, which announces it (and its temporary) to
the manifest that is :meth:`Manifest.recording` (in a pool worker too:
:func:`~shipgym_baselines.records.outfiles.carried`), so a user's file that appears meanwhile is
not the run's.  ``--force`` deletes exactly the listed paths and refuses, before deleting
anything, a folder that holds anything else: a user's file, a directory of their own, a
link (never written by a run, whatever its name), a file of an earlier shipgym version
that kept no manifest.  The lock file (:mod:`shipgym_baselines.records.locking`) is never listed
and never deleted; only a regular file of that name is the lock.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path

from shipgym_baselines.errors import RunError
from shipgym_baselines.records.locking import LOCK_FILE
from shipgym_baselines.records.outfiles import announce, open_regular, recording, write_text

#: the list of paths the runs in a folder wrote
MANIFEST_FILE = "manifest.txt"


def snapshot(folder: str | os.PathLike) -> set[str]:
    """Every path below ``folder`` (files, links and directories, relative, ``/``-separated;
    symbolic links are not followed), the lock file aside (a regular file of that name:
    a link in its place is listed)."""
    root = Path(folder)
    found: set[str] = set()
    for top, dirs, files in os.walk(root):
        for name in [*dirs, *files]:
            path = Path(top) / name
            rel = path.relative_to(root).as_posix()
            if rel != LOCK_FILE or path.is_symlink() or not path.is_file():
                found.add(rel)
    return found


def _links(folder: Path, paths: Iterable[str]) -> set[str]:
    """Those of ``paths`` (relative to ``folder``) that are symbolic links."""
    return {p for p in paths if (folder / p).is_symlink()}


def read_manifest(folder: str | os.PathLike) -> set[str]:
    """The paths ``folder``'s manifest lists (empty without one); the manifest itself
    included once it exists."""
    file = Path(folder) / MANIFEST_FILE
    if file.is_symlink() or not file.is_file():  # a link is nobody's manifest
        return set()
    listed = {line for line in file.read_text(errors="replace").splitlines() if line}
    return listed | {MANIFEST_FILE}


class Manifest:
    """The manifest of an open run folder: :meth:`claim` a path before writing it, or
    write inside :meth:`recording` (each file written through
    :mod:`shipgym_baselines.records.outfiles` is claimed as it is written)."""

    def __init__(self, folder: str | os.PathLike):
        self.folder = Path(folder)
        self.listed = read_manifest(self.folder)

    def claim(self, *paths: str) -> None:
        """List ``paths`` (relative to the folder) unless listed; on disk at once, in one
        appending write (pool workers claim into the same file)."""
        new = [p for p in dict.fromkeys(paths) if p not in self.listed]
        if not new:
            return
        if MANIFEST_FILE not in self.listed:  # a manifest inside another run's folder is
            self.listed.add(MANIFEST_FILE)  # listed there (its own recorder claims nothing)
            announce(self.folder / MANIFEST_FILE)
        data = "".join(f"{p}\n" for p in new).encode("utf-8")
        fd = open_regular(self.folder / MANIFEST_FILE, os.O_WRONLY | os.O_APPEND | os.O_CREAT)
        try:
            done = 0
            while done < len(data):
                done += os.write(fd, data[done:])
        finally:
            os.close(fd)
        self.listed |= {*new, MANIFEST_FILE}

    def record(self, paths: Sequence[Path]) -> None:
        """Claim those of ``paths`` (absolute) that lie inside the folder: the recorder of
        :meth:`recording`."""
        root = Path(os.path.abspath(self.folder))
        inside = [p.relative_to(root).as_posix() for p in paths if p.is_relative_to(root)]
        self.claim(*[p for p in inside if p != "."])

    @contextlib.contextmanager
    def recording(self) -> Iterator[None]:
        """Claim every file and folder written in this folder through
        :mod:`shipgym_baselines.records.outfiles` during the ``with`` body, before it is written
        (files that appear otherwise, a user's, are not claimed)."""
        with recording(self.record):
            yield

    def compact(self, keep: Iterable[str] = ()) -> None:
        """Rewrite the manifest, when a run finishes, to list only the listed paths that
        exist and ``keep`` (what a later run in the folder may write again, e.g. the run
        record): a run that wrote and removed thousands of trajectory
        files and their temporaries lists only those it kept.  Never lists
        anything unlisted, so ``--force`` still deletes only what runs wrote.  Atomic
        (a listed temporary renamed over the manifest); on a full disk left as it was."""
        self.listed |= read_manifest(self.folder)  # pool workers' claims too
        kept = sorted(((self.listed & snapshot(self.folder)) | set(keep)) - {MANIFEST_FILE})
        with recording(self.record):  # its temporary is listed while it exists
            try:
                write_text(self.folder / MANIFEST_FILE, "".join(f"{p}\n" for p in kept))
            except OSError:
                return
        self.listed = {*kept, MANIFEST_FILE}


def check_listed(folder: str | os.PathLike, option: str = "--force") -> set[str]:
    """The paths below ``folder`` (:func:`snapshot`), all listed in its manifest; a
    :class:`RunError` naming those that are not (or are links) otherwise."""
    path = Path(folder)
    if not path.is_dir():
        return set()
    listed = read_manifest(path)
    present = snapshot(path)
    foreign = sorted((present - listed) | _links(path, present))  # a run writes no link
    if foreign:
        more = f", … ({len(foreign)} in all)" if len(foreign) > 5 else ""
        shown = ", ".join(foreign[:5]) + more
        why = "" if listed else f" (no {MANIFEST_FILE}: no run of this version wrote it)"
        raise RunError(
            f"{option}: {path} holds files no run wrote{why}: {shown}; move them away or "
            "choose another folder"
        )
    return present


def clear_listed(folder: str | os.PathLike, option: str = "--force") -> None:
    """Delete what the manifest of ``folder`` lists; a :class:`RunError`, before deleting
    anything, when the folder holds anything the manifest does not list
    (:func:`check_listed`)."""
    path = Path(folder)
    present = check_listed(path, option)
    for rel in sorted(present, key=lambda p: p.count("/"), reverse=True):  # deepest first
        entry = path / rel
        if entry.is_dir() and not entry.is_symlink():
            entry.rmdir()  # emptied above: everything in it was listed
        else:
            entry.unlink()


__all__ = [
    "MANIFEST_FILE",
    "Manifest",
    "check_listed",
    "clear_listed",
    "read_manifest",
    "snapshot",
]
