"""Files a command writes into its output folder, written so that no link is followed.

A run folder is the user's (``--out``), and anyone may have put a symbolic link into it: as
the lock, as ``leaderboard.md``, as a temporary.  Writing *through* such a link would
overwrite whatever it points to, outside the folder.  So every file a run writes goes
through this module:

* :func:`write_bytes` writes a new file under a unique temporary name, created
  exclusively without following links (``O_CREAT | O_EXCL | O_NOFOLLOW``), and renames it
  over the target (``os.replace`` replaces a directory entry, never what a link points
  to); a target that is a link (or a folder, a FIFO) is refused in one line naming it;
* :func:`open_regular` opens a file a run changes in place (the lock, ``episodes.jsonl``,
  ``manifest.txt``) without following a link, and refuses anything but a regular file
  with one name (a link, a FIFO, a hard link to a file elsewhere);
* :func:`make_dir` makes a sub-folder, refusing a link in its place;
* :func:`check_no_links` refuses a folder holding any link or special file, before a run
  writes there (``--resume``, ``--force``, the "not empty" check).

Every path :func:`write_bytes` and :func:`make_dir` write is first announced to the
recorders of this process (:func:`recording`; the run's manifest lists it before it
exists, :mod:`shipgym_baselines.records.manifest`); :func:`carried` takes them along into a pool
worker.  The folder ``--out`` itself may be a link (a results folder on another disk):
only what is inside it is checked.
"""

from __future__ import annotations

import contextlib
import errno
import functools
import os
import stat
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

from shipgym_baselines.errors import RunError

#: announces paths about to be written (absolute, lexical: links not resolved)
Recorder = Callable[[Sequence[Path]], None]

#: the recorders of this process, innermost last (:func:`recording`)
_RECORDERS: list[Recorder] = []

#: hex digits of a temporary's random part
_TOKEN_BYTES = 4


def _kind(mode: int) -> str:
    """What a file of ``mode`` is, as a refusal names it."""
    if stat.S_ISLNK(mode):
        return "a symbolic link"
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) else "not a regular file"


def refusal(path: str | os.PathLike, what: str, elsewhere: str = "--out") -> RunError:
    """The one-line refusal to write ``path``, which is ``what`` (a link names its target);
    ``elsewhere``: the option that names another place."""
    target = ""
    if what == "a symbolic link":
        with contextlib.suppress(OSError):
            target = f" to {os.readlink(path)}"
    return RunError(
        f"{os.fspath(path)} is {what}{target}: a run writes no file through it; remove it "
        f"or choose another {elsewhere}"
    )


