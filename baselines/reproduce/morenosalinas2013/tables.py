"""Moreno-Salinas et al. (2013) §4: the markdown report."""

from __future__ import annotations

from shipgym_baselines.reproduce.morenosalinas2013.experiment import CASES, CONTROLLERS, SIGNALS
from shipgym_baselines.reproduce.protocol import Rows
from shipgym_baselines.reproduce.report import cell, index, seeds_of, table


def report(rows: Rows) -> str:
    """Table: case × signal; the paper's error std next to ours (vs measured and vs plant)."""
    by_key = index(rows)
    head = ["case", "signal", "paper"]
    for controller in CONTROLLERS:
        head += [f"{controller}", f"{controller} vs plant"]
    body = []
    for case in CASES:
        for signal in SIGNALS:
            unit = "rad/s" if signal == "yaw_rate" else "m/s"
            first = by_key.get((case, CONTROLLERS[0], f"std_error_{signal}"))
            if first is None:
                continue
            cells = [
                f"{case} ({CASES[case][2]})",
                f"{signal} [{unit}]",
                cell(first["paper"], ".4f"),
            ]
            for controller in CONTROLLERS:
                for metric in (f"std_error_{signal}", f"std_error_{signal}_vs_plant"):
                    cells.append(cell(by_key[(case, controller, metric)]["ours"], ".4f"))
            body.append(cells)
    note = (
        "\nStandard deviation of the error identified − measured (the paper's figure; "
        "measured = plant + IMU noise of §4.1) and identified − noise-free plant, mean over "
        f"{seeds_of(rows)} noise realisation(s).  Plant: the blanke naval vessel (51.5 m, "
        "8 m/s), not the paper's scale ship.  lssvm_blanke_lowpass: 0.5 Hz zero-phase "
        "low-pass before the regression (our addition).\n"
    )
    return "\n".join(table(head, body)) + "\n" + note
