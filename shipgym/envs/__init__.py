"""Gymnasium environments of shipgym."""

from shipgym.envs.context import ControllerContext
from shipgym.envs.path_follow import OBS_NAMES, ShipPathFollowEnv

__all__ = ["OBS_NAMES", "ControllerContext", "ShipPathFollowEnv"]
