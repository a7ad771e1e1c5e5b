"""The shipped estimators of ``nmpc_learned_id``: the folders ``seeds/seed_<k>`` beside this
module and their training seeds, read without importing the controller (the registry
lists the seeds, :data:`shipgym_baselines.controllers.BUILTINS`)."""

from __future__ import annotations

import re
from pathlib import Path

from shipgym_baselines.learned.plant_id.network import WEIGHTS_FILE

#: the shipped estimators: ``seed_<k>`` folders
SHIPPED = Path(__file__).parent / "seeds"
_SEED = re.compile(r"seed_(\d+)")


def shipped_seeds(folder: Path = SHIPPED) -> tuple[int, ...]:
    """The training seeds of the estimators in ``folder`` (``seed_<k>`` with weights)."""
    if not folder.is_dir():
        return ()
    return tuple(
        sorted(
            int(m.group(1))
            for p in folder.iterdir()
            if (m := _SEED.fullmatch(p.name)) and (p / WEIGHTS_FILE).is_file()
        )
    )
