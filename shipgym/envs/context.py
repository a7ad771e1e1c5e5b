"""What a controller may know: the nominal model and the task, never the truth."""

from __future__ import annotations

import dataclasses

import numpy as np

from shipgym.models.base import ParameterRecord, ShipModel


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
    los_radius_L: float  # n in R_LOS = nL
    action_mode: str  # "rudder" | "guidance"
    scenario_name: str

    @property
    def nominal_params(self) -> ParameterRecord:
        return self.nominal_model.params
