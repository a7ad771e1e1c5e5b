"""A trained agent's folder: what a training run writes there, the settings it started with,
the value of its best model, and whether a fresh run may start in it.  Shared by the SB3 trainer
(:mod:`shipgym_baselines.learned.train`) and the DAgger agent
(:mod:`shipgym_baselines.learned.dagger_agent`)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from shipgym_baselines.errors import RunError
from shipgym_baselines.records.folders import check_out_dir

#: what a training run writes into its directory (``force`` clears these, and only these)
TRAINING_OUTPUTS = (
    "model.zip",
    "best_model.zip",
    "meta.json",
    "vecnormalize.json",
    "checkpoints",
    "eval",
    "tb",
    "learning_curve.json",
    "tuned_from.json",
    "dagger",  # a dagger agent's DAgger run (shipgym_baselines.learned.dagger_agent)
)
#: the chosen settings a run was started with (``--settings tuned``; null: the config's)
TUNED_FROM_FILE = "tuned_from.json"


def check_tuned_from(out: Path, tuned_from: dict[str, Any] | None, resuming: bool) -> None:
    """A fresh run records the settings it starts with (``tuned_from.json``); a resumed one
    is refused if they changed since (e.g. a study rewrote the chosen settings)."""
    file = out / TUNED_FROM_FILE
    record = json.loads(json.dumps(tuned_from))  # as JSON reads it back
    if resuming and file.is_file():
        started = json.loads(file.read_text())
        if _substance(started) != _substance(record):
            raise RunError(
                f"--resume: {out} was started with other settings ({file}); train it "
                "afresh with --force, or resume with the settings it started with"
            )
        return
    file.write_text(json.dumps(record, indent=2))


def _substance(tuned_from: dict[str, Any] | None) -> Any:
    """What a resumed run must share with its start: the applied settings and final block
    (not where the files lie: a moved checkout resumes)."""
    if tuned_from is None:
        return None
    return {key: tuned_from.get(key) for key in ("settings", "final")}


def check_agent_folder(out: str | Path, name: str, force: bool = False) -> None:
    """A :class:`RunError` unless ``out`` can take a fresh training run of agent ``name``:
    usable, and empty unless ``force``."""
    check_out_dir(out, force=force, note=f" (agent folder of {name})")


#: the value of ``best_model.zip`` (the best ever evaluated, which a resumed run's history
#: may no longer hold) and the env step it was evaluated at
BEST_FILE = "best.json"


def write_best(out: Path, value: float, step: int) -> None:
    """Record in ``out/eval/`` (:data:`BEST_FILE`) the value of the model just saved as
    ``best_model.zip`` (its mean return, or its relative cost when the run selects on it)
    and the env step it was evaluated at."""
    (out / "eval").mkdir(parents=True, exist_ok=True)
    (out / "eval" / BEST_FILE).write_text(json.dumps({"value": value, "env_steps": step}))
