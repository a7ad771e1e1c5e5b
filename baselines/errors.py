"""The errors ``baselines`` raises for bad input: :class:`shipgym.errors.ShipgymError`s.

The ``shipgym`` CLI prints them as one line (exit code 2); each also derives from the
built-in it refines, so ``except KeyError`` / ``except ValueError`` keep working.  A bad
suite or agent config raises shipgym's :class:`~shipgym.config.ConfigError` (re-exported
here), as a bad scenario file does.
"""

from __future__ import annotations

from shipgym.config import ConfigError
from shipgym.errors import ShipgymError


class ControllerError(ShipgymError, KeyError):
    """A controller name is neither a registered controller, a shipped learned policy nor a
    trained agent's directory; the message lists the valid names."""

    def __str__(self) -> str:  # the message as written, not KeyError's repr of it
        return Exception.__str__(self)


class RunError(ShipgymError, ValueError):
    """A run (leaderboard, reproduction, training, manoeuvre) cannot start as asked: an
    unknown ship, a bad seed count, backend or option combination, nothing to resume or
    export."""


class BackendError(ShipgymError, RuntimeError):
    """The requested execution backend is not installed (Ray)."""


def check_seeds(seeds: int, option: str = "seeds") -> None:
    """Raise :class:`RunError` unless the number of seeds is at least 1."""
    if seeds < 1:
        raise RunError(f"{option} must be ≥ 1, got {seeds}")


__all__ = ["BackendError", "ConfigError", "ControllerError", "RunError", "check_seeds"]
