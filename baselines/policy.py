"""The one policy interface every controller and agent implements (docs/plugins.md), and how
the figures draw a controller: its family (the column, :data:`FAMILIES`) and its look
(:class:`Style`), traits of its record (the built-ins':
:data:`shipgym_baselines.controllers.BUILTINS`; a plug-in's:
:func:`shipgym_baselines.registry.register_controller`; the learned agents':
:data:`shipgym_baselines.learned.policy.AGENT_LOOKS`), read by
:func:`shipgym_baselines.plots.panels.controller_family` and
:func:`shipgym_baselines.plots.style.controller_style`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

from shipgym.envs.context import ControllerContext


@runtime_checkable
class Policy(Protocol):
    """A controller: ``reset`` once per episode with what it may know, ``act`` every step.

    ``act`` receives the observation and the env's ``info`` (measurements, samples); it
    never sees the true plant parameters or the event schedule.
    """

    name: str
    kind: str  # one of registry.KINDS: the ``kind`` column of the leaderboard's rows

    def reset(self, context: ControllerContext, seed: int | None = None) -> None: ...

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray: ...


def check_action_mode(policy: Any, context: ControllerContext) -> None:
    """Raise unless the env runs in the action mode ``policy`` drives.

    The mode is the policy's ``action_mode`` (set by its registration, or a learned
    agent's training run); a policy without one drives the rudder.
    """
    mode = getattr(policy, "action_mode", "rudder")
    if context.action_mode != mode:
        raise ValueError(
            f"{policy.name} drives action_mode {mode!r}, the env uses "
            f"{context.action_mode!r}: make the env with action_mode={mode!r}"
        )


#: controller families, the order of the figures' columns
FAMILIES = ("PID", "LQR", "NMPC", "backstepping", "learned", "other", "references")


@dataclass(frozen=True)
class Style:
    """Matplotlib keyword arguments of one controller: colour (``#rrggbb``), line style
    and marker."""

    color: str
    linestyle: str
    marker: str

    def kwargs(self) -> dict[str, str]:
        return {"color": self.color, "linestyle": self.linestyle}
