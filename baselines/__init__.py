"""Controllers, the evaluation loop, the leaderboard and the ``shipgym`` CLI on top of shipgym.

``from shipgym_baselines import register_controller`` enters a controller (see
:mod:`shipgym_baselines.registry`).
"""

from __future__ import annotations

from typing import Any

__all__ = ["register_controller"]


def register_controller(*args: Any, **kwargs: Any) -> Any:
    """:func:`shipgym_baselines.registry.register_controller`, with the same arguments (the
    registry is imported on the first call, so ``import shipgym_baselines.x`` stays light)."""
    from shipgym_baselines.registry import register_controller as register

    return register(*args, **kwargs)
