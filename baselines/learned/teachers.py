"""Teachers of DAgger (:mod:`shipgym_baselines.learned.dagger`): what labels a student's states.

:class:`OracleTeacher` is the causal ``oracle`` (:mod:`shipgym_baselines.classical.oracle`,
NMPC on the true plant now) as a :class:`~shipgym_baselines.learned.dagger.Teacher`.  It
reads the true plant at training time only, through
:func:`shipgym_baselines.privileged.teacher_truth`; the student it teaches sees the
observation alone, and nothing evaluated ever makes a teacher.

Per rollout, the teacher follows the env's episode:

========================  ===================================================================
call                      what the oracle does
========================  ===================================================================
``reset(env, seed)``      ``reset_privileged`` with the context of the env's current scenario
                          (:attr:`~shipgym.envs.path_follow.ShipPathFollowEnv.controller_context`,
                          as the evaluation loop builds it) and that env's truth
``label(obs, info, env)`` ``act``: one solve on the true plant now; the normalised command
``observe_applied(a)``    the command the env applied, δc = a·δmax [rad], becomes the oracle's
                          previous command (its ``command``: the rudder-rate term and the
                          tail's speed); when the applied action is the oracle's own label,
                          its own command stands, so a rollout of the teacher alone is the
                          oracle's own episode, bit for bit (tested)
========================  ===================================================================

The oracle's warm start (its ``plan``, shifted one period) is its own last plan either way:
a starting guess of the multistart solve, not a state of the plant.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from shipgym_baselines.classical.oracle import Oracle, OracleSettings
from shipgym_baselines.errors import RunError
from shipgym_baselines.privileged import teacher_truth


class OracleTeacher:
    """The causal oracle labelling a rudder-mode env's states (module doc)."""

    def __init__(self, settings: OracleSettings | None = None) -> None:
        self.oracle = Oracle(settings)
        self._label: np.ndarray | None = None
        self._rudder_limit = 0.0  # rad, the current scenario's δmax

    def reset(self, env: Any, seed: int) -> None:
        """Start the episode the env was just reset to (``seed``: its env seed)."""
        base = env.unwrapped
        if getattr(base, "action_mode", None) != "rudder":
            raise RunError(
                f"the oracle teacher labels rudder commands: the env's action_mode is "
                f"{getattr(base, 'action_mode', None)!r}, not 'rudder'"
            )
        context = base.controller_context
        self._rudder_limit = float(context.rudder_limit)
        self.oracle.reset_privileged(context, teacher_truth(env), seed=seed)
        self._label = None

    def label(self, obs: np.ndarray, info: dict[str, Any], env: Any) -> np.ndarray:
        """The oracle's normalised rudder command for the state the env is in, shape (1,)."""
        action = np.asarray(self.oracle.act(obs, info), dtype=np.float32)
        self._label = action.copy()
        return action

    def observe_applied(self, action: np.ndarray) -> None:
        """The env was stepped with ``action`` (normalised): the oracle's previous command."""
        applied = np.asarray(action, dtype=np.float32).reshape(-1)
        if self._label is not None and np.array_equal(applied, self._label):
            return  # its own command, as the oracle alone carries it
        self.oracle.command = float(np.clip(applied[0], -1.0, 1.0)) * self._rudder_limit

    def solve_cpu_s(self) -> float:
        """The CPU seconds of the oracle's solves in this episode so far."""
        return float(sum(self.oracle.solve_cpu_times))


def oracle_teacher() -> OracleTeacher:
    """An :class:`OracleTeacher` with the oracle's own settings (a picklable factory)."""
    return OracleTeacher()
