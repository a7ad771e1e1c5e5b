"""The leaderboard's tables as markdown: the ranking, the headroom, the cost ratios, the
per-row table and the generalisation table."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from shipgym.scenarios.families import family_label
from shipgym_baselines.escaping import md_cell
from shipgym_baselines.page.columns import (
    RankingColumn,
    count,
    markdown_columns,
    shown,
)
from shipgym_baselines.page.verdict import verdict
from shipgym_baselines.privileged import ORACLE
from shipgym_baselines.scoring.change_share import (
    CHANGE_SHARE_EXPLAINED,
    NOMINAL,
    SHARE_GRID_EXPLAINED,
)
from shipgym_baselines.scoring.headroom import HEADROOM_EXPLAINED, headroom_grid
from shipgym_baselines.scoring.ranking import (
    PARTIAL,
    SCORE_EXPLAINED,
    is_partial,
    no_ranking,
    resolution_lines,
)
from shipgym_baselines.scoring.splits import TEST_SPLITS, split_label, table_title
from shipgym_baselines.scoring.tables import generalisation, generalisation_splits


def _interval(value: Any, ci: Any, digits: int = 2) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "–"
    text = f"{value:.{digits}f}"
    if ci:
        text += f" [{ci[0]:.{digits}f}, {ci[1]:.{digits}f}]"
    return text


def _table_title(split: str, rows: Sequence[Mapping[str, Any]]) -> str:
    """A ranking table's heading: the split, and its scenarios (every controller's in a
    main table; a partial table's controllers have their own)."""
    base = split.removesuffix(PARTIAL)
    name = table_title(base)
    if is_partial(split):
        return (
            f"{name}: controllers that do not apply to every scenario (each ranked on the "
            "scenarios it applies to; not comparable with the table above)"
        )
    return f"{name} ({len(rows[0]['scenarios'])}, the same for every controller)"


def ranking_tables(board: Sequence[Mapping[str, Any]]) -> list[str]:
    """The ranking as markdown: one table per split, each followed by its partial table; the
    column of the probability of improvement over ``pid_los`` only where a row has one (the
    run has ``pid_los`` and another controller), the columns against the frozen optimum
    (adaptation gain, P(beats it), gap closed) only where a row has them (the run has
    ``oracle_frozen``); the columns: :mod:`.columns`."""
    lines: list[str] = []
    for split in dict.fromkeys(r["split"] for r in board):
        mine = [r for r in board if r["split"] == split]
        columns = shown(markdown_columns(), mine)
        header = [str(c.markdown) for c in columns]
        lines += [
            f"### {_table_title(split, mine)}",
            "",
            "| " + " | ".join(header) + " |",
            "|" + "---|" * len(header),
        ]
        for rank, r in enumerate(mine, start=1):
            cells = [_ranking_cell(c, r, rank) for c in columns]
            lines.append("| " + " | ".join(cells) + " |")
        lines.append("")
    return lines


def _ranking_cell(column: RankingColumn, row: Mapping[str, Any], rank: int) -> str:
    """A ranking row's cell in ``column``: the value and its interval on one line (the
    count of trials after it where the column has one), "–" where there is none."""
    value = column.value(row)
    if column.cell == "rank":
        return str(rank)
    if column.cell in ("name", "text"):
        return md_cell(value)
    if column.cell == "count":
        return str(count(value) or "–")
    text = _interval(value, column.interval(row), column.digits)
    trials = row.get(column.trials) if column.trials else None
    return text + (f" ({trials})" if text != "–" and trials else "")


