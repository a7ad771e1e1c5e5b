"""A trained agent's folder: what a training run writes there, the settings it started with,
the value of its best model, and whether a fresh run may start in it.  Shared by the SB3 trainer
(:mod:`shipgym_baselines.training.train`) and the DAgger agent
(:mod:`shipgym_baselines.training.dagger_agent`).

A training run writes its folder as ``shipgym run`` writes its own (:func:`agent_run`): the
folder locked while it trains (a second run on it refused in one line), every file it
writes listed in ``manifest.txt`` before it is written, ``force`` deleting only what the
manifest lists (a folder holding anything else is refused before anything is deleted), and
a folder holding a link refused (files are written through none).
"""

from __future__ import annotations

import contextlib
import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from shipgym_baselines.errors import RunError
from shipgym_baselines.records.folders import check_out_dir, check_out_usable
from shipgym_baselines.records.jsonfiles import read_json
from shipgym_baselines.records.locking import out_lock
from shipgym_baselines.records.manifest import Manifest, clear_listed
from shipgym_baselines.records.outfiles import check_no_links, make_dir, write_text
from shipgym_baselines.records.runrecord import now

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
    "dagger",  # a dagger agent's DAgger run (shipgym_baselines.training.dagger_agent)
)
#: the chosen settings a run was started with (``--settings tuned``; null: the config's)
TUNED_FROM_FILE = "tuned_from.json"
#: the files and folders of a training run with fixed names, listed in its manifest when it
#: starts (those it names as it goes, checkpoints and TensorBoard logs, are listed then)
TRAINING_FILES = (
    "model.zip",
    "best_model.zip",
    "meta.json",
    "vecnormalize.json",
    "learning_curve.json",
    TUNED_FROM_FILE,
    "checkpoints",
    "checkpoints/state.json",
    "eval",
    "eval/evaluations.npz",
    "eval/best.json",
    "eval/selection.json",
    "eval/reference_costs.json",
    "tb",
)


@contextlib.contextmanager
def agent_run(out: str | Path, name: str, resume: bool, force: bool) -> Iterator[Manifest]:
    """The agent folder ``out`` open for a training run of agent ``name`` (module doc): a
    :class:`RunError` in one line when another run holds it, it holds a link, or (a fresh
    run) it is not empty without ``force``; with ``force`` the paths its manifest lists
    are deleted first.  Inside, every file written through
    :mod:`~shipgym_baselines.records.outfiles` is listed in the manifest yielded."""
    folder = Path(out)
    check_out_usable(folder, resume=resume, force=force)
    with out_lock(folder, now()):
        check_no_links(folder)
        if not resume:
            check_agent_folder(folder, name, force)
            if force:
                clear_listed(folder)
        manifest = Manifest(folder)
        manifest.claim(*TRAINING_FILES)
        with manifest.recording():
            yield manifest
        manifest.compact()


def read_record(file: Path, key: str | None = None) -> Any:
    """A JSON record of a training run (its ``key`` only, if given); a :class:`RunError`
    in one line naming the file when it cannot be read, or lacks ``key`` (a damaged record:
    the run is trained afresh with ``--force``)."""
    try:
        record = read_json(file)
        return record if key is None else record[key]
    except RunError as exc:
        why = str(exc)
    except (KeyError, TypeError, IndexError):
        why = f"{file}: no {key!r} in it"
    raise RunError(f"{why}: a damaged record of the run (--force trains it afresh)")


def write_json_file(file: Path, value: Any, indent: int | None = 2) -> None:
    """``value`` as JSON in ``file``, atomically and through no link (its folder made if
    missing)."""
    if not file.parent.is_dir():
        file.parent.mkdir(parents=True, exist_ok=True)
        make_dir(file.parent)  # listed; refused if a link stands in its place
    write_text(file, json.dumps(value, indent=indent))


def check_tuned_from(out: Path, tuned_from: dict[str, Any] | None, resuming: bool) -> None:
    """A fresh run records the settings it starts with (``tuned_from.json``); a resumed one
    is refused if they changed since (e.g. a study rewrote the chosen settings)."""
    file = out / TUNED_FROM_FILE
    record = json.loads(json.dumps(tuned_from))  # as JSON reads it back
    if resuming and file.is_file():
        started = read_record(file)
        if _substance(started) != _substance(record):
            raise RunError(
                f"--resume: {out} was started with other settings ({file}); train it "
                "afresh with --force, or resume with the settings it started with"
            )
        return
    write_json_file(file, record)


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
    write_json_file(out / "eval" / BEST_FILE, {"value": value, "env_steps": step}, None)
