"""One run per output folder: an exclusive lock on ``--out`` while a run writes there.

``leaderboard``, ``evaluate`` and ``report`` hold :func:`out_lock` on their ``--out`` for
the whole run.  The lock is a POSIX record lock (``fcntl.lockf``) on the file
:data:`LOCK_FILE` in the folder, which holds the holder's process id, start time and
command.  A second run on the folder is refused at once, in one line naming the holder.

A stale lock cannot block anyone: the kernel releases a process's record locks when it
dies, however it dies (kill -9 included), and record locks are not inherited by forked
workers.  A lock file left by a killed run is therefore free; the next run takes it and
writes its own holder into it.  The file is not a run's output: the "not empty" check and
``--force`` ignore it, and a run that ends removes it.  It is opened without following a
link (:func:`shipgym_baselines.records.outfiles.open_regular`): a link, a folder or a hard link in
its place is refused in one line, and whatever it points to is left as it was (the "not
empty" check and ``--force`` see it, too).

A single file that a command fills over a long time (``shipgym references --table`` /
``--packaged``) or reads, changes and writes back (a study's chosen settings) is locked the
same way by :func:`file_lock`, on ``<file>.lock`` beside it.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import functools
import json
import os
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

from shipgym_baselines.errors import RunError
from shipgym_baselines.records.outfiles import open_regular

#: the lock file a run keeps in its ``--out`` while it runs
LOCK_FILE = ".shipgym.lock"

#: folders this process holds (a second lock of one folder in one process is refused too:
#: POSIX record locks do not exclude their own process)
_HELD: set[Path] = set()


def _holder(file: Path) -> str:
    """Who holds the lock, from the lock file (pid and start time)."""
    try:
        fd = open_regular(file, os.O_RDONLY)
        try:
            holder = json.loads(os.pread(fd, 4096, 0))
        finally:
            os.close(fd)
        return f"process {holder['pid']}, started {holder['start_time']}"
    except (OSError, RunError, ValueError, KeyError, TypeError):
        return "a process that has not yet written its name"


def in_use(folder: Path, holder: str) -> RunError:
    """The refusal of a folder another run holds (``holder``: who)."""
    return RunError(
        f"--out {folder} is in use by another run ({holder}): wait for it to end, or choose "
        "another --out"
    )


def _acquire(folder: Path, start_time: str) -> int:
    """The descriptor of the locked lock file of ``folder``; a :class:`RunError` naming
    the holder when another process holds it, or naming the lock file when it is a link
    or no regular file of its own (:func:`~shipgym_baselines.records.outfiles.open_regular`)."""
    return _acquire_file(folder / LOCK_FILE, start_time, lambda who: in_use(folder, who))


def _acquire_file(
    file: Path,
    start_time: str,
    busy: Callable[[str], RunError],
    wait: bool = False,
    elsewhere: str = "--out",
) -> int:
    """The descriptor of the lock file ``file``, locked, the holder written into it;
    ``busy(holder)``: the refusal raised when another process holds it (``wait``: wait
    for it to end instead); ``elsewhere``: the option a link's refusal names."""
    while True:
        fd = open_regular(file, os.O_RDWR | os.O_CREAT, elsewhere=elsewhere)
        try:
            fcntl.lockf(fd, fcntl.LOCK_EX if wait else fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            os.close(fd)
            if exc.errno in (errno.EACCES, errno.EAGAIN):
                raise busy(_holder(file)) from None
            raise
        try:  # the file may have been removed by its last holder meanwhile: lock the new one
            same = os.path.samestat(os.fstat(fd), os.stat(file))
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)
    holder = {"pid": os.getpid(), "start_time": start_time, "command": sys.argv}
    os.ftruncate(fd, 0)
    os.pwrite(fd, (json.dumps(holder) + "\n").encode(), 0)
    return fd


def lock_holder(folder: str | os.PathLike) -> str | None:
    """Who holds the lock of ``folder`` (process id, start time), or None when nobody else
    does (free, no lock file, or held by this process)."""
    path = Path(folder)
    file = path / LOCK_FILE
    if path.resolve() in _HELD or not file.is_file():
        return None
    try:
        fd = open_regular(file, os.O_RDONLY)
    except (OSError, RunError):  # not a lock: the run refuses it when it takes the lock
        return None
    try:  # a shared lock conflicts with the holder's exclusive one; closing releases ours
        fcntl.lockf(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except OSError as exc:
        if exc.errno in (errno.EACCES, errno.EAGAIN):
            return _holder(file)
        raise
    finally:
        os.close(fd)
    return None


def _release(key: Path, lock_file: Path, fd: int) -> None:
    """End a hold of this process: ``key`` off the held set, ``lock_file`` removed while
    still locked (the next holder finds a fresh file), then the lock released."""
    _HELD.discard(key)
    with contextlib.suppress(OSError):
        lock_file.unlink()
    os.close(fd)


@contextlib.contextmanager
def out_lock(out: str | os.PathLike, start_time: str) -> Iterator[Path]:
    """Hold the exclusive lock of the folder ``out`` (made if missing; removed again if
    the run leaves it empty) for the ``with`` body; ``start_time``: the holder's, as the
    refusal names it.  A :class:`RunError` if another run holds it."""
    folder = Path(out)
    key = folder.resolve()
    if key in _HELD:
        raise in_use(folder, f"process {os.getpid()}, this one")
    made = not folder.exists()
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise RunError(f"--out {folder}: cannot create it ({exc.strerror})") from None
    try:
        fd = _acquire(folder, start_time)
    except BaseException:
        if made:
            with contextlib.suppress(OSError):
                folder.rmdir()
        raise
    _HELD.add(key)
    try:
        yield folder
    finally:
        _release(key, folder / LOCK_FILE, fd)
        if made:
            with contextlib.suppress(OSError):
                folder.rmdir()  # only if empty: a run refused before writing leaves nothing


def lock_file_of(file: str | os.PathLike) -> Path:
    """The lock file of ``file`` (:func:`file_lock`): ``<file>.lock`` beside it."""
    path = Path(file)
    return path.with_name(f"{path.name}.lock")


@contextlib.contextmanager
def file_lock(
    file: str | os.PathLike, start_time: str, option: str, wait: bool = False
) -> Iterator[Path]:
    """Hold the exclusive lock of the single file ``file`` (:func:`lock_file_of`; its
    folder made if missing) for the ``with`` body: another process filling it is refused at
    once, in one line naming ``option`` (the command's option that named the file) and the
    holder; ``wait``: wait for the other process instead (a short read-modify-write).  A
    link or anything but a regular file in the lock file's place is refused in one line;
    the lock file is removed at the end, as :func:`out_lock` removes its own."""
    path = Path(file)
    key = Path(os.path.abspath(lock_file_of(path)))
    if key in _HELD:
        raise _file_in_use(path, option, f"process {os.getpid()}, this one")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise RunError(f"{option} {path}: cannot create its folder ({exc.strerror})") from None
    busy = functools.partial(_file_in_use, path, option)
    fd = _acquire_file(key, start_time, busy, wait, elsewhere=option)
    _HELD.add(key)
    try:
        yield path
    finally:
        _release(key, key, fd)


def _file_in_use(file: Path, option: str, holder: str) -> RunError:
    """The refusal of a file another process fills (``holder``: who)."""
    return RunError(
        f"{option} {file} is being written by another process ({holder}): wait for it to "
        "end, or choose another file"
    )


__all__ = ["LOCK_FILE", "file_lock", "in_use", "lock_file_of", "lock_holder", "out_lock"]
