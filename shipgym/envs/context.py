"""What a controller may know: the nominal model and the task, never the truth."""

from __future__ import annotations

import dataclasses

import numpy as np

from shipgym.models.base import ParameterRecord, ShipModel
from shipgym.paths import PchipPath, WaypointPath
from shipgym.scenarios.schema import GuidanceConfig
from shipgym.tracking import PathTracker


@dataclasses.dataclass(frozen=True)
class ControllerContext:
    """Handed to every policy at reset.

    ``nominal_model`` carries the pre-change (nominal) parameters the scenario declares;
    the true parameters and the event schedule are not in here, by design.
    """

    ship: str
    nominal_model: ShipModel
    waypoints: np.ndarray  # (M, 2) [m]
    path_type: str  # "waypoints" | "pchip"
    ship_length: float  # L [m]
    nominal_speed: float  # [m/s]
    rudder_limit: float  # δmax [rad]
    control_period: float  # Ts [s]
    fine_step: float  # h [s]
    acceptance_radius: float  # R0 [m]
    switching: str  # waypoint switching rule: "circle" | "along_track"
    los_radius_L: float  # n in R_LOS = nL
    action_mode: str  # "rudder" | "guidance"
    #: the scenario's guidance settings (law, R_LOS, look-ahead, VF/TVVF parameters)
    guidance: GuidanceConfig = dataclasses.field(default_factory=GuidanceConfig)

    @property
    def nominal_params(self) -> ParameterRecord:
        return self.nominal_model.params

    def new_tracker(self) -> PathTracker:
        """A path tracker with the env's path and switching rule (for measured positions)."""
        path = (
            PchipPath(self.waypoints) if self.path_type == "pchip" else WaypointPath(self.waypoints)
        )
        return PathTracker(path, self.acceptance_radius, self.switching)
