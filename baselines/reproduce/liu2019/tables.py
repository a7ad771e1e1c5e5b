"""Liu et al. (2019) §4: the markdown report."""

from __future__ import annotations

from baselines.reproduce.liu2019.experiment import CASES, CONTROLLERS, READINGS
from baselines.reproduce.protocol import Rows
from baselines.reproduce.report import cell, index, table

NOTE = (
    "\nACE: mean |e| [m] after the change (Liu et al. 2019 eq. 46); t_c: the moment [s] "
    "from which |e| stays below 0.05 m ('never' if it does not).\n"
)


def _fmt(value: float | None) -> str:
    return cell(value, ".3f", inf="never")


def report(rows: Rows) -> str:
    """Table: case × controller, ACE and t_c ours/paper per unit reading."""
    readings = sorted({r["unit_reading"] for r in rows}, key=READINGS.index)
    head = ["case", "controller", "ACE paper", "t_c paper"]
    for reading in readings:
        head += [f"ACE ({reading})", f"t_c ({reading})"]
    by_key = index(rows, "unit_reading")
    body = []
    for case in CASES:
        for cls in CONTROLLERS:
            name = cls.name
            cells = [
                f"{CASES[case][0]} {case}",
                name,
                _fmt(by_key[(case, name, "ace", readings[0])]["paper"]),
                _fmt(by_key[(case, name, "t_c", readings[0])]["paper"]),
            ]
            for reading in readings:
                cells += [
                    _fmt(by_key[(case, name, "ace", reading)]["ours"]),
                    _fmt(by_key[(case, name, "t_c", reading)]["ours"]),
                ]
            body.append(cells)
    return "\n".join(table(head, body)) + "\n" + NOTE
