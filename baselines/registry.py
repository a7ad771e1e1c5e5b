"""Controller names -> factories (the names used by suites, the CLI and the leaderboard)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from baselines.classical.l1_backstepping import AdaptiveBackstepping, L1Backstepping
from baselines.classical.lqr import LQR, AdaptiveLQR
from baselines.classical.nmpc import NMPC, NMPCLambdaLSSVM, NMPCWeightedLSSVM
from baselines.classical.pid import PIDLOS, PIDTVVF, PIDVF, PIDLookaheadLOS
from baselines.classical.reference import RandomRudder, ZeroRudder
from baselines.policy import Policy

#: name -> (factory, action mode the controller drives)
CONTROLLERS: dict[str, tuple[Callable[..., Policy], str]] = {
    "pid_los": (PIDLOS, "rudder"),
    "pid_lookahead_los": (PIDLookaheadLOS, "rudder"),
    "pid_vf": (PIDVF, "rudder"),
    "pid_tvvf": (PIDTVVF, "rudder"),
    "lqr": (LQR, "rudder"),
    "adaptive_lqr": (AdaptiveLQR, "rudder"),
    "l1_backstepping": (L1Backstepping, "rudder"),
    "adaptive_backstepping": (AdaptiveBackstepping, "rudder"),
    "nmpc": (NMPC, "rudder"),
    "nmpc_wlssvm": (NMPCWeightedLSSVM, "rudder"),
    "nmpc_lambda_lssvm": (NMPCLambdaLSSVM, "rudder"),
    "zero_rudder": (ZeroRudder, "rudder"),
    "random": (RandomRudder, "rudder"),
}


#: ships a classical controller applies to (absent: every ship).  The NMPC family is
#: built on the nomoto2 model structure it identifies online (Liu et al. 2019).
APPLIES_TO: dict[str, tuple[str, ...]] = {
    "nmpc": ("nomoto2",),
    "nmpc_wlssvm": ("nomoto2",),
    "nmpc_lambda_lssvm": ("nomoto2",),
}


def applies_to(controller: str, ship: str) -> bool:
    """Whether ``controller`` runs on ``ship`` (learned agents and the rest: every ship)."""
    ships = APPLIES_TO.get(controller)
    return ships is None or ship in ships


def controller_kind(controller: str) -> str:
    """``"classical"`` for a registered controller, else ``"learned"``."""
    if controller in CONTROLLERS:
        return getattr(CONTROLLERS[controller][0], "kind", "classical")
    return "learned"


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
