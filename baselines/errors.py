"""The errors ``baselines`` raises for bad input: :class:`shipgym.errors.ShipgymError`s.

The ``shipgym`` CLI prints them as one line (exit code 2); each also derives from the
built-in it refines, so ``except KeyError`` / ``except ValueError`` keep working.  A bad
suite or agent config raises shipgym's :class:`~shipgym.config.ConfigError`, as a bad
scenario file does.
"""

from __future__ import annotations

from shipgym.errors import ShipgymError
from shipgym.limits import MAX_SEEDS


class ControllerError(ShipgymError, KeyError):
    """A controller cannot be made as named: an unknown name (the message lists the valid
    ones), a spec whose module, file or attribute is missing or not a Policy, a broken
    plug-in entry point, a model zip or ``meta.json`` that is unreadable or contradicts
    itself (the message names the file and key)."""

    def __str__(self) -> str:  # the message as written, not KeyError's repr of it
        return Exception.__str__(self)


class UnsafeFileError(ControllerError):
    """A file that only unpickling can read (an SB3 zip's pickled parts a scoring run needs,
    a ``vecnormalize.pkl``): unpickling runs any code the file holds, so it is refused
    unless the user passes ``--trust-pickle`` (:mod:`shipgym_baselines.learned.trust`)."""


class RunError(ShipgymError, ValueError):
    """A run (leaderboard, reproduction, training, manoeuvre) cannot start as asked: an
    unknown ship, a bad seed count, backend or option combination, nothing to resume or
    export."""


class RunFailed(ShipgymError, RuntimeError):
    """A run stopped by something outside it, not by bad input: a worker process killed,
    the disk full.  The message says what happened and what was kept; the CLI prints it
    as one line (exit code 1)."""


class BackendError(ShipgymError, RuntimeError):
    """The requested execution backend is not installed (Ray)."""


def check_count(count: int, option: str) -> None:
    """Raise :class:`RunError` unless a count (``--seeds``, ``--repeats``, ``--timesteps``)
    is at least 1; the message names the option."""
    if count < 1:
        raise RunError(f"{option} must be ≥ 1, got {count}")


def check_seeds(seeds: int, option: str = "seeds") -> None:
    """Raise :class:`RunError` unless the number of seeds is at least 1 and at most
    :data:`shipgym.limits.MAX_SEEDS`."""
    check_count(seeds, option)
    if seeds > MAX_SEEDS:
        raise RunError(f"{option} is {seeds}, beyond the limit of {MAX_SEEDS} seeds per scenario")


__all__ = [
    "BackendError",
    "ControllerError",
    "RunError",
    "RunFailed",
    "UnsafeFileError",
    "check_count",
    "check_seeds",
]
