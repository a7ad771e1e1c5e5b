"""Reading the settings a study chose: ``configs/tuning/chosen/<controller>.yaml``.

One file per controller, one section per ship (a per-ship study) or ``all`` (one setting for
every ship).  :func:`tuned_settings` is what a controller's default construction
(``preset="tuned"``) reads at reset; the writer and the files' format:
:mod:`shipgym_baselines.tuning.chosen`.
"""

from __future__ import annotations

import functools
import os
from pathlib import Path
from typing import Any

import yaml

from shipgym.config import catalogue
from shipgym_baselines.errors import RunError

#: the section of settings that hold for every ship
ALL_SHIPS = "all"


def chosen_dir() -> Path:
    """The packaged folder of chosen settings (``configs/tuning/chosen``)."""
    return Path(str(catalogue("tuning"))) / "chosen"


def chosen_file(controller: str, folder: str | os.PathLike | None = None) -> Path:
    return Path(folder if folder is not None else chosen_dir()) / f"{controller}.yaml"


def read_chosen(controller: str, folder: str | os.PathLike | None = None) -> dict[str, Any]:
    """The chosen-settings document of ``controller`` (empty when there is none); a
    :class:`RunError` in one line naming the file when it is no such document."""
    file = chosen_file(controller, folder)
    if not file.is_file():
        return {}
    try:
        data = yaml.safe_load(file.read_text(encoding="utf-8")) or {}
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        why = " ".join(str(exc).split())
        raise RunError(f"{file}: unreadable chosen settings ({why})") from None
    if not isinstance(data, dict) or not all(
        isinstance(data.get(key) or {}, dict) for key in ("ships", "studies")
    ):
        raise RunError(f"{file}: a mapping of 'controller', 'ships', 'studies' expected")
    return data


@functools.cache
def packaged_chosen(controller: str) -> dict[str, Any]:
    """:func:`read_chosen` of the packaged folder, read once per process (a writer clears
    the cache: :func:`shipgym_baselines.tuning.chosen.write_chosen`)."""
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
    ships = packaged_chosen(controller).get("ships") or {}
    return dict(ships.get(ship, ships.get(ALL_SHIPS)) or {})
