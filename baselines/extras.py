"""The optional dependencies (``pyproject.toml`` extras) that some commands need.

:func:`require` turns a missing one into one line that names the ``pip install`` to run,
instead of a ``ModuleNotFoundError`` traceback from deep inside the command.
"""

from __future__ import annotations

import importlib.util

from shipgym_baselines.errors import BackendError

#: extra → what it installs, as pyproject.toml declares it
EXTRAS: dict[str, str] = {
    "rl": "stable-baselines3, sb3-contrib and torch",
    "tune": "optuna",
    "ray": "Ray",
    "video": "imageio-ffmpeg and moviepy",
}


class MissingExtra(BackendError):
    """A command needs an optional dependency that is not installed."""


def install_hint(extra: str) -> str:
    """The command that installs ``extra`` (in a checkout, and from an index)."""
    return f'pip install -e ".[{extra}]" (a checkout) or pip install "shipgym[{extra}]"'


def require(module: str, extra: str, command: str) -> None:
    """Raise :class:`MissingExtra` naming the install when ``module`` cannot be imported."""
    if extra not in EXTRAS:
        raise ValueError(f"unknown extra {extra!r}; known: {', '.join(EXTRAS)}")
    if importlib.util.find_spec(module) is None:
        raise MissingExtra(
            f"{command} needs {EXTRAS[extra]} ({module} is not installed): {install_hint(extra)}"
        )


__all__ = ["EXTRAS", "MissingExtra", "install_hint", "require"]
