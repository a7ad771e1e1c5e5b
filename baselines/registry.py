"""Controller names -> factories (the names used by suites, the CLI and the leaderboard)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from baselines.classical.nmpc import NMPC, NMPCLambdaLSSVM, NMPCWeightedLSSVM
from baselines.classical.pid import PIDLOS
from baselines.classical.reference import RandomRudder, ZeroRudder
from baselines.policy import Policy

#: name -> (factory, action mode the controller drives)
CONTROLLERS: dict[str, tuple[Callable[..., Policy], str]] = {
    "pid_los": (PIDLOS, "rudder"),
    "nmpc": (NMPC, "rudder"),
    "nmpc_wlssvm": (NMPCWeightedLSSVM, "rudder"),
    "nmpc_lambda_lssvm": (NMPCLambdaLSSVM, "rudder"),
    "zero_rudder": (ZeroRudder, "rudder"),
    "random": (RandomRudder, "rudder"),
}


def make_controller(name: str, **settings: Any) -> tuple[Policy, str]:
    """A fresh controller and the action mode it needs; unknown names list the valid ones.

    ``name`` is a classical controller, a shipped learned policy (``ppo``, …, in
    ``baselines/learned/policies``) or the directory of a trained agent.
    """
    if name in CONTROLLERS:
        factory, mode = CONTROLLERS[name]
        return factory(**settings), mode
    from baselines.learned.policy import POLICY_DIR, LearnedPolicy, shipped_policies

    if name in shipped_policies() or Path(name).exists():
        policy = LearnedPolicy(POLICY_DIR / name if name in shipped_policies() else name)
        return policy, policy.action_mode
    raise KeyError(
        f"unknown controller {name!r}; valid: {', '.join(sorted(CONTROLLERS))}, the learned "
        f"policies {', '.join(shipped_policies())} or a trained agent's directory"
    )
