"""Xu & Guedes Soares (2020) Tables 2–3: VF against LOS, statistic by statistic, the paper's
relation against ours (no published row: the tables carry the paper's numbers)."""

from __future__ import annotations

from typing import Any

from shipgym_baselines.reproduce.xu2020.published import TABLE_LINES

Index = dict[tuple[Any, ...], dict[str, Any]]  # (case, controller, metric, setting, gains)
VF, LOS = "pid_vf", "pid_lookahead_los"


def relation(vf: float, los: float) -> str:
    """ "VF<LOS", "VF=LOS" or "VF>LOS"."""
    return "VF=LOS" if vf == los else ("VF<LOS" if vf < los else "VF>LOS")


def paper_relations(
    by_key: Index, case: str, setting: str, gains: str
) -> list[tuple[str, str, str]]:
    """(column label, metric, the paper's relation) of every statistic of Tables 2–3 that the
    paper prints for both laws (read from the rows of ``setting`` and ``gains``)."""
    checks = []
    for _, mean_key, std_key, _, reading in TABLE_LINES:
        for stat, key in (("mean", mean_key), ("std", std_key)):
            vf = by_key.get((case, VF, key, setting, gains))
            los = by_key.get((case, LOS, key, setting, gains))
            if vf is None or los is None or vf["paper"] is None:
                continue
            checks.append((f"{stat} {reading}", key, relation(vf["paper"], los["paper"])))
    return checks


def our_relations(
    by_key: Index, case: str, setting: str, gains: str, checks: list[tuple[str, str, str]]
) -> tuple[list[str], int, int]:
    """Our relation per check ("–" if not run), marked ✓ / ✗ where the paper's is strict;
    the number of strict checks we agree with and the number of strict checks."""
    cells, agree, total = [], 0, 0
    for _, key, rel in checks:
        vf = by_key.get((case, VF, key, setting, gains))
        los = by_key.get((case, LOS, key, setting, gains))
        if vf is None or los is None:
            cells.append("–")
            continue
        ours = relation(vf["ours"], los["ours"])
        mark = ""
        if rel != "VF=LOS":
            total += 1
            agree += ours == rel
            mark = " ✓" if ours == rel else " ✗"
        cells.append(ours + mark)
    return cells, agree, total