def ranking_markdown(
    board: list[dict[str, Any]],
    scores: list[dict[str, Any]],
    scenarios: list[str],
    left_out: Sequence[str] = (),
    episodes: Sequence[Mapping[str, Any]] = (),
    note: str = "",
    headroom: Sequence[Mapping[str, Any]] = (),
    shares: Mapping[str, Any] | None = None,
) -> str:
    """The head of ``leaderboard.md``: the score in two sentences, the ranking per split
    (and its partial tables), the resolution, the headroom per ship × change family and the
    controller × scenario table of cost ratios; ``episodes``: the ranked ones (to name the
    scenarios without the oracle's); ``note``: what the run is ranked against
    (:func:`~shipgym_baselines.scoring.comparison.comparison_note`), under the score's
    sentences; ``headroom``: :func:`~shipgym_baselines.scoring.headroom.headroom_table`'s
    rows; ``shares``: the change share per ship × change family
    (:func:`~shipgym_baselines.leaderboard.outputs.share_table`)."""
    lead = verdict(board, episodes, headroom=headroom)
    lines = ["# Leaderboard", "", *([lead, ""] if lead else []), "## Ranking", ""]
    if not board:
        return "\n".join([*lines, no_ranking(scores), ""])
    lines += [SCORE_EXPLAINED, ""]
    if note:
        lines += [note, ""]
    if left_out:
        lines += [f"Left out (episodes missing): {', '.join(left_out)}.", ""]
    with_oracle = {e["scenario"] for e in episodes if e["controller"] == ORACLE}
    unranked = sorted({e["scenario"] for e in episodes} - with_oracle)
    if unranked:
        lines += [
            f"Not ranked (no episodes of {ORACLE}; a run with the references has them): "
            f"{', '.join(unranked)}.",
            "",
        ]
    if any(r.get(NOMINAL) is not None for r in board):
        lines += [CHANGE_SHARE_EXPLAINED, ""]
    lines += ranking_tables(board) + resolution_lines(board) + headroom_markdown(headroom)
    lines += share_markdown(shares or {}) + scores_markdown(board, scores, scenarios)
    return "\n".join(lines)


def headroom_markdown(headroom: Sequence[Mapping[str, Any]]) -> list[str]:
    """The headroom table (:func:`~shipgym_baselines.scoring.headroom.headroom_table` rows): a
    row per ship, a column per change family, each cell the geometric mean of C_frozen / C_oracle
    and its trials; no lines without rows."""
    if not headroom:
        return []
    ships, families, cells = headroom_grid(headroom)
    lines = [
        "### Headroom per ship and change family",
        "",
        HEADROOM_EXPLAINED,
        "",
        "| ship | " + " | ".join(family_label(f) for f in families) + " |",
        "|---|" + "---|" * len(families),
    ]
    for ship in ships:
        row = [md_cell(ship)]
        for family in families:
            found = cells.get((ship, family))
            row.append(f"{found['headroom_gmean']:.2f} ({found['trials']})" if found else "–")
        lines.append("| " + " | ".join(row) + " |")
    return [*lines, ""]


def share_markdown(shares: Mapping[str, Any]) -> list[str]:
    """The change share per ship × change family of the top competitors and the best learned
    agent (:func:`~shipgym_baselines.leaderboard.outputs.share_table`): a row per ship and
    family, a column per controller; no lines without rows."""
    if not shares or not shares["rows"]:
        return []
    controllers = shares["controllers"]
    lines = [
        "### Change share per ship and change family",
        "",
        f"{SHARE_GRID_EXPLAINED} ({split_label(shares['split'])} scenarios).",
        "",
        "| ship | family | trials | " + " | ".join(map(md_cell, controllers)) + " |",
        "|---|---|---|" + "---|" * len(controllers),
    ]
    for row in shares["rows"]:
        cells = [md_cell(row["ship"]), family_label(row["family"]), str(row["trials"])]
        cells += [_interval(row["shares"][c], None) for c in controllers]
        lines.append("| " + " | ".join(cells) + " |")
    return [*lines, ""]


def scores_markdown(
    board: list[dict[str, Any]], scores: list[dict[str, Any]], scenarios: list[str]
) -> list[str]:
    """The controller × scenario table: the oracle's mean cost, then each controller's
    geometric-mean cost ratio [95 % CI] (– where it does not apply)."""
    by_scenario = {s["scenario"]: s for s in scores}
    shown = [s for s in scenarios if s in by_scenario]
    cell = {(c["controller"], s["scenario"]): c for s in scores for c in s["controllers"]}
    controllers = list(dict.fromkeys(r["controller"] for r in board))
    controllers += sorted({c for c, _ in cell} - set(controllers))  # the references
    lines = [
        "## Cost ratio per scenario",
        "",
        f"First row: the mean cost of {ORACLE} on each scenario [95 % interval]. Then each "
        "controller's geometric mean of C / C_oracle over the row's episodes [95 % interval, "
        "stratified over training seeds]; – where the controller does not apply.",
        "",
        "| controller | " + " | ".join(map(md_cell, shown)) + " |",
        "|---|" + "---|" * len(shown),
        f"| {ORACLE} (cost) | "
        + " | ".join(
            _interval(by_scenario[s]["oracle_cost"], by_scenario[s]["oracle_cost_ci95"], 1)
            for s in shown
        )
        + " |",
    ]
    for controller in controllers:
        row = [md_cell(controller)]
        for s in shown:
            found = cell.get((controller, s))
            row.append(
                _interval(found["cost_ratio_gmean"], found["cost_ratio_gmean_ci95"], 3)
                if found
                else "–"
            )
        lines.append("| " + " | ".join(row) + " |")
    return [*lines, ""]


