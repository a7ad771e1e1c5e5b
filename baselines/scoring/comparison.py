"""What a run is ranked against: the references added to its controllers.

The ranking divides each episode's cost by the ``oracle``'s on the same trial
(:mod:`shipgym_baselines.scoring.ranking`), so a run without the oracle has no ranking.
``shipgym evaluate``, ``shipgym leaderboard --controllers`` and a suite that does not list
the ``oracle`` add the references :data:`REFERENCES` the controllers lack, unless
``--no-references`` (a suite that lists the oracle runs as it lists its controllers):

* ``oracle``: the denominator of the cost ratio, read from its shipped reference table
  (:mod:`shipgym_baselines.references`: no episode to run on the packaged suites);
* ``oracle_frozen``: the same NMPC with its truth frozen at the episode's start, the optimum
  of a controller that never adapts (the gap metrics' other end), read from its table too;
* ``zero_rudder`` and ``random``: what doing nothing and acting at random cost on the
  same trials, the cheapest controllers of the suite (a line of the cost-ratio table each;
  never ranked).

A run of chosen controllers (``evaluate``, ``--controllers``) is ranked against these
references and among its own controllers only: it is not merged with any other run.
``run.json`` records what was added (:func:`references_record`) and the tables say so in one
line (:func:`comparison_note`), with the commands that compare with the suite's controllers.
"""

from __future__ import annotations

import shlex
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from shipgym_baselines.plugins import ControllerEntry, ControllerSpec
from shipgym_baselines.privileged import ORACLE, ORACLE_FROZEN
from shipgym_baselines.scoring.scores import REFERENCE_KIND

#: the references added to a run's controllers (the cost ratio's denominator first)
REFERENCES = (ORACLE, ORACLE_FROZEN, "zero_rudder", "random")
#: the key of ``run.json``'s suite record that :func:`references_record` fills
RECORD_KEY = "references"
#: the folder of the leaderboard's default ``--out`` (:func:`suite_folder`)
RESULTS_ROOT = Path("results")


def _spec(controller: ControllerSpec) -> str:
    return controller if isinstance(controller, str) else controller.controller


def with_references(
    controllers: Sequence[ControllerSpec],
) -> tuple[list[ControllerSpec], list[str]]:
    """``controllers`` followed by the :data:`REFERENCES` none of them is (by table name),
    and the names added."""
    from shipgym_baselines.registry import controller_label

    labels = {controller_label(c) for c in controllers}
    added = [name for name in REFERENCES if name not in labels]
    return [*controllers, *added], added


def suite_folder(suite: str | Path) -> Path:
    """``shipgym leaderboard``'s default ``--out`` for ``--suite suite``: ``results/<name>``
    (a suite file: its stem), so each suite's run has its own folder."""
    return RESULTS_ROOT / Path(str(suite)).stem


def references_record(
    suite: str | Path,
    suite_controllers: Sequence[ControllerSpec],
    given: Sequence[ControllerSpec] | None,
    added: Sequence[str],
) -> dict[str, Any]:
    """``run.json``'s record of the references added: ``added`` (their names), ``suite`` (as
    given to ``--suite``), ``suite_controllers`` (the suite's specs) and ``given`` (the
    controllers asked for, None: the suite's)."""
    return {
        "added": list(added),
        "suite": str(suite),
        "suite_controllers": [_spec(c) for c in suite_controllers],
        "given": None
        if given is None
        else [c if isinstance(c, str) else c.model_dump() for c in given],
    }


def _shown(folder: str | Path) -> str:
    """``folder`` relative to the working directory when inside it, else as given."""
    try:
        return str(Path(folder).resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(folder)


def _command_words(given: Iterable[Any]) -> tuple[list[str], list[str]]:
    """The specs of the controllers asked for and their ``--name SPEC=NAME`` options."""
    specs, names = [], []
    for c in given:
        if isinstance(c, str):
            specs.append(c)
            continue
        entry = ControllerEntry(**c)
        specs.append(entry.controller)
        if entry.name:
            names += ["--name", f"{entry.controller}={entry.name}"]
    return specs, names


def comparison_note(suite: Mapping[str, Any], folder: str | Path | None = None) -> str:
    """One line on what a run is ranked against (``suite``: ``run.json``'s suite record), ""
    when no reference was added and no controller of the suite left out: the references
    added, and for a run that left out controllers of its suite the command that runs them
    beside its own and (``folder``: the run's) the one that merges it with a run of the
    suite."""
    record = suite.get(RECORD_KEY)
    if not record:
        return ""
    specs, names = _command_words(record["given"] or [])
    not_run = [c for c in record["suite_controllers"] if c not in specs and c not in REFERENCES]
    added = ", ".join(f"`{name}`" for name in record["added"])
    if record["given"] is None or not not_run:
        if not added:
            return ""
        return f"References added for the cost ratio: {added} (`--no-references`: none)."
    competitors = [c["name"] for c in suite["controllers"] if c["kind"] != REFERENCE_KIND]
    listed = ", ".join(
        f"`{c['name']}`" for c in suite["controllers"] if c["kind"] == REFERENCE_KIND
    )
    if len(competitors) <= 1:
        head = f"Ranked against the references only ({listed})"
    else:
        head = f"Ranked among this run's {len(competitors)} controllers and against the "
        head += f"references ({listed}) only"
    run = ["shipgym", "leaderboard", "--suite", record["suite"]]
    if not set(specs) <= set(record["suite_controllers"]):
        run += ["--controllers", *not_run, *specs, *names]
    text = (
        f"{head}, not against the suite's other controllers ({len(not_run)}); to compare "
        f"with them, add them: `{shlex.join(run)}`"
    )
    suite_run = str(suite_folder(record["suite"]))
    if folder is not None and Path(str(folder)).resolve() != Path(suite_run).resolve():
        merged = f"{suite_run}_with_{Path(str(folder)).name}"
        report = ["shipgym", "report", suite_run, _shown(folder), "--out", merged]
        text += f", or merge this run with one of the suite: `{shlex.join(report)}`"
    return text + "."
