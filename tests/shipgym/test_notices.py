"""The terminal's notice lines and their durations."""

from __future__ import annotations

import sys

import pytest

from shipgym.notices import duration, notice

#: these tests read the notice lines, which the suite silences
pytestmark = pytest.mark.usefixtures("loud")


def test_durations_read_as_a_person_says_them() -> None:
    assert [duration(s) for s in (0.2, 40, 95, 200, 540, 5400, 9000)] == [
        "1 s",
        "40 s",
        "2 min",
        "3 min",
        "9 min",
        "1.5 h",
        "2.5 h",
    ]


def test_a_notice_clears_a_progress_bar_on_a_terminal(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """On a terminal the line under way (a progress bar) is cleared first; in a file not."""
    notice("shipgym: a")
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    notice("shipgym: b")
    assert capsys.readouterr().err == "shipgym: a\n\r\x1b[Kshipgym: b\n"
