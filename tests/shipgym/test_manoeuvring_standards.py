"""MSC.137(76) criteria (5.3.1, 5.3.3) against limits computed by hand, and the CLI's list."""

from __future__ import annotations

import json

import pytest

from shipgym.manoeuvring_standards import (
    first_overshoot_limit,
    imo_criteria,
    second_overshoot_limit,
)
from shipgym_baselines.cli import main


@pytest.mark.parametrize(
    ("l_over_v", "first", "second"),
    [
        (5.0, 10.0, 25.0),  # L/V < 10 s
        (9.999, 10.0, 25.0),
        (10.0, 10.0, 25.0),  # 5 + 5, 17.5 + 7.5: continuous at 10 s
        (20.0, 15.0, 32.5),  # 5 + 10, 17.5 + 15
        (29.0, 19.5, 39.25),
        (30.0, 20.0, 40.0),  # L/V ≥ 30 s
        (100.0, 20.0, 40.0),
    ],
)
def test_overshoot_limits_by_l_over_v(l_over_v: float, first: float, second: float) -> None:
    assert first_overshoot_limit(l_over_v) == pytest.approx(first)
    assert second_overshoot_limit(l_over_v) == pytest.approx(second)


def test_zigzag_10_10_uses_the_ships_l_over_v() -> None:
    """L = 160 m, V = 8 m/s: L/V = 20 s -> 15° first, 32.5° second overshoot."""
    got = imo_criteria(
        "zigzag", {"overshoot_1": 14.0, "overshoot_2": 33.0}, 160.0, 8.0, rudder_deg=10.0
    )
    assert got == [
        {
            "criterion": "first_overshoot_10_10",
            "value": 14.0,
            "limit": 15.0,
            "unit": "deg",
            "passed": True,
        },
        {
            "criterion": "second_overshoot_10_10",
            "value": 33.0,
            "limit": 32.5,
            "unit": "deg",
            "passed": False,
        },
    ]


def test_zigzag_20_20_first_overshoot_25_deg() -> None:
    got = imo_criteria("zigzag", {"overshoot_1": 25.0}, 100.0, 1.0, rudder_deg=20.0)
    assert got == [
        {
            "criterion": "first_overshoot_20_20",
            "value": 25.0,
            "limit": 25.0,
            "unit": "deg",
            "passed": True,
        }
    ]
    # a 20/10 zig-zag is no standard manoeuvre: nothing to judge
    assert imo_criteria("zigzag", {"overshoot_1": 5.0}, 100.0, 1.0, 20.0, 10.0) == []


def test_turning_in_ship_lengths() -> None:
    """Advance 450 m and tactical diameter 520 m of a 100 m ship: 4.5 L passes, 5.2 L fails."""
    figures = {"advance": 450.0, "tactical_diameter": 520.0}
    got = imo_criteria("turning", figures, 100.0, 5.0, rudder_deg=35.0)
    assert [(c["criterion"], c["value"], c["limit"], c["passed"]) for c in got] == [
        ("advance", 4.5, 4.5, True),
        ("tactical_diameter", 5.2, 5.0, False),
    ]
    # the maximum rudder of a ship that steers ±30° is its standard turning circle (4.2.2)
    assert len(imo_criteria("turning", figures, 100.0, 5.0, 30.0, max_rudder_deg=30.0)) == 2
    assert imo_criteria("turning", figures, 100.0, 5.0, rudder_deg=20.0) == []
    # never turned 180°: no value, not passed
    (_, diameter) = imo_criteria("turning", {"advance": 300.0}, 100.0, 5.0, 35.0)
    assert diameter["value"] is None and diameter["passed"] is False


def test_cli_manoeuvre_json_lists_the_criteria(tmp_path, capsys) -> None:
    """The Mariner (L = 172 m, V = 7.857 m/s, L/V = 21.89 s) in a 10/10 zig-zag."""
    out = ["--json", "--out", str(tmp_path)]
    assert main(["manoeuvre", "mariner", "zigzag", "--rudder", "10", *out]) == 0
    doc = json.loads(capsys.readouterr().out)
    first, second = doc["imo_criteria"]
    assert first["limit"] == pytest.approx(5.0 + 0.5 * 172.0 / (7.857142857142857))
    assert second["limit"] == pytest.approx(17.5 + 0.75 * 172.0 / (7.857142857142857))
    assert first["value"] == doc["overshoot_1"] and second["value"] == doc["overshoot_2"]
    assert main(["manoeuvre", "mariner", "turning", *out]) == 0
    doc = json.loads(capsys.readouterr().out)
    advance, diameter = doc["imo_criteria"]
    assert advance["value"] == pytest.approx(doc["advance"] / 172.0)
    assert diameter["value"] == pytest.approx(doc["tactical_diameter"] / 172.0)
    assert advance["unit"] == "L" and diameter["limit"] == 5.0