def _fmt(value: Any, std: Any = None) -> str:
    if isinstance(value, float):
        if math.isinf(value):
            return "never" if value > 0 else "-inf"
        if math.isnan(value):
            return "–"
        text = f"{value:.3f}"
        if isinstance(std, float) and math.isfinite(std):
            text += f" ± {std:.3f}"
        return text
    return str(value)


def generalisation_table(rows: list[dict[str, Any]]) -> str:
    """Markdown of :func:`generalisation` (empty when the suite has no held-out or in-range
    scenarios)."""
    if not any(r["split"] in TEST_SPLITS for r in rows):
        return ""
    gen = generalisation(rows)
    splits = generalisation_splits(rows)
    counts = ", ".join(f"{gen[0][f'{s}_scenarios']} {split_label(s)}" for s in splits)
    header = ["controller", "kind"] + [
        f"{what} {split_label(s)}" for what in ("ACE/L", "return", "success") for s in splits
    ]
    title = " vs ".join(split_label(s) for s in splits)
    lines = [
        f"\n## Generalisation: {title} scenarios\n\nMeans over the scenarios "
        f"of each split on which every controller ran ({counts}).\n",
        "| " + " | ".join(header) + " |",
        "|" + "---|" * len(header),
    ]
    for g in gen:
        cells = [md_cell(g["controller"]), md_cell(g["kind"])]
        cells += [
            _fmt(g[f"{split}_{key}"]) for key in ("ace_L", "return", "success") for split in splits
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def markdown_table(rows: list[dict[str, Any]]) -> str:
    """The per-row table: mean ± std over each row's episodes, ACE and return with their
    95 % intervals."""
    head = [
        "scenario",
        "controller",
        "kind",
        "seeds",
        "ACE [m]",
        "ACE 95 % CI",
        "ACE/L",
        "t_c [s]",
        "return",
        "return 95 % CI",
        "rudder travel [rad]",
        "J",
        "success",
        "compute [ms]",
        "training",
    ]
    keys = ["ace_L", "t_c", "return", "rudder_travel", "J", "success", "compute_ms"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        cells = [md_cell(r["scenario"]), md_cell(r["controller"]), md_cell(r["kind"])]
        if not r.get("applies", True):
            lines.append("| " + " | ".join(cells + ["does not apply"] + [""] * 11) + " |")
            continue
        seeds = str(r["seeds"])
        if r.get("training_seeds") and r["episodes"] == r["seeds"] * r["training_seeds"]:
            seeds += f" × {r['training_seeds']} trained"
        elif r.get("training_seeds"):  # the training seeds share the trials
            seeds += f" shared by {r['training_seeds']} trained"
        values = {k: _fmt(r[k], r.get(f"{k}_std")) for k in ("ace", *keys)}
        cells += [seeds, values["ace"], _ci(r.get("ace_ci95")), values["ace_L"], values["t_c"]]
        cells += [values["return"], _ci(r.get("return_ci95"))]
        cells += [values[k] for k in ("rudder_travel", "J", "success", "compute_ms")]
        cost = ""
        if "train_env_steps" in r:
            cost = f"{r['train_env_steps'] / 1e3:.0f} k steps, {r['train_wall_s'] / 60:.1f} min"
        cells.append(cost)
        lines.append("| " + " | ".join(cells) + " |")
    note = (
        "\nMean ± std over each row's episodes (evaluation seeds; × training seeds for a "
        "learned agent), with the 95 % bootstrap interval of the mean (stratified over "
        "training seeds; every metric's is in leaderboard.json as *_ci95). t_c: moment (s of "
        "simulation time) from which |e| stays below the threshold after the first parameter "
        "change; 'never' when it does not. training: env steps and wall time of a learned "
        "agent's training run (mean over its training seeds).\n"
    )
    return "\n".join(lines) + "\n" + note


def _ci(ci: Any) -> str:
    return f"[{ci[0]:.3f}, {ci[1]:.3f}]" if ci else "–"
