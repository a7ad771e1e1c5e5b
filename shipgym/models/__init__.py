"""Ship models: one right-hand side each, evaluated by numpy and CasADi."""

from shipgym.models.base import ShipModel
from shipgym.models.blanke import Blanke
from shipgym.models.esso_osaka import EssoOsaka
from shipgym.models.kvlcc2 import KVLCC2
from shipgym.models.mariner import Mariner
from shipgym.models.nomoto2 import Nomoto2

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
    "MODELS",
    "UNSEEN_HULLS",
]