def refuse_special(path: str | os.PathLike, elsewhere: str = "--out") -> None:
    """A :class:`RunError` if ``path`` exists and is not a regular file (a link, a folder,
    a FIFO, …); nothing if it is one or does not exist."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return
    if not stat.S_ISREG(mode):
        raise refusal(path, _kind(mode), elsewhere)


def check_no_links(folder: str | os.PathLike) -> None:
    """A :class:`RunError` naming the first link or special file (FIFO, socket, device)
    below ``folder`` (links not followed), if any; ``folder`` itself may be a link."""
    root = Path(folder)
    if not root.is_dir():
        return
    for top, dirs, files in os.walk(root):
        for name in sorted([*dirs, *files]):
            path = Path(top) / name
            mode = os.lstat(path).st_mode
            if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
                raise refusal(path, _kind(mode))


def open_regular(
    path: str | os.PathLike, flags: int, mode: int = 0o644, elsewhere: str = "--out"
) -> int:
    """A descriptor of ``path`` opened with ``flags`` (``O_CREAT`` to make it) and never
    through a link; a :class:`RunError` naming it when it is a link, not a regular file,
    or a file with other names (a hard link: writing would change that file too);
    ``elsewhere``: the option that names another place, as the refusal says it."""
    try:
        fd = os.open(path, flags | os.O_NOFOLLOW | os.O_NONBLOCK, mode)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise refusal(path, "a symbolic link", elsewhere) from None
        if exc.errno in (errno.EISDIR, errno.ENXIO):
            refuse_special(path, elsewhere)
        raise
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode) or info.st_nlink > 1:
        os.close(fd)
        what = _kind(info.st_mode) if not stat.S_ISREG(info.st_mode) else "a hard link"
        raise refusal(path, what, elsewhere)
    os.set_blocking(fd, True)
    return fd


def announce(*paths: Path) -> None:
    """Tell this process's recorders that ``paths`` are about to be written (by a writer
    other than :func:`write_bytes` and :func:`make_dir`, which announce their own)."""
    absolute = [Path(os.path.abspath(p)) for p in paths]
    for record in list(_RECORDERS):
        record(absolute)


@contextlib.contextmanager
def recording(recorder: Recorder) -> Iterator[None]:
    """Announce every path :func:`write_bytes` and :func:`make_dir` write in this process
    to ``recorder`` during the ``with`` body."""
    _RECORDERS.append(recorder)
    try:
        yield
    finally:
        _RECORDERS.remove(recorder)


def _with_recorders(
    recorders: tuple[Recorder, ...], fn: Callable[..., Any], *args: Any, **kwargs: Any
) -> Any:
    """``fn(*args, **kwargs)`` with exactly ``recorders`` (a forked worker's inherited
    ones set aside meanwhile)."""
    inherited = _RECORDERS[:]
    _RECORDERS[:] = recorders
    try:
        return fn(*args, **kwargs)
    finally:
        _RECORDERS[:] = inherited


def carried(fn: Callable[..., Any]) -> Callable[..., Any]:
    """``fn`` with this process's recorders (picklable when they are): a task that a pool
    worker runs (forked or spawned) announces what it writes as the submitting process
    would."""
    return functools.partial(_with_recorders, tuple(_RECORDERS), fn)


def temporary_name(file: Path) -> Path:
    """A new temporary beside ``file``: ``.<name>.<random>.tmp``."""
    return file.with_name(f".{file.name}.{os.urandom(_TOKEN_BYTES).hex()}.tmp")


def make_dir(folder: str | os.PathLike) -> Path:
    """``folder`` made if missing (announced first, its parent must exist); a
    :class:`RunError` when a link or a file is in its place."""
    path = Path(folder)
    announce(path)
    with contextlib.suppress(FileExistsError):
        path.mkdir()
    mode = os.lstat(path).st_mode
    if not stat.S_ISDIR(mode):
        raise refusal(path, _kind(mode))
    return path


def write_bytes(file: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` as ``file``, atomically and through no link: into a new temporary
    (:func:`temporary_name`, created exclusively, links not followed), renamed over
    ``file``.  Both are announced first (:func:`recording`).  A ``file`` that is a link
    or no regular file is a :class:`RunError` naming it; a full disk leaves neither a
    half-written ``file`` nor the temporary, and its error names ``file``."""
    path = Path(file)
    refuse_special(path)
    tmp = temporary_name(path)
    announce(path, tmp)
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o644)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.replace(tmp, path)
    except BaseException as exc:  # no half-written temporary left behind (a full disk)
        with contextlib.suppress(OSError):
            tmp.unlink()
        if isinstance(exc, OSError) and exc.filename in (None, str(tmp)):
            exc.filename = str(path)  # the one-line message names it
        raise


def write_text(file: str | os.PathLike, text: str) -> None:
    """:func:`write_bytes` of ``text`` as UTF-8."""
    write_bytes(file, text.encode("utf-8"))


__all__ = [
    "announce",
    "carried",
    "check_no_links",
    "make_dir",
    "open_regular",
    "recording",
    "refusal",
    "refuse_special",
    "temporary_name",
    "write_bytes",
    "write_text",
]
