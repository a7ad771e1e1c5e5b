"""The one privileged channel: the true plant, for the built-in ``oracle`` reference only.

The evaluation loop gives every controller the observation, ``info`` and the controller
context, nothing else.  The ``oracle`` reference (:mod:`shipgym_baselines.classical.oracle`) is the
one exception: when, and only when, a run names the registered ``oracle`` itself (not an
instance, a spec, a renamed long form or one with settings), the loop hands it the env's
:meth:`~shipgym.envs.path_follow.ShipPathFollowEnv.plant_truth` through
``reset_privileged``.  A plug-in cannot take the name (a registered name is never
re-registered) and nothing of the truth reaches ``info`` or the context.
"""

from __future__ import annotations

from typing import Any

from shipgym_baselines.errors import ControllerError
from shipgym_baselines.plugins import ControllerEntry, as_entry
from shipgym_baselines.registry import CONTROLLERS

ORACLE = "oracle"


def grants_truth(controller: Any) -> bool:
    """True only for the built-in oracle named as such (module doc)."""
    if not isinstance(controller, str | ControllerEntry):
        return False
    entry = as_entry(controller)
    if entry.controller != ORACLE or entry.settings or entry.name not in (None, ORACLE):
        return False
    from shipgym_baselines.classical.oracle import Oracle

    record = CONTROLLERS.get(ORACLE)
    return record is not None and record.factory is Oracle


def reset_with_truth(policy: Any, context: Any, env: Any, seed: int | None) -> None:
    """Start the oracle's episode with the env's truth (the caller checked the grant)."""
    from shipgym_baselines.classical.oracle import Oracle

    if type(policy) is not Oracle:
        raise ControllerError(f"only the built-in oracle reads the true plant, not {policy!r}")
    policy.reset_privileged(context, env.plant_truth, seed=seed)
