"""Who copes with which change: a run's change share per change family, with intervals.

``python -m shipgym_baselines.studies.change_shares FOLDER [--split S] [--top N] [--json]``
reads a leaderboard run folder (its ``run.json`` and ``episodes.jsonl``) and prints, per
change family of the split's changing scenarios (default: the catalogue), the competitors
ranked by their change share over that family's trials, each with its stratified-bootstrap
95 % interval (:func:`shipgym_baselines.scoring.change_share.twin_fields`), and the
worked decomposition of one trial (``--trial SCENARIO:SEED CONTROLLER``): the cost ratio,
the nominal ratio, D and the change share.
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from shipgym_baselines.privileged import ORACLE, ORACLE_FROZEN
from shipgym_baselines.records.episodes import read_episodes
from shipgym_baselines.records.runrecord import read_run
from shipgym_baselines.records.trajectories import episode_result
from shipgym_baselines.records.trials import shares_trials, twins_of
from shipgym_baselines.scoring.change_share import (
    NOMINAL,
    SHARE,
    episode_costs,
    trial_cells,
    twin_fields,
)
from shipgym_baselines.scoring.scores import REFERENCE_KIND, scored_episodes
from shipgym_baselines.scoring.splits import suite_families, suite_splits
from shipgym_baselines.scoring.tables import episode_rows, rankable


def run_episodes(folder: str | Path) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """(the run's resolved suite, its scored episodes the ranking reads)."""
    suite = read_run(folder)["suite"]
    results = [episode_result(e, folder) for e in read_episodes(folder)]
    ranked = rankable(episode_rows(results), suite.get("scenario_seeds"), shares_trials(suite))
    return suite, scored_episodes(ranked)


def family_shares(
    folder: str | Path, split: str = "catalogue", top: int = 3
) -> dict[str, list[dict[str, Any]]]:
    """Change family → its ``top`` competitors by change share over the family's changing
    scenarios of ``split`` (rows: controller, kind and the twin fields)."""
    suite, scored = run_episodes(folder)
    twins = twins_of(suite)
    splits = suite_splits(suite)
    families = suite_families(suite)
    kinds = {c["name"]: c["kind"] for c in suite["controllers"]}
    costs = episode_costs(scored)
    by_family: dict[str, list[str]] = {}
    for s, sp in splits.items():
        if sp == split and s in twins:
            by_family.setdefault(families[s], []).append(s)
    out = {}
    for family, scenarios in by_family.items():
        rows = []
        for controller, kind in kinds.items():
            if kind == REFERENCE_KIND:
                continue
            ran = {e["scenario"] for e in scored if e["controller"] == controller}
            tasks = [s for s in scenarios if s in ran]
            if tasks != scenarios:
                continue  # ranked on the whole family only
            fields = twin_fields(scored, controller, tasks, twins, costs=costs)
            if fields[SHARE] is not None:
                rows.append({"controller": controller, "kind": kind, **fields})
        rows.sort(key=lambda r: -r[SHARE])
        out[family] = rows[:top]
    return out


def worked_trial(folder: str | Path, scenario: str, seed: int, controller: str) -> dict:
    """Every cost and ratio of one trial of ``controller`` (module doc)."""
    suite, scored = run_episodes(folder)
    twin = twins_of(suite)[scenario]
    costs = episode_costs(scored)
    runs = [k for (s, c, k, sd) in costs if s == scenario and c == controller and sd == seed]
    cells = trial_cells(costs, controller, scenario, twin, (runs[0], seed))
    if cells is None:
        raise SystemExit(f"no twin episodes of {controller} on {scenario} seed {seed}")
    c = {
        "C_x": costs[(scenario, controller, runs[0], seed)],
        "C_x_twin": costs[(twin, controller, runs[0], seed)],
        "C_oracle": costs[(scenario, ORACLE, None, seed)],
        "C_oracle_twin": costs[(twin, ORACLE, None, seed)],
        "C_frozen": costs[(scenario, ORACLE_FROZEN, None, seed)],
    }
    return {
        "scenario": scenario,
        "twin": twin,
        "seed": seed,
        "controller": controller,
        **c,
        "cost_ratio": c["C_x"] / c["C_oracle"],
        "nominal_ratio": cells[0],
        "D_x": c["C_x"] / c["C_x_twin"],
        "D_oracle": c["C_oracle"] / c["C_oracle_twin"],
        "D_frozen": c["C_frozen"] / c["C_oracle_twin"],
        "headroom": c["C_frozen"] / c["C_oracle"],
        "change_share": cells[1],
    }


def _interval(row: dict, field: str) -> str:
    ci = row.get(f"{field}_ci95")
    value = row[field]
    text = "–" if value is None or not math.isfinite(value) else f"{value:.2f}"
    return text + (f" [{ci[0]:.2f}, {ci[1]:.2f}]" if ci else "")


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder")
    parser.add_argument("--split", default="catalogue")
    parser.add_argument("--top", type=int, default=3)
    parser.add_argument("--trial", nargs=2, metavar=("SCENARIO:SEED", "CONTROLLER"))
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    if args.trial:
        scenario, _, seed = args.trial[0].rpartition(":")
        print(json.dumps(worked_trial(args.folder, scenario, int(seed), args.trial[1]), indent=1))
        return
    shares = family_shares(args.folder, args.split, args.top)
    if args.json:
        print(json.dumps(shares, indent=1))
        return
    print("| family | rank | controller | kind | change share [95 % CI] (trials) | nominal ratio |")
    print("|---|---|---|---|---|---|")
    for family, rows in shares.items():
        for rank, r in enumerate(rows, 1):
            print(
                f"| {family} | {rank} | `{r['controller']}` | {r['kind']} | "
                f"{_interval(r, SHARE)} ({r['share_trials']}) | {_interval(r, NOMINAL)} |"
            )


if __name__ == "__main__":
    main()
