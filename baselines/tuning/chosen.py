"""The settings a study chose: ``configs/tuning/chosen/<controller>.yaml``.

One file per controller, one section per ship (a per-ship study) or ``all`` (one setting for
every ship, e.g. a learned agent's hyperparameters)::

    controller: pid_los
    ships:
      mariner: {natural_frequency_T: 1.9, damping: 1.2, los_radius_L: 4.1}
    studies:
      mariner: {study: "pid_los:mariner", best_value: 1.83, default_value: 7.2, ...}

:func:`~shipgym_baselines.records.chosen.tuned_settings` is what a controller's default
construction (``preset="tuned"``) reads at reset (the reader sits below the controllers, in
:mod:`shipgym_baselines.records.chosen`; its names stay importable from here);
:func:`write_chosen` is what ``shipgym tune`` writes when a study ends (into the study's own
folder unless it is promoted: :mod:`~shipgym_baselines.tuning.promotion`).

Each study summary records the validation objective of the settings it chose and, under
``validation``, the trials it was scored on with their cost ratios and the env and oracle
revisions: a later study compares its winner with these settings on the same trials
(paired) before it may replace them.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import yaml

# the reader sits below the controllers (records/chosen.py: a controller's 'tuned' preset
# reads it); its names stay importable from here
from shipgym_baselines.records.chosen import chosen_file, packaged_chosen, read_chosen
from shipgym_baselines.records.locking import file_lock
from shipgym_baselines.records.outfiles import refuse_special, write_text
from shipgym_baselines.records.runrecord import now


def write_chosen(
    controller: str,
    section: str,
    settings: dict[str, Any],
    study: dict[str, Any],
    folder: str | os.PathLike | None = None,
) -> tuple[Path, dict[str, Any] | None]:
    """Set the ``section`` (a ship or ``all``) of ``controller``'s chosen settings to
    ``settings`` (with the study's summary ``study``), keeping the other sections; returns
    the file and the settings it replaced (None: a new section).  The file is read,
    changed and written under its lock (two studies of two ships that end together keep
    both sections) and written through no link (a link in its place is refused in one
    line): :mod:`shipgym_baselines.records.locking`, :mod:`~shipgym_baselines.records.outfiles`."""
    file = chosen_file(controller, folder)
    with file_lock(file, now(), "--chosen-dir", wait=True):
        return _write_chosen(controller, section, settings, study, folder, file)


def _write_chosen(
    controller: str,
    section: str,
    settings: dict[str, Any],
    study: dict[str, Any],
    folder: str | os.PathLike | None,
    file: Path,
) -> tuple[Path, dict[str, Any] | None]:
    """:func:`write_chosen` once the file is locked."""
    refuse_special(file, "--chosen-dir")  # before the result is merged into what it points to
    data = read_chosen(controller, folder)
    ships = dict(data.get("ships") or {})
    studies = dict(data.get("studies") or {})
    replaced = ships.get(section)
    ships[section] = {k: _plain(v) for k, v in settings.items()}
    studies[section] = {k: _plain(v) for k, v in study.items()}
    document = {
        "controller": controller,
        "ships": dict(sorted(ships.items())),
        "studies": dict(sorted(studies.items())),
    }
    header = (
        f"# Chosen settings of {controller}, written by `shipgym tune` (docs/tuning.md): one\n"
        "# section per ship (or 'all'); each study's report is named under 'studies'.\n"
    )
    write_text(file, header + yaml.safe_dump(document, sort_keys=False))  # atomic, no link
    packaged_chosen.cache_clear()
    return file, replaced


def _plain(value: Any) -> Any:
    """YAML-safe: numpy scalars as Python numbers, tuples as lists."""
    if hasattr(value, "item"):
        return value.item()
    if isinstance(value, tuple | list):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value
