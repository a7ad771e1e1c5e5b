"""The built-in controllers: each one's name, entry point and traits (data only).

An entry point is a string ``"package.module:Attr"``, imported only when the controller is
made (:func:`shipgym_baselines.registry.make_controller`).  So the registry answers what a
controller is (its kind, family, look, ships, action mode, training seeds, whether it reads
the true plant) without importing it, and this module imports no controller.  The order
of :data:`BUILTINS` is the registry's (``CONTROLLERS`` and the docs' index list it).
"""

from __future__ import annotations

from dataclasses import dataclass

from shipgym_baselines.policy import Style


@dataclass(frozen=True)
class Builtin:
    """One built-in controller.

    ``entry_point``: ``"module:Attr"`` of its Policy class; ``kind``: ``"classical"``,
    ``"learned"`` or ``"reference"`` (shown on every scenario, never ranked); ``family``
    and ``look``: how the figures draw it; ``action_mode``: the env mode it drives;
    ``applies_to``: the ship ids it runs on (None: every ship); ``privileged``: a
    reference that reads the env's true plant (:mod:`shipgym_baselines.privileged`);
    ``seeds``: ``"module:function"`` listing a learned controller's training seeds (None:
    not trained).
    """

    name: str
    entry_point: str
    family: str
    look: Style
    kind: str = "classical"
    action_mode: str = "rudder"
    applies_to: tuple[str, ...] | None = None
    privileged: bool = False
    seeds: str | None = None


_CLASSICAL = "shipgym_baselines.classical"

#: every built-in controller, in the registry's order
BUILTINS: tuple[Builtin, ...] = (
    Builtin("pid_los", f"{_CLASSICAL}.pid:PIDLOS", "PID", Style("#1f77b4", "-", "o")),
    Builtin(
        "pid_lookahead_los",
        f"{_CLASSICAL}.pid:PIDLookaheadLOS",
        "PID",
        Style("#6baed6", "--", "o"),
    ),
    Builtin("pid_vf", f"{_CLASSICAL}.pid:PIDVF", "PID", Style("#08519c", "-.", "o")),
    Builtin("pid_tvvf", f"{_CLASSICAL}.pid:PIDTVVF", "PID", Style("#9ecae1", ":", "o")),
    Builtin("lqr", f"{_CLASSICAL}.lqr:LQR", "LQR", Style("#31a354", "-", "s")),
    Builtin("adaptive_lqr", f"{_CLASSICAL}.lqr:AdaptiveLQR", "LQR", Style("#74c476", "--", "s")),
    Builtin(
        "l1_backstepping",
        f"{_CLASSICAL}.l1_backstepping:L1Backstepping",
        "backstepping",
        Style("#756bb1", "-", "D"),
    ),
    Builtin(
        "adaptive_backstepping",
        f"{_CLASSICAL}.l1_backstepping:AdaptiveBackstepping",
        "backstepping",
        Style("#bcbddc", "--", "D"),
    ),
    Builtin("nmpc", f"{_CLASSICAL}.nmpc:NMPC", "NMPC", Style("#fd8d3c", "-", "^")),
    Builtin(
        "nmpc_wlssvm", f"{_CLASSICAL}.nmpc:NMPCWeightedLSSVM", "NMPC", Style("#e6550d", "--", "^")
    ),
    Builtin(
        "nmpc_lambda_lssvm",
        f"{_CLASSICAL}.nmpc:NMPCLambdaLSSVM",
        "NMPC",
        Style("#a63603", "-.", "^"),
    ),
    Builtin(
        "nmpc_wlssvm_svf",
        f"{_CLASSICAL}.nmpc:NMPCWeightedLSSVMSVF",
        "NMPC",
        Style("#fdae6b", ":", "^"),
    ),
    Builtin(
        "nmpc_lambda_lssvm_svf",
        f"{_CLASSICAL}.nmpc:NMPCLambdaLSSVMSVF",
        "NMPC",
        Style("#7f2704", ":", "v"),
    ),
    Builtin(
        "zero_rudder",
        f"{_CLASSICAL}.reference:ZeroRudder",
        "references",
        Style("#7f7f7f", ":", "."),
        kind="reference",
    ),
    Builtin(
        "random",
        f"{_CLASSICAL}.reference:RandomRudder",
        "references",
        Style("#c7c7c7", ":", "."),
        kind="reference",
    ),
    Builtin(
        "oracle",
        f"{_CLASSICAL}.oracle:Oracle",
        "references",
        Style("#17becf", "-", "s"),
        kind="reference",
        privileged=True,
    ),
    Builtin(
        "oracle_frozen",
        f"{_CLASSICAL}.oracle:OracleFrozen",
        "references",
        Style("#525252", "-.", "x"),
        kind="reference",
        privileged=True,
    ),
    Builtin("nmpc_ekf", f"{_CLASSICAL}.nmpc_ekf:NmpcEkf", "NMPC", Style("#e31a1c", "-", "v")),
    Builtin(
        "nmpc_learned_id",
        "shipgym_baselines.learned.plant_id.controller:NmpcLearnedId",
        "learned",
        Style("#9467bd", "-", "P"),
        kind="learned",
        seeds="shipgym_baselines.learned.plant_id.shipped:shipped_seeds",
    ),
)
