"""Ship models: one right-hand side each, evaluated by numpy and CasADi."""

from shipgym.models.base import (
    CASADI,
    NUMPY,
    ParameterError,
    ParameterRecord,
    ShipModel,
    rk4_step,
)
from shipgym.models.blanke import Blanke, BlankeParams
from shipgym.models.esso_osaka import EssoOsaka, EssoOsakaParams
from shipgym.models.kvlcc2 import KVLCC2, KVLCC2Params
from shipgym.models.mariner import Mariner, MarinerParams
from shipgym.models.nomoto2 import Nomoto2, Nomoto2Params, UnitReading, params_from_paper

#: model id -> class; the scenario loader and the env look models up here.
MODELS: dict[str, type[ShipModel]] = {
    "nomoto2": Nomoto2,
    "mariner": Mariner,
    "blanke": Blanke,
    "esso_osaka": EssoOsaka,
    "kvlcc2": KVLCC2,
}

#: hulls no controller is tuned or trained on: the leaderboard's unseen-hull split.  Only a
#: ``test_only`` distribution may list one (:mod:`shipgym.scenarios.sampling`).
UNSEEN_HULLS: frozenset[str] = frozenset({"kvlcc2"})

__all__ = [
    "CASADI",
    "KVLCC2",
    "MODELS",
    "NUMPY",
    "UNSEEN_HULLS",
    "Blanke",
    "BlankeParams",
    "EssoOsaka",
    "EssoOsakaParams",
    "KVLCC2Params",
    "Mariner",
    "MarinerParams",
    "Nomoto2",
    "Nomoto2Params",
    "ParameterError",
    "ParameterRecord",
    "ShipModel",
    "UnitReading",
    "params_from_paper",
    "rk4_step",
]
