"""A run's summary: the numbers the README and the docs quote, in one file.

``shipgym summary RUN_DIR --out FILE`` reads a finished leaderboard folder (``run.json``,
``aggregate.json``, ``episodes.jsonl``) and writes one JSON document:

* the run: suite, commit, status, episodes, wall and CPU seconds (``run.json``);
* per split, the ranked competitors (cost-ratio IQM, nominal ratio and change share, each
  with its 95 % interval, and the failure rate), in the ranking's order;
* per split, what knowing the change is worth (C_frozen / C_oracle, geometric mean) and
  its value per ship × change family;
* the verdict, as the run's page and ``leaderboard.md`` open with it.

A ``shipgym report`` folder (no ``run.json``) is refused: its runs' own folders are the
ones to summarise.

The repository ships the default run's summary as ``docs/run_summary.json``.  The README's
ranking table is :func:`readme_table` of it, and a test fails when the two differ.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from shipgym_baselines.page.verdict import folder_verdict
from shipgym_baselines.scoring.change_share import NOMINAL, SHARE
from shipgym_baselines.scoring.headroom import (
    gmean_headroom,
    headroom_table,
    scenario_ships,
    trial_headroom,
)
from shipgym_baselines.scoring.ranking import is_partial
from shipgym_baselines.scoring.splits import suite_families, suite_splits

#: the summary's layout; bump when a field changes meaning
SUMMARY_VERSION = 1
#: the fields of a ranked row the summary keeps (each ``*_ci95`` beside its estimate)
ROW_FIELDS = (
    "cost_ratio_iqm",
    "cost_ratio_gmean",
    NOMINAL,
    SHARE,
    "gap_closed_iqm",
    "failure_rate",
)
#: the rows of the main split the README shows
README_ROWS = 8
#: the split whose ranking the README shows, and the one beside it
README_SPLIT, README_SIDE = "catalogue", "heldout"


def _row(rank: int, row: Mapping[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {"rank": rank, "controller": row["controller"], "kind": row["kind"]}
    for field in ROW_FIELDS:
        out[field] = row.get(field)
        out[f"{field}_ci95"] = row.get(f"{field}_ci95")
    return out


def ranked_splits(board: Sequence[Mapping[str, Any]]) -> dict[str, list[dict[str, Any]]]:
    """split → its ranked rows (cost-ratio IQM ascending, as the tables rank), main splits
    only (a partial split's rows are left out)."""
    splits: dict[str, list[dict[str, Any]]] = {}
    for split in dict.fromkeys(r["split"] for r in board):
        if is_partial(split):
            continue
        rows = sorted(
            (r for r in board if r["split"] == split),
            key=lambda r: (r["cost_ratio_iqm"], r["controller"]),
        )
        splits[split] = [_row(i, r) for i, r in enumerate(rows, start=1)]
    return splits


def _headroom(
    episodes: Sequence[Mapping[str, Any]],
    suite: Mapping[str, Any],
    split: str,
    scenarios: Sequence[str],
) -> dict[str, Any] | None:
    found = gmean_headroom(trial_headroom(episodes), list(scenarios))
    if found is None:
        return None
    worth, trials = found
    ships = scenario_ships(suite["scenarios"])
    cells = headroom_table(episodes, ships, suite_families(suite), suite_splits(suite), split)
    return {
        "gmean": worth,
        "trials": trials,
        "cells": [{k: c[k] for k in ("ship", "family", "trials", "headroom_gmean")} for c in cells],
    }


def run_summary(folder: str | os.PathLike) -> dict[str, Any]:
    """The summary of the leaderboard run in ``folder`` (module doc).  Raises
    FileNotFoundError naming the missing file of a folder that is not a finished run."""
    from shipgym_baselines.records.episodes import read_episodes
    from shipgym_baselines.records.runrecord import RUN_FILE, read_run

    folder = Path(folder)
    for name in (RUN_FILE, "aggregate.json"):
        if not (folder / name).is_file():
            raise FileNotFoundError(f"{folder}: no {name}: not a leaderboard run folder")
    record = read_run(folder)
    board = json.loads((folder / "aggregate.json").read_text(encoding="utf-8"))
    episodes = read_episodes(folder)
    suite = record["suite"]
    splits = ranked_splits(board)
    scenarios = {
        split: next(r["scenarios"] for r in board if r["split"] == split) for split in splits
    }
    commit = record.get("git_commit")
    return {
        "summary_version": SUMMARY_VERSION,
        "suite": suite.get("name"),
        "commit": commit[:7] if isinstance(commit, str) else None,
        "status": record.get("status"),
        "episodes": len(episodes),
        "wall_s": record.get("wall_s"),
        "cpu_s": record.get("cpu_s"),
        "end_time": record.get("end_time"),
        "splits": {
            split: {
                "competitors": len(rows),
                "scenarios": len(scenarios[split]),
                "rows": rows,
                "headroom": _headroom(episodes, suite, split, scenarios[split]),
            }
            for split, rows in splits.items()
        },
        "verdict": folder_verdict(folder),
    }


def _cell(row: Mapping[str, Any], field: str, digits: int) -> str:
    value, ci = row.get(field), row.get(f"{field}_ci95")
    if value is None:
        return "–"
    text = f"{value:.{digits}f}"
    return text + (f" [{ci[0]:.{digits}f}, {ci[1]:.{digits}f}]" if ci else "")


def readme_table(summary: Mapping[str, Any], rows: int = README_ROWS) -> str:
    """The README's ranking table: the first ``rows`` of the catalogue split with their cost
    ratio, nominal ratio and change share, and each one's held-out IQM and rank."""
    splits = summary["splits"]
    main = splits[README_SPLIT]["rows"][:rows]
    side = {r["controller"]: r for r in splits.get(README_SIDE, {}).get("rows", [])}
    lines = [
        "| rank | controller | kind | cost ratio IQM [95 % CI] | nominal ratio [95 % CI] "
        "| change share [95 % CI] | held-out IQM (rank) |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in main:
        other = side.get(r["controller"])
        held = f"{other['cost_ratio_iqm']:.3f} ({other['rank']})" if other else "–"
        lines.append(
            f"| {r['rank']} | {r['controller']} | {r['kind']} | {_cell(r, 'cost_ratio_iqm', 3)} "
            f"| {_cell(r, NOMINAL, 2)} | {_cell(r, SHARE, 2)} | {held} |"
        )
    return "\n".join(lines)


__all__ = ["SUMMARY_VERSION", "ranked_splits", "readme_table", "run_summary"]
