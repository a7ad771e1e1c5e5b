"""Ship models: one right-hand side each, evaluated by numpy and CasADi; each module ends with
its ship's record (:mod:`shipgym.models.ship`), registered here."""

from shipgym.models import blanke, esso_osaka, kvlcc2, mariner, nomoto2
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
from shipgym.models.ship import ShipSet, ShipTable, register

for _ship in (nomoto2.SHIP, mariner.SHIP, blanke.SHIP, esso_osaka.SHIP, kvlcc2.SHIP):
    register(_ship)

#: model id -> class (every registered ship's record); the scenario loader and the env look
#: models up here.
MODELS: ShipTable[type[ShipModel]] = ShipTable(lambda ship: ((ship.name, ship.model),))

#: hulls no controller is tuned or trained on (records with ``unseen``): the leaderboard's
#: unseen-hull split.  Only a ``test_only`` distribution may list one
#: (:mod:`shipgym.scenarios.sampling`).
UNSEEN_HULLS: ShipSet = ShipSet(lambda ship: ship.unseen)

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
