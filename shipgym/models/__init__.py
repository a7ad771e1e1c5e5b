"""Ship models: one right-hand side each, evaluated by numpy and CasADi; each module ends with
its ship's record (:mod:`shipgym.models.ship`), registered here."""

from shipgym.models import blanke, esso_osaka, kvlcc2, mariner, nomoto2
from shipgym.models.base import ShipModel
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
    "MODELS",
    "UNSEEN_HULLS",
]
