"""The settings a study chose: ``configs/tuning/chosen/<controller>.yaml``.

One file per controller, one section per ship (a per-ship study) or ``all`` (one setting for
every ship, e.g. a learned agent's hyperparameters)::

    controller: pid_los
    ships:
      mariner: {natural_frequency_T: 1.9, damping: 1.2, los_radius_L: 4.1}
    studies:
      mariner: {study: "pid_los:mariner", best_value: 1.83, default_value: 7.2, ...}

:func:`tuned_settings` is what a controller's default construction (``preset="tuned"``)
reads at reset; :func:`write_chosen` is what ``shipgym tune`` writes when a study ends (into
the study's own folder unless it is promoted: :mod:`~shipgym_baselines.tuning.promotion`).

Each study summary records the validation objective of the settings it chose and, under
``validation``, the trials it was scored on with their cost ratios and the env and oracle
revisions: a later study compares its winner with these settings on the same trials
(paired) before it may replace them.
"""

from __future__ import annotations

import functools
import os
from pathlib import Path
from typing import Any

import yaml

from shipgym.config import catalogue

#: the section of settings that hold for every ship
ALL_SHIPS = "all"


def chosen_dir() -> Path:
    """The packaged folder of chosen settings (``configs/tuning/chosen``)."""
    return Path(str(catalogue("tuning"))) / "chosen"


def chosen_file(controller: str, folder: str | os.PathLike | None = None) -> Path:
    return Path(folder if folder is not None else chosen_dir()) / f"{controller}.yaml"


def read_chosen(controller: str, folder: str | os.PathLike | None = None) -> dict[str, Any]:
    """The chosen-settings document of ``controller`` (empty when there is none)."""
    file = chosen_file(controller, folder)
    if not file.is_file():
        return {}
    data = yaml.safe_load(file.read_text(encoding="utf-8")) or {}
    if not isinstance(data, dict):
        raise ValueError(f"{file}: a mapping of 'controller', 'ships', 'studies' expected")
    return data


@functools.cache
def _packaged(controller: str) -> dict[str, Any]:
    return read_chosen(controller)


def section_record(
    controller: str, section: str, folder: str | os.PathLike | None = None
) -> tuple[dict[str, Any], dict[str, Any]] | None:
    """The settings of ``section`` and the summary of the study that chose them, or None
    when the file has no such section."""
    data = read_chosen(controller, folder)
    ships = data.get("ships") or {}
    if section not in ships:
        return None
    return dict(ships[section] or {}), dict((data.get("studies") or {}).get(section) or {})


def tuned_settings(controller: str, ship: str) -> dict[str, Any]:
    """The packaged chosen settings of ``controller`` on ``ship`` (its ship section, else the
    ``all`` section, else none: the paper's settings)."""
    ships = _packaged(controller).get("ships") or {}
    return dict(ships.get(ship, ships.get(ALL_SHIPS)) or {})


def write_chosen(
    controller: str,
    section: str,
    settings: dict[str, Any],
    study: dict[str, Any],
    folder: str | os.PathLike | None = None,
) -> tuple[Path, dict[str, Any] | None]:
    """Set the ``section`` (a ship or ``all``) of ``controller``'s chosen settings to
    ``settings`` (with the study's summary ``study``), keeping the other sections; returns
    the file and the settings it replaced (None: a new section)."""
    file = chosen_file(controller, folder)
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
    file.parent.mkdir(parents=True, exist_ok=True)
    staged = file.with_name(f"{file.name}.{os.getpid()}.tmp")
    staged.write_text(header + yaml.safe_dump(document, sort_keys=False), encoding="utf-8")
    os.replace(staged, file)
    _packaged.cache_clear()
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
