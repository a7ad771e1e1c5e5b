"""What a controller may know: the nominal model and the task, never the truth."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from shipgym.envs.core import scenario_context_row
from shipgym.models.base import ParameterRecord, ShipModel
from shipgym.paths import PchipPath, WaypointPath
from shipgym.scenarios.loader import Scenario, nominal_nomoto
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
    action_mode: str  # "rudder" | "guidance"
    #: the scenario's guidance settings (law, R_LOS = los_radius_L·L, look-ahead, VF/TVVF
    #: parameters): a scenario's ``guidance:`` block
    guidance: Any
    #: the scenario's reward weights (``reward:`` block: w_ψ, w_δ, w_Δ, goal bonus): the task's
    #: objective, public like the path
    reward: Any
    #: the observation's optional context features of this context (core.CONTEXT_NAMES,
    #: scaled as the env's ``context_features=True`` gives them): from the nominal model
    feature_row: np.ndarray

    @classmethod
    def of(cls, scenario: Scenario, action_mode: str) -> ControllerContext:
        """The context of ``scenario`` (its nominal model, path and timing).  A nominal ship
        that gives no first-order Nomoto model (what model-based controllers design on) is
        a :class:`~shipgym.scenarios.loader.ScenarioError` naming the key, as validation reports
        it (:func:`~shipgym.scenarios.loader.nominal_nomoto`; cached per ship)."""
        sc = scenario
        nominal_nomoto(sc)
        return cls(
            ship=sc.model.name,
            nominal_model=sc.model.with_params(sc.nominal_params),
            waypoints=np.array(sc.path.waypoints),
            path_type=sc.config.path.type,
            ship_length=sc.ship_length,
            nominal_speed=sc.model.nominal_speed,
            rudder_limit=sc.model.rudder_limit,
            control_period=sc.control_period,
            fine_step=sc.fine_step,
            acceptance_radius=sc.acceptance_radius,
            switching=sc.config.path.switching,
            action_mode=action_mode,
            guidance=sc.config.guidance,
            reward=sc.config.reward,
            feature_row=scenario_context_row(sc),
        )

    @property
    def nominal_params(self) -> ParameterRecord:
        return self.nominal_model.params

    def new_tracker(self) -> PathTracker:
        """A path tracker with the env's path and switching rule (for measured positions)."""
        path = (
            PchipPath(self.waypoints) if self.path_type == "pchip" else WaypointPath(self.waypoints)
        )
        return PathTracker(path, self.acceptance_radius, self.switching)
