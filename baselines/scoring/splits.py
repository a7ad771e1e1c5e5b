"""The leaderboard's scenario splits: their names, which split a scenario falls in, and how
the tables, the figures and the sentences title each; and the change family of a run's
scenarios (:func:`suite_families`).

Every split is one entry of :data:`SPLITS` (the ranking is computed per split, each in its
own table and figures); a new split needs its entry there, with ``test=True`` when its
scenarios are named test scenarios ``<split>:<index>`` (:func:`scenario_split`).
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass
from typing import Any

from shipgym.config import is_path
from shipgym.models import UNSEEN_HULLS
from shipgym.scenarios.families import OTHER
from shipgym.scenarios.loader import ScenarioError, list_scenarios, load_scenario_file


@dataclass(frozen=True)
class Split:
    """How one split is titled: ``table`` heads its ranking tables (``leaderboard.md`` and
    the page), ``figure`` names it in a figure's title, ``label`` in a sentence (the
    generalisation table, the verdict); ``test``: its scenarios are the named test scenarios
    ``<split>:<index>``."""

    table: str
    figure: str
    label: str
    test: bool = False


#: the split of the suite's own scenarios (scenario files)
YOURS = "yours"
#: the split of the scenarios on an unseen hull
UNSEEN_HULL = "unseen_hull"
#: every split, by the name the rows' ``split`` holds, in the order the generalisation
#: table reads them
SPLITS = {
    "catalogue": Split("Catalogue scenarios", "catalogue scenarios", "catalogue"),
    # jumps outside the learned agents' training ranges (extrapolation)
    "heldout": Split("Held-out scenarios", "held-out scenarios", "held-out", test=True),
    # jumps inside them (interpolation)
    "inrange": Split(
        "In-range scenarios, drawn from the training ranges",
        "in-range scenarios",
        "in-range",
        test=True,
    ),
    # scenarios on a hull no controller is tuned or trained on (shipgym.models.UNSEEN_HULLS)
    UNSEEN_HULL: Split(
        "Unseen-hull scenarios, on a hull no controller was tuned or trained on",
        "unseen-hull scenarios",
        "unseen-hull",
    ),
    YOURS: Split("Your scenarios", "your scenarios", "yours"),
}
#: the ranking tables' headings, by split
SPLIT_TITLES = {name: split.table for name, split in SPLITS.items()}
#: the splits of the named test scenarios (``<split>:<index>``)
TEST_SPLITS = tuple(name for name, split in SPLITS.items() if split.test)
#: the splits of :func:`~shipgym_baselines.scoring.tables.generalisation`, in its order
GENERALISATION_SPLITS = ("catalogue", *TEST_SPLITS, UNSEEN_HULL)
#: the splits :func:`~shipgym_baselines.scoring.tables.generalisation` always has
ALWAYS_GENERALISED = ("catalogue", "heldout")


def table_title(split: str) -> str:
    """The heading of ``split``'s ranking table (an unknown split: its name)."""
    found = SPLITS.get(split)
    return found.table if found else split


def figure_title(split: str) -> str:
    """``split`` as a figure's title names it (an unknown split: its name)."""
    found = SPLITS.get(split)
    return found.figure if found else split


def split_label(split: str) -> str:
    """``split`` in a sentence (an unknown split: its name)."""
    found = SPLITS.get(split)
    return found.label if found else split


def scenario_split(scenario: str, own: Collection[str] = (), unseen: Collection[str] = ()) -> str:
    """``heldout`` / ``inrange`` for named held-out / in-range test scenarios
    (``heldout:3``, ``inrange:3``), :data:`YOURS` for the suite's own scenarios (``own``:
    their table names; a YAML path, as older records name them), :data:`UNSEEN_HULL` for
    the catalogue scenarios on an unseen hull (``unseen``: their names,
    :func:`unseen_hull_scenarios`), else ``catalogue``."""
    for split in TEST_SPLITS:
        if scenario.startswith(f"{split}:"):
            return split
    if scenario in own or is_path(scenario):
        return YOURS
    return UNSEEN_HULL if scenario in unseen else "catalogue"


def unseen_hull_scenarios(settings: Mapping[str, Mapping[str, Any]]) -> set[str]:
    """The scenarios of a run (name → settings, as ``run.json`` records them) whose ship is
    an unseen hull (:data:`shipgym.models.UNSEEN_HULLS`)."""
    return {name for name, s in settings.items() if s["ship"]["model"] in UNSEEN_HULLS}


def suite_splits(suite: Mapping[str, Any]) -> dict[str, str]:
    """Scenario → split of a resolved suite (``run.json``'s): its scenarios only, never its
    no-change twins (:func:`scenario_split` with the suite's own files and unseen hulls)."""
    own = suite.get("scenario_files", {})
    unseen = unseen_hull_scenarios(suite["scenarios"])
    return {s: scenario_split(s, own, unseen) for s in suite["scenarios"]}


def suite_families(suite: Mapping[str, Any]) -> dict[str, str]:
    """Scenario → change family of a resolved suite (``run.json``'s; never its no-change
    twins): the ``family:`` of the file the scenario was read from, the suite's own
    (``scenario_files``) or the catalogue's of that name; ``other`` for a named test
    scenario (``heldout:3``) and for a file no longer readable.  ``run.json`` records no
    family (the settings it keeps are the plant's), so a run of any age reads the same."""
    own = suite.get("scenario_files", {})
    catalogue = set(list_scenarios())
    files = {s: own.get(s, s if s in catalogue else None) for s in suite["scenarios"]}
    return {s: OTHER if file is None else _file_family(file) for s, file in files.items()}


def _file_family(file: str) -> str:
    """The change family a scenario file (a path or a catalogue name) names; ``other``
    when it cannot be read."""
    try:
        return load_scenario_file(file).family
    except ScenarioError:
        return OTHER
