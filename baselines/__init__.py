"""Controllers, the evaluation loop, the leaderboard and the ``shipgym`` CLI on top of shipgym.

``from shipgym_baselines import register_controller`` enters a controller (see
:mod:`shipgym_baselines.registry`); it is imported on first use, so
``import shipgym_baselines.x`` stays light.
"""

from __future__ import annotations

from typing import Any

__all__ = ["register_controller"]


def __getattr__(name: str) -> Any:
    if name == "register_controller":
        from shipgym_baselines.registry import register_controller

        return register_controller
    raise AttributeError(f"module 'shipgym_baselines' has no attribute {name!r}")
