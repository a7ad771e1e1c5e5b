"""Lines for the person at the terminal: what a wait is for and how long it may take.

``SHIPGYM_QUIET=1`` in the environment silences them (scripts; the test suite sets it, and
the tests of the lines themselves unset it).
"""

from __future__ import annotations

import os
import sys

#: the environment variable that silences :func:`notice` (any value but "" and "0")
QUIET_ENV = "SHIPGYM_QUIET"


def quiet() -> bool:
    """Whether notices are silenced (:data:`QUIET_ENV`)."""
    return os.environ.get(QUIET_ENV, "") not in ("", "0")


def notice(line: str) -> None:
    """Write ``line`` on stderr, on a line of its own: on a terminal the line a progress
    bar is drawing is cleared first (the bar draws itself again below); nothing when
    :func:`quiet`."""
    if quiet():
        return
    clear = "\r\x1b[K" if sys.stderr.isatty() else ""
    sys.stderr.write(f"{clear}{line}\n")
    sys.stderr.flush()


def duration(seconds: float) -> str:
    """``seconds`` [s] for a person: "40 s", "9 min", "2.5 h"."""
    if seconds < 90:
        return f"{max(seconds, 1):.0f} s"
    if seconds < 90 * 60:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


__all__ = ["QUIET_ENV", "duration", "notice", "quiet"]
