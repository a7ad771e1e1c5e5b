"""Xu & Guedes Soares (2020) §5–§6: the two guidance laws with a Vyshnegradsky PID, logging
ψd, and the two gain designs."""

from __future__ import annotations

from shipgym.autopilot import VYSHNEGRADSKY_AB_PRINTED, VYSHNEGRADSKY_AB_STATED
from shipgym.envs.context import ControllerContext
from shipgym_baselines.classical.pid import PIDVF, PIDLookaheadLOS

#: gain design -> (A, B) of the Vyshnegradsky diagram (§5.1 states 4, 4; 3, 3 gives the
#: printed gains, :mod:`shipgym.autopilot`)
GAINS = {"A=B=4": VYSHNEGRADSKY_AB_STATED, "A=B=3": VYSHNEGRADSKY_AB_PRINTED}


class _RecordsDesiredHeading:
    """Mixin: logs ψd [rad] at every ``act`` (for the autopilot heading error ψd − ψ)."""

    desired_log: list[float]

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        super().reset(context, seed)  # type: ignore[misc]
        self.desired_log = []

    def desired_heading(self, cross_track: float, path_angle: float) -> float:
        psi_d = super().desired_heading(cross_track, path_angle)  # type: ignore[misc]
        self.desired_log.append(float(psi_d))
        return psi_d


class _LookaheadLOS(_RecordsDesiredHeading, PIDLookaheadLOS):
    default_preset = "paper"  # the paper's design, never the tuned settings


class _VF(_RecordsDesiredHeading, PIDVF):
    default_preset = "paper"


CONTROLLERS = (_LookaheadLOS, _VF)  # names: pid_lookahead_los, pid_vf
