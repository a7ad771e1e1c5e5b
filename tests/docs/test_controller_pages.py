"""The generated controller pages (``docs/_ext/shipgym_docs/controllers.py``) show the shipped
chosen settings per ship beside the defaults, with each study's validation objective; checked
on the page text, without a Sphinx build."""

from __future__ import annotations

import re
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "docs" / "_ext"))

from shipgym_docs import controllers  # noqa: E402

from shipgym.models import MODELS  # noqa: E402
from shipgym_baselines.records.chosen import read_chosen  # noqa: E402
from shipgym_baselines.registry import CONTROLLERS  # noqa: E402

#: the ship no tuning study covers (docs/ships.md, KVLCC2)
UNTUNED = "kvlcc2"


def settings_rows(text: str) -> dict[str, list[str]]:
    """Keyword -> the cells of its row in the page's settings table."""
    section = text.split("## Settings", 1)[1].split("## Description", 1)[0]
    rows = {}
    for line in section.splitlines():
        match = re.match(r"\| `(\w+)` \| (.*) \|$", line)
        if match:
            rows[match.group(1)] = [c.strip() for c in match.group(2).split(" | ")]
    return rows


def test_the_pid_los_page_shows_each_ships_chosen_settings() -> None:
    text = controllers.page(CONTROLLERS["pid_los"])
    chosen = read_chosen("pid_los")
    ships = list(MODELS)
    # every ship but kvlcc2, the hull no controller is tuned on: its column shows "—"
    assert set(chosen["ships"]) == set(ships) - {UNTUNED}
    rows = settings_rows(text)
    untuned = 1 + ships.index(UNTUNED)
    settings_cells = [cells for cells in rows.values() if len(cells) == 1 + len(ships)]
    assert settings_cells and all(cells[untuned] == "—" for cells in settings_cells), UNTUNED
    for ship, values in chosen["ships"].items():
        column = 1 + ships.index(ship)  # after the default
        assert f"{values['natural_frequency_T']:.6g}" in text, ship
        for keyword, value in values.items():
            cell = rows[keyword][column]
            assert "None" not in cell, (ship, keyword, cell)
            shown = f"{value:.6g}" if isinstance(value, float) else repr(value)
            assert cell == f"`{shown}`", (ship, keyword, cell)
    # a keyword with a chosen value never shows None as its default either
    for keyword in {k for values in chosen["ships"].values() for k in values}:
        assert "None" not in rows[keyword][0], (keyword, rows[keyword])
    assert "`'tuned'`" in rows["preset"][0]


def test_the_pid_los_page_gives_each_studys_validation_objective() -> None:
    text = controllers.page(CONTROLLERS["pid_los"])
    for ship, study in read_chosen("pid_los")["studies"].items():
        row = next(line for line in text.splitlines() if line.startswith(f"| `{ship}` | `pid_los"))
        assert f"| {study['best_value']:.3f} | {study['default_value']:.3f} |" in row, row


def test_an_nmpc_member_without_a_study_shows_the_settings_it_borrows() -> None:
    text = controllers.page(CONTROLLERS["nmpc_wlssvm_svf"])
    assert "`nmpc`'s, `configs/tuning/chosen/nmpc.yaml`" in text
    horizon = read_chosen("nmpc")["ships"]["mariner"]["horizon_scale"]
    assert f"`{horizon:.6g}`" in settings_rows(text)["horizon_scale"]


def test_a_controller_without_chosen_settings_says_so() -> None:
    text = controllers.page(CONTROLLERS["oracle"])
    assert "No chosen settings" in text and "chosen: nomoto2" not in text
