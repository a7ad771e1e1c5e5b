"""The one privileged channel: the true plant, for the built-in references only.

The evaluation loop gives every controller the observation, ``info`` and the controller
context, nothing else.  The references ``oracle`` and ``oracle_frozen``
(:mod:`shipgym_baselines.classical.oracle`, marked ``privileged`` in the table of built-ins
:data:`shipgym_baselines.controllers.BUILTINS`) are the one exception: when, and only when,
a run names one of them itself (not an instance, a spec, a renamed long form or one with
settings: its record stays ``privileged``,
:func:`~shipgym_baselines.registry.resolve_controller`), the loop hands it the env's
:meth:`~shipgym.envs.path_follow.ShipPathFollowEnv.plant_truth` through
``reset_privileged``.  A plug-in cannot take the names (a registered name is never
re-registered), nor declare itself privileged, and nothing of the truth reaches ``info``
or the context.

At training time a teacher may read it too (:func:`teacher_truth`): the DAgger teacher
(:class:`shipgym_baselines.learned.teachers.OracleTeacher`) labels the states a student
learns from with the oracle's action.  The student never receives it, and the evaluation
loop never calls :func:`teacher_truth` (tested).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from shipgym_baselines.controllers import BUILTINS
from shipgym_baselines.errors import ControllerError
from shipgym_baselines.plugins import ControllerEntry, as_entry
from shipgym_baselines.registry import ControllerRecord, resolve_controller

#: the reference of the leaderboard's cost ratio (its cost is the denominator)
ORACLE = "oracle"
#: the second reference: the same NMPC with its truth frozen at the episode's start (the
#: optimum that never adapts); C_frozen / C_oracle is what knowing the change is worth
ORACLE_FROZEN = "oracle_frozen"
#: the names that receive the truth
PRIVILEGED_NAMES = tuple(builtin.name for builtin in BUILTINS if builtin.privileged)


def grants_truth(controller: Any) -> bool:
    """True only for a built-in reference named as such (module doc): a record that is
    ``privileged``, or a name or long form that resolves to one."""
    if isinstance(controller, ControllerRecord):
        # only the registry's own record of a reference: a record built by hand that says
        # ``privileged`` (under another name, with settings, another entry point) is not
        return (
            controller.privileged
            and controller.name in PRIVILEGED_NAMES
            and controller == resolve_controller(controller.name)
        )
    if not isinstance(controller, str | ControllerEntry):
        return False
    entry = as_entry(controller)
    name = entry.controller
    if name not in PRIVILEGED_NAMES or entry.settings or entry.name not in (None, name):
        return False  # nothing else is privileged: no need to resolve it
    return resolve_controller(controller).privileged


def reset_with_truth(policy: Any, context: Any, env: Any, seed: int | None) -> None:
    """Start a reference's episode with the env's truth (the caller checked the grant)."""
    from shipgym_baselines.classical.oracle import PRIVILEGED

    if type(policy) not in PRIVILEGED.values():
        raise ControllerError(f"only the built-in references read the true plant, not {policy!r}")
    policy.reset_privileged(context, env.plant_truth, seed=seed)


def teacher_truth(env: Any) -> Callable[[], Any]:
    """Training time only: the truth of ``env`` in the episode it is in, the
    :meth:`~shipgym.envs.path_follow.ShipPathFollowEnv.plant_truth` callable (returns the
    :class:`~shipgym.envs.truth.PlantTruth` now), for a teacher that labels a student's
    training data.  ``env``: a ShipPathFollow env or the randomised training env (either
    possibly wrapped), after its ``reset``: the randomised env's truth is its current
    scenario's, so a teacher asks again after every reset.  Nothing evaluated calls it."""
    base = getattr(env, "unwrapped", env)
    try:
        truth = base.plant_truth
    except AttributeError:
        truth = None
    if not callable(truth):
        raise ControllerError(
            f"{type(base).__name__} has no plant truth: a teacher labels on a ShipPathFollow "
            "env (or the randomised training env)"
        )
    return truth
