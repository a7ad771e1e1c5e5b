"""Signals: SIGTERM ends a run as Ctrl-C does, and pool workers never outlive their parent.

* :func:`terminate_as_interrupt`: while it is in force, SIGTERM (what ``timeout``, CI
  cancels and service managers send) raises :class:`Terminated`, a ``KeyboardInterrupt``,
  so a run ends as after Ctrl-C (its record "interrupted", one line); the CLI exits with
  128 + the signal's number (143).
* :func:`worker_init`: the initializer of every process-pool worker.  A worker ignores
  SIGINT and SIGTERM sent to the whole process group (the parent decides, and stops its
  workers with SIGKILL), and exits as soon as its parent is gone, however the parent died:
  the kernel sends it SIGKILL (Linux ``PR_SET_PDEATHSIG``) and, elsewhere or as a second
  guard, a watchdog thread sees the parent change.
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator
from types import FrameType

#: how often a worker's watchdog looks for its parent [s]
WATCHDOG_PERIOD_S = 0.5
#: ``prctl`` option: the signal a process gets when its parent dies (Linux)
_PR_SET_PDEATHSIG = 1


class Terminated(KeyboardInterrupt):
    """A termination signal (SIGTERM) received; ``signum`` is its number."""

    def __init__(self, signum: int = signal.SIGTERM):
        super().__init__(signal.Signals(signum).name)
        self.signum = int(signum)


def signal_number(exc: BaseException) -> int:
    """The signal an interrupt came from: a :class:`Terminated`'s, else SIGINT (Ctrl-C)."""
    return int(getattr(exc, "signum", signal.SIGINT))


def _raise_terminated(signum: int, frame: FrameType | None) -> None:
    raise Terminated(signum)


@contextlib.contextmanager
def terminate_as_interrupt() -> Iterator[None]:
    """SIGTERM raises :class:`Terminated` in the main thread for the ``with`` body (no
    change outside the main thread, where handlers cannot be set)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def _die_with_parent() -> None:
    """Ask the kernel for SIGKILL when the parent dies (Linux; elsewhere nothing)."""
    if not sys.platform.startswith("linux"):
        return
    with contextlib.suppress(OSError, AttributeError):
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(WATCHDOG_PERIOD_S)
    os._exit(1)  # the parent is gone: nobody waits for this worker's results


def worker_init() -> None:
    """A pool worker's initializer (module doc): group SIGINT / SIGTERM ignored, gone with
    its parent."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    import multiprocessing

    known = multiprocessing.parent_process()
    parent = known.pid if known is not None and known.pid else os.getppid()
    _die_with_parent()
    if os.getppid() != parent:  # the parent died before the request took effect
        os._exit(1)
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True).start()


__all__ = ["Terminated", "signal_number", "terminate_as_interrupt", "worker_init"]
