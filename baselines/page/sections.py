"""The page's tables: the ranking per split, the controller × scenario cost ratios, the
headroom per ship × change family and the long per-row table
(:mod:`~shipgym_baselines.page.html`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from shipgym.scenarios.families import family_label
from shipgym_baselines.learned.curves import SEED_FLAG_RULE, flag_text
from shipgym_baselines.page.cells import (
    Td,
    esc,
    finite_number,
    html_table,
    leading_number,
    name_cell,
    number_text,
    text_cell,
    value_cell,
)
from shipgym_baselines.page.columns import RankingColumn, count, page_columns, shown
from shipgym_baselines.page.figures import anchor
from shipgym_baselines.privileged import ORACLE, ORACLE_FROZEN
from shipgym_baselines.scoring.change_share import SHARE_GRID_EXPLAINED
from shipgym_baselines.scoring.headroom import HEADROOM_EXPLAINED, headroom_grid
from shipgym_baselines.scoring.ranking import PARTIAL, is_partial, resolution_lines
from shipgym_baselines.scoring.splits import split_label, table_title

#: the long table's metric columns: key → header (with units)
ROW_METRICS = {
    "ace": "ACE [m]",
    "ace_L": "ACE/L [–]",
    "t_c": "t_c [s]",
    "return": "return [–]",
    "cost": "cost [–]",
    "rudder_travel": "rudder travel [rad]",
    "J": "J [–]",
    "success": "success [–]",
    "compute_ms": "compute [ms]",
}


def ranking_tables(aggregate: Sequence[Mapping[str, Any]]) -> str:
    """One table per split of the ``aggregate.json`` rows, in their order (ranked by the
    cost ratio's IQM, lowest first); a split's partial table is titled as such.  A table
    whose rows have no probability of improvement (``pid_los`` not ranked there) has no
    such column; a row without one (``pid_los`` itself) shows "–".  The columns against
    the frozen optimum (adaptation gain, P(beats it), gap closed) only where a row has
    them; the columns: :mod:`.columns`."""
    parts = []
    for split in dict.fromkeys(r["split"] for r in aggregate):
        rows = [r for r in aggregate if r["split"] == split]
        base = split.removesuffix(PARTIAL)
        title = table_title(base)
        if is_partial(split):
            title += ": controllers that do not apply to every scenario (each on its own)"
        table = _ranking_table(f"ranking-{split}", rows, page_columns())
        parts.append(f"<div><h3>{esc(title)}</h3>{table}")
        if any(c.long for c in shown(page_columns(long=True), rows)):
            long = _ranking_table(f"ranking-long-{split}", rows, page_columns(long=True))
            parts.append(
                "<details><summary>Every field of the ranking (against the frozen optimum: "
                f"C_frozen / C, P(C &lt; C_frozen), gap closed)</summary>{long}</details>"
            )
        parts.append("</div>")
    lines = resolution_lines(aggregate) + flag_lines(aggregate)
    notes = "".join(f'<p class="note">{esc(line)}</p>' for line in lines)
    return '<div class="splits">' + "".join(parts) + "</div>" + notes


def flag_lines(aggregate: Sequence[Mapping[str, Any]]) -> list[str]:
    """The note on the learned rows' flagged training seeds (⚑ in the ranking), with the
    rule; none without a flagged seed."""
    flagged = {r["controller"]: r["seed_flags"] for r in aggregate if r.get("seed_flags")}
    if not flagged:
        return []
    named = "; ".join(
        f"{name}: " + ", ".join(flag_text(f) for f in flags) for name, flags in flagged.items()
    )
    return [f"⚑ flagged training seeds ({SEED_FLAG_RULE}): {named}."]


def _ranking_table(
    table_id: str, rows: Sequence[Mapping[str, Any]], columns: Sequence[RankingColumn]
) -> str:
    """One split's ranking table of ``columns`` (those some row has)."""
    mine = shown(columns, rows)
    heads = [(c.name, esc(c.page), _sort_kind(c)) for c in mine]
    body = [[_ranking_cell(c, r, rank) for c in mine] for rank, r in enumerate(rows, 1)]
    return html_table(table_id, heads, body, compact=True, cls="ranking")


def _sort_kind(column: RankingColumn) -> str:
    """How the page sorts a ranking column (:func:`~shipgym_baselines.page.cells._head`): text, or
    numbers (``lower``:
    ascending on the first click)."""
    if column.cell in ("name", "text"):
        return "text"
    return "lower" if column.lower else "number"


def _ranking_cell(column: RankingColumn, row: Mapping[str, Any], rank: int) -> Td:
    """A ranking row's cell in ``column``: the value, its interval below it (the count of
    trials after it where the column has one)."""
    if column.cell == "rank":
        return Td(str(rank), -rank, rank)  # best-first on the first click
    if column.cell == "name":
        td = name_cell(row["controller"])
        flags = row.get("seed_flags")
        if not flags:
            return td
        title = "; ".join(flag_text(f) for f in flags)
        mark = f' <span class="flag" title="{esc(title)}">⚑{len(flags)}</span>'
        return td._replace(html=td.html + mark)
    if column.cell == "text":
        return text_cell(row.get(column.key, ""))
    if column.cell == "count":
        return value_cell(count(column.value(row)))
    td = value_cell(column.value(row), column.interval(row))
    trials = row.get(column.trials) if column.trials else None
    if column.value(row) is None or not trials:
        return td
    return td._replace(html=f"{td.html}<i>{esc(trials)} trials</i>")


def _controller_order(
    rows: Sequence[Mapping[str, Any]],
    aggregate: Sequence[Mapping[str, Any]],
    cells: Mapping[tuple[str, str], Mapping[str, Any]],
) -> list[str]:
    """Controllers by the first split's ranking, then any other in the order they appear."""
    names = [r["controller"] for r in aggregate if r["split"] == aggregate[0]["split"]]
    names += [r["controller"] for r in aggregate]
    names += [r["controller"] for r in rows] + [c for c, _ in cells]
    return list(dict.fromkeys(names))


def score_table(
    rows: Sequence[Mapping[str, Any]],
    aggregate: Sequence[Mapping[str, Any]],
    scores: Sequence[Mapping[str, Any]],
) -> str:
    """The sortable controller × scenario table (``id="scores"``): each controller's IQM cost
    ratio per split, then its geometric-mean cost ratio with interval per scenario (whose
    header gives the oracle's mean cost); "n/a" where it does not apply."""
    scenarios = list(dict.fromkeys([r["scenario"] for r in rows] + [s["scenario"] for s in scores]))
    split_of = {r["scenario"]: r.get("split", "") for r in rows}
    split_of.update({s["scenario"]: s.get("split", "") for s in scores})
    splits = list(dict.fromkeys(r["split"] for r in aggregate))
    cell = {(c["controller"], s["scenario"]): c for s in scores for c in s["controllers"]}
    oracle = {s["scenario"]: s for s in scores}
    iqm = {(r["controller"], r["split"]): r for r in aggregate}
    kinds = {r["controller"]: r.get("kind", "") for r in [*rows, *aggregate]}
    kinds.update({c: v.get("kind", "") for (c, _), v in cell.items()})
    not_applicable = {
        (r["controller"], r["scenario"]) for r in rows if r.get("applies", True) is False
    }
    columns = [("controller", "controller", "text"), ("kind", "kind", "text")]
    columns += [(f"iqm:{sp}", f"IQM<br>{esc(sp)}", "lower") for sp in splits]
    columns += [
        (s, f'<a href="#fig-{esc(anchor(s))}">{esc(s)}</a><br><small>{esc(split_of[s])}'
         f"{_oracle_cost(oracle.get(s))}</small>", "lower")
        for s in scenarios
    ]  # fmt: skip
    body = []
    for name in _controller_order(rows, aggregate, cell):
        if name == ORACLE:
            continue
        tds = [name_cell(name), text_cell(kinds.get(name, ""))]
        for sp in splits:
            agg = iqm.get((name, sp), {})
            tds.append(value_cell(agg.get("cost_ratio_iqm"), agg.get("cost_ratio_iqm_ci95")))
        for s in scenarios:
            if (name, s) in not_applicable:
                tds.append(Td("n/a", attrs=' class="na" title="does not apply"'))
            else:
                sc = cell.get((name, s), {})
                tds.append(
                    value_cell(
                        sc.get("cost_ratio_gmean"), sc.get("cost_ratio_gmean_ci95"), shade=True
                    )
                )
        body.append(tds)
    return html_table("scores", columns, body)


def _oracle_cost(entry: Mapping[str, Any] | None) -> str:
    """A scenario header's line on the oracle's mean cost (the ratios' denominator), and
    the frozen optimum's where it ran."""
    if not entry:
        return ""
    text = f"<br>{esc(ORACLE)} cost {esc(number_text(entry.get('oracle_cost')))}"
    if entry.get("oracle_frozen_cost") is not None:
        text += f"<br>{esc(ORACLE_FROZEN)} cost {esc(number_text(entry['oracle_frozen_cost']))}"
    return text


def headroom_html(headroom: Sequence[Mapping[str, Any]]) -> str:
    """The headroom table (:func:`shipgym_baselines.scoring.headroom.headroom_table` rows): one
    row per ship, one column per change family, each cell the geometric mean of C_frozen / C_oracle
    over its trials (how many beside it); empty without rows."""
    if not headroom:
        return ""
    ships, families, cells = headroom_grid(headroom)
    columns = [("ship", "ship", "text")]
    columns += [(f, esc(family_label(f)), "number") for f in families]
    body = []
    for ship in ships:
        tds = [text_cell(ship)]
        for family in families:
            found = cells.get((ship, family))
            if found is None:
                tds.append(Td("–"))
                continue
            trials = found["trials"]
            value = finite_number(found["headroom_gmean"])
            text = number_text(found["headroom_gmean"])
            small = f"<i>{trials} trial{'s' if trials != 1 else ''}</i>"
            tds.append(Td(f"{esc(text)}{small}", value, leading_number(text)))
        body.append(tds)
    return (
        '<h3 id="headroom">Headroom per ship and change family</h3>'
        f'<p class="note">{esc(HEADROOM_EXPLAINED)}</p>'
        f"{html_table('headroom', columns, body, compact=True)}"
    )


def share_html(shares: Mapping[str, Any]) -> str:
    """The change share per ship × change family of the top competitors and the best learned
    agent (:func:`~shipgym_baselines.leaderboard.outputs.share_table`), sortable; empty
    without rows."""
    if not shares or not shares["rows"]:
        return ""
    controllers = shares["controllers"]
    columns = [("ship", "ship", "text"), ("family", "family", "text")]
    columns += [("trials", "trials", "number")]
    columns += [(f"share:{c}", esc(c), "number") for c in controllers]
    body = []
    for row in shares["rows"]:
        tds = [text_cell(row["ship"]), text_cell(family_label(row["family"]))]
        tds += [value_cell(row["trials"])]
        tds += [value_cell(row["shares"][c]) for c in controllers]
        body.append(tds)
    note = f"{SHARE_GRID_EXPLAINED} ({split_label(shares['split'])} scenarios)."
    return (
        '<h3 id="change-share">Change share per ship and change family</h3>'
        f'<p class="note">{esc(note)}</p>{html_table("change-share", columns, body, compact=True)}'
    )


def row_table(rows: Sequence[Mapping[str, Any]]) -> str:
    """The long table: one row per (scenario, controller), every metric with its interval
    (``*_ci95``, else ± std)."""
    metrics = [k for k in ROW_METRICS if any(k in r for r in rows)]
    columns = [
        ("controller", "controller", "text"),
        ("scenario", "scenario", "text"),
        ("split", "split", "text"),
        ("kind", "kind", "text"),
        ("seeds", "seeds", "number"),
        ("training_seeds", "training seeds", "number"),
    ] + [(k, esc(ROW_METRICS[k]), "number") for k in metrics]
    body = []
    for r in rows:
        tds = [name_cell(r["controller"])] + [
            text_cell(r.get(k, "")) for k in ("scenario", "split", "kind")
        ]
        tds += [value_cell(r.get("seeds")), value_cell(r.get("training_seeds"))]
        if r.get("applies", True) is False:
            attrs = f' class="na" colspan="{len(metrics)}" style="text-align:left"'
            tds.append(Td("does not apply", attrs=attrs))
        else:
            tds += [value_cell(r.get(k), r.get(f"{k}_ci95"), r.get(f"{k}_std")) for k in metrics]
        body.append(tds)
    return html_table("rows", columns, body)
