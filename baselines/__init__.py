"""Controllers, the evaluation loop, the leaderboard and the ``shipgym`` CLI on top of shipgym.

``from baselines import register_controller`` enters a controller (see
:mod:`baselines.registry`); it is imported on first use, so ``import baselines.x`` stays
light.
"""

from __future__ import annotations

from typing import Any

__all__ = ["register_controller"]


def __getattr__(name: str) -> Any:
    if name == "register_controller":
        from baselines.registry import register_controller

        return register_controller
    raise AttributeError(f"module 'baselines' has no attribute {name!r}")
