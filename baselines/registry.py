"""Controller names -> factories (the names used by suites, the CLI and the leaderboard)."""

from __future__ import annotations

from collections.abc import Callable
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
    """A fresh controller and the action mode it needs; unknown names list the valid ones."""
    if name not in CONTROLLERS:
        raise KeyError(f"unknown controller {name!r}; valid: {', '.join(sorted(CONTROLLERS))}")
    factory, mode = CONTROLLERS[name]
    return factory(**settings), mode
