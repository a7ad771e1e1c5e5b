"""From a study to a training run: the agent config with its study's chosen settings and
the protocol's final-training block (``shipgym train AGENT --settings tuned``).

The chosen settings are the ``all`` section of ``configs/tuning/chosen/<controller>.yaml``
(dotted keys, applied with the study's own
:func:`~shipgym_baselines.tuning.learned.apply_overrides`); the tuning config
``configs/tuning/<agent>.yaml`` gives the controller and the ``final`` block (env steps,
plateau rule, model selection, seeds).  What was applied is returned as ``tuned_from``,
recorded in the run's ``meta.json``.
"""

from __future__ import annotations

import os
from typing import Any

from shipgym_baselines.errors import RunError
from shipgym_baselines.records import chosen
from shipgym_baselines.records.chosen import ALL_SHIPS, chosen_file, read_chosen
from shipgym_baselines.tuning.learned import apply_overrides
from shipgym_baselines.tuning.space import TuningConfig, TuningError, load_tuning

#: ``--settings``: the agent config as written, or with its study's chosen settings
SETTINGS = ("config", "tuned")


def agent_tuning(agent_name: str) -> TuningConfig:
    """The learned tuning config of agent ``agent_name`` (``configs/tuning/<name>.yaml``)
    with its ``final`` block; a :class:`RunError` naming the file otherwise."""
    try:
        tuning = load_tuning(agent_name)
    except TuningError as exc:
        raise RunError(
            f"--settings tuned: the tuning config of agent {agent_name!r}: {exc}"
        ) from exc
    if tuning.kind != "learned" or tuning.training is None:
        raise RunError(f"--settings tuned: tuning config {agent_name!r} is not a learned study")
    if tuning.final is None:
        raise RunError(
            f"--settings tuned: configs/tuning/{agent_name}.yaml has no 'final' block "
            "(n_timesteps, plateau, select_on, seeds)"
        )
    return tuning


def tuned_agent(
    agent: Any, chosen_dir: str | os.PathLike | None = None
) -> tuple[Any, dict[str, Any]]:
    """``agent`` (an AgentConfig) with its study's chosen settings and the final block
    (n_timesteps, plateau, eval.select_on) applied, and the ``tuned_from`` record; a
    :class:`RunError` naming the chosen file when it has no (or an empty) ``all`` section."""
    tuning = agent_tuning(agent.name)
    final = tuning.final
    assert final is not None  # agent_tuning checked it
    file = chosen_file(tuning.controller, chosen_dir)
    document = read_chosen(tuning.controller, chosen_dir)
    settings = (document.get("ships") or {}).get(ALL_SHIPS)
    if not settings:
        state = "an empty" if settings is not None else "no"
        raise RunError(
            f"--settings tuned: {file} has {state} '{ALL_SHIPS}' section for {tuning.controller} "
            f"(run `shipgym tune {tuning.name}`; empty: the study kept the default)"
        )
    tuned = apply_overrides(agent, dict(settings))
    tuned = tuned.model_validate(
        {
            **tuned.model_dump(),
            "n_timesteps": final.n_timesteps,
            "plateau": final.plateau.model_dump(),
            "eval": {**tuned.eval.model_dump(), "select_on": final.select_on},
        }
    )
    study = (document.get("studies") or {}).get(ALL_SHIPS) or {}
    # the packaged file by its path in the repository (a record that does not name the
    # machine it was trained on), another folder's as given
    packaged = file.parent == chosen.chosen_dir()
    shown = f"configs/tuning/chosen/{file.name}" if packaged else str(file)
    tuned_from = {
        "chosen": shown,
        "section": ALL_SHIPS,
        "settings": dict(settings),
        "study": study.get("study"),
        "report": study.get("report"),
        "tuning": tuning.name,
        "final": final.model_dump(),
    }
    return tuned, tuned_from
