"""The twins a leaderboard run plays: each changing scenario's no-change twin
(:func:`shipgym.scenarios.twins.nominal_twin`), shared where they are the same task.

Every scenario of a run that changes gets a twin, played by every competitor and by the
``oracle`` on the same evaluation seeds (the optimum that never adapts needs none: on a
twin the plant never changes, so its cost there is taken as the oracle's).  Twins that are
the same task (:func:`shipgym.scenarios.twins.same_trial`) are played once:

* a twin equal to a scenario of the run (``esso_osaka_rudder_aging``'s is
  ``esso_osaka_nominal``: same route, start and time limit) is that scenario;
* twins equal to each other (``rudder_aging_long`` and ``current_shift_long`` share one)
  are one twin, named after the first scenario that has it: ``twin:rudder_aging_long``.

``run.json`` records the result (:func:`twin_record`): ``twins`` maps each changing
scenario to its twin's table name, ``twin_scenarios`` holds the settings of the twins
that are not scenarios of the run, ``twin_players`` the controllers that play them.  A
learned agent whose training seeds share the trials deals a scenario's trials as its
twin's, so each trial and its twin are played by the same training seed
(:func:`~shipgym_baselines.records.trials.deal_names`).
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from typing import Any

from shipgym.scenarios.loader import Scenario
from shipgym.scenarios.twins import nominal_twin, settings_without_labels
from shipgym_baselines.records.trials import TWIN_SCENARIOS, TWINS

#: the prefix of a twin's table name that is no scenario of the run
TWIN_PREFIX = "twin:"


def plan_twins(
    scenarios: Mapping[str, Scenario], seeds_of: Mapping[str, Sequence[int]]
) -> tuple[dict[str, str], dict[str, Scenario]]:
    """(scenario → its twin's table name, the new twins by table name) for the changing
    ``scenarios`` (table name → scenario, in the suite's order; module doc).  A twin is
    shared with a scenario or another twin only when both are the same task and run on the
    same evaluation seeds (``seeds_of``: each scenario's)."""
    drawn = {name: nominal_twin(sc, name=f"{TWIN_PREFIX}{name}") for name, sc in scenarios.items()}
    by_task: dict[tuple[str, tuple[int, ...]], str] = {}
    for name, scenario in scenarios.items():
        if drawn[name] is None:
            by_task.setdefault(_task(scenario, seeds_of[name]), name)
    twins: dict[str, str] = {}
    new: dict[str, Scenario] = {}
    for name, twin in drawn.items():
        if twin is None:
            continue
        key = _task(twin, seeds_of[name])
        if key not in by_task:
            by_task[key] = twin.name
            new[twin.name] = twin
        twins[name] = by_task[key]
    return twins, new


def _task(scenario: Scenario, seeds: Sequence[int]) -> tuple[str, tuple[int, ...]]:
    text = json.dumps(settings_without_labels(scenario), sort_keys=True)
    return text, tuple(int(s) for s in seeds)


def twin_record(twins: Mapping[str, str], new: Mapping[str, Scenario]) -> dict[str, Any]:
    """``run.json``'s twin keys (module doc); empty without twins."""
    if not twins:
        return {}
    return {
        TWINS: dict(twins),
        TWIN_SCENARIOS: {t: sc.config.model_dump(mode="json") for t, sc in new.items()},
    }
