"""``leaderboard.html``: the leaderboard as one self-contained page.

It opens with the run's verdict in two sentences (:mod:`shipgym_baselines.leaderboard.verdict`).
No network: the style sheet and the script are inline and every figure is embedded as a
data URI (the SVG copy where there is one, else the PNG).  The page holds, in order:

1. the **ranking** per split (``aggregate.json`` rows: IQM and geometric mean of the cost
   ratio C / C_oracle, the probability of improvement over ``pid_los`` and the failure
   rate, 95 % intervals; a split's partial table below it), the resolution of each split,
   the headroom per ship × change family (what knowing the change is worth: C_frozen /
   C_oracle, :func:`shipgym_baselines.leaderboard.ranking.headroom_table`) and the figures
   (``ranking_*`` / ``profile_*`` of :mod:`shipgym_baselines.leaderboard.figures`);
2. the **controller × scenario table**: the oracle's mean cost, then each controller's
   geometric-mean cost ratio with its interval (``scenario_scores.json``,
   :func:`shipgym_baselines.leaderboard.ranking.scenario_scores`), shaded from 1 (the oracle, green)
   to ≥ 4 (red);
3. the **scenario figures** (``scenario_*``), one per scenario;
4. the **long per-row table** (``leaderboard.json`` rows), collapsed.

Every table sorts on a click on its header (numbers best-first: cost ratios and failure
rates ascending, others descending; text ascending; a second click reverses; empty cells
stay last).  The page sorts its
controller × scenario table on load from the address's hash: ``#sort=<column>`` (the first
click's order) or ``#sort=<column>:asc`` / ``:desc``, where a column is ``controller``,
``kind``, ``iqm:<split>`` or a scenario's name.  Every text from the data (controller
names are user input: plug-ins) is HTML-escaped.

:func:`write_html` ``(out_dir, rows, aggregate, scores, figures, title=…, subtitle=None,
verdict=None, note="", headroom=())``
writes the page and returns its path.
"""

from __future__ import annotations

import base64
import gzip
import html
import io
import itertools
import json
import math
import re
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any, NamedTuple

from shipgym_baselines.leaderboard.columns import RankingColumn, count, page_columns, shown
from shipgym_baselines.leaderboard.figures import (
    LEARNING_CURVES_STEM,
    LEGEND_KEY,
    LEGEND_TOP_KEY,
    figure_stem,
)
from shipgym_baselines.leaderboard.ranking import (
    HEADROOM_EXPLAINED,
    ORACLE,
    ORACLE_FROZEN,
    PARTIAL,
    SCORE_EXPLAINED,
    headroom_grid,
    is_partial,
    no_ranking,
    resolution_lines,
)
from shipgym_baselines.leaderboard.ranking import PROB as PROB  # re-exported
from shipgym_baselines.leaderboard.splits import SPLIT_TITLES as SPLIT_TITLES  # re-exported
from shipgym_baselines.leaderboard.splits import table_title
from shipgym_baselines.leaderboard.style import controller_style
from shipgym_baselines.records.outfiles import write_bytes

PAGE_FILE = "leaderboard.html"
#: most significant digits of a cell's sort key (``data-sort``)
SORT_DIGITS = 7
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

_CSS = """
body{font:14px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;margin:24px;
color:#1b1f24;background:#fff}
h1{font-size:24px;margin:0 0 4px}h2{font-size:19px;margin:28px 0 8px;border-bottom:1px solid
#d0d7de;padding-bottom:4px}h3{font-size:16px;margin:18px 0 6px}
p.note{color:#57606a;margin:4px 0 10px;max-width:75em}
.scroll{overflow-x:auto;max-width:100%;border:1px solid #d0d7de;border-radius:4px}
table{border-collapse:collapse;font-variant-numeric:tabular-nums}
th,td{padding:3px 8px;border-bottom:1px solid #eaeef2;text-align:right;white-space:nowrap}
th{background:#f6f8fa;position:sticky;top:0;cursor:pointer;user-select:none;z-index:1}
th[aria-sort=ascending]::after{content:" \\25B2"}th[aria-sort=descending]::after{content:" \\25BC"}
td:first-child,th:first-child{text-align:left;position:sticky;left:0;background:#fff;z-index:2}
th:first-child{background:#f6f8fa;z-index:3}
th.text,table.ranking td:nth-child(3),#scores td:nth-child(2),#rows td:nth-child(-n+4){
text-align:left}
td i{color:#57606a;display:block;font-size:11px;font-style:normal}
table.compact td i{display:inline;margin-left:6px}
.splits{display:flex;flex-wrap:wrap;gap:8px 24px;align-items:flex-start}
td.na{color:#8c959f;font-style:italic}
td:first-child span{display:inline-block;width:22px;height:0;border-top-width:3px;
margin-right:6px;vertical-align:middle}
figure{margin:10px 0 22px}figure img{max-width:100%;height:auto;border:1px solid #eaeef2}
figcaption{color:#57606a;font-size:12px}
.legend{display:flex;flex-wrap:wrap;gap:2px 18px;font-size:12px;margin:4px 0}
.legend ul{list-style:none;margin:0;padding:0}.legend b{font-weight:600}
.legend span{display:inline-block;width:22px;height:0;border-top-width:2px;margin-right:6px;
vertical-align:middle}
details>summary{cursor:pointer;font-weight:600;margin:8px 0}
"""

_JS = """
(function () {
  // a packed table body (the long table, deflated for a lighter page): its rows, unpacked in place
  document.querySelectorAll("tbody[data-gzip]").forEach(function (body) {
    var bin = atob(body.getAttribute("data-gzip")), bytes = new Uint8Array(bin.length);
    for (var i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
    var rows = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("gzip"));
    new Response(rows).text().then(function (text) {
      body.innerHTML = text;
      body.removeAttribute("data-gzip");
    });
  });
  function key(row, col, numeric) {  // data-sort, else the cell's text
    var cell = row.cells[col];
    if (!cell) return null;
    var v = cell.getAttribute("data-sort");
    if (v === null) v = cell.textContent;
    if (v === "") return null;
    if (!numeric) return v.toLowerCase();
    var x = parseFloat(v);
    return isNaN(x) ? null : x;
  }
  function sortTable(table, col, dir) {
    var head = table.tHead.rows[0].cells, body = table.tBodies[0];
    var numeric = head[col].getAttribute("data-type") === "number";
    var rows = Array.prototype.slice.call(body.rows);
    rows.sort(function (a, b) {
      var x = key(a, col, numeric), y = key(b, col, numeric);
      if (x === null || y === null) return (x === null) - (y === null);
      var r = numeric ? x - y : (x < y ? -1 : x > y ? 1 : 0);
      return dir === "descending" ? -r : r;
    });
    rows.forEach(function (r) { body.appendChild(r); });
    for (var i = 0; i < head.length; i++) head[i].removeAttribute("aria-sort");
    head[col].setAttribute("aria-sort", dir);
  }
  function firstOrder(th) {
    if (th.getAttribute("data-first")) return th.getAttribute("data-first");
    return th.getAttribute("data-type") === "number" ? "descending" : "ascending";
  }
  document.querySelectorAll("table.sortable").forEach(function (table) {
    var head = table.tHead.rows[0].cells;
    Array.prototype.forEach.call(head, function (th, col) {
      th.title = "click to sort (again to reverse)";
      th.addEventListener("click", function (ev) {
        if (ev.target.closest && ev.target.closest("a")) return;  // a link, not a sort
        var first = firstOrder(th), now = th.getAttribute("aria-sort");
        sortTable(table, col, now === first ? (first === "ascending" ? "descending"
                                                                   : "ascending") : first);
      });
    });
  });
  var m = /^#sort=(.+)$/.exec(window.location.hash);
  var table = document.getElementById("scores");
  if (m && table) {
    var want = decodeURIComponent(m[1]), dir = null, tail = /:(asc|desc)$/.exec(want);
    if (tail) { dir = tail[1] === "asc" ? "ascending" : "descending";
                want = want.slice(0, -tail[0].length); }
    Array.prototype.forEach.call(table.tHead.rows[0].cells, function (th) {
      if (th.getAttribute("data-key") !== want) return;
      th.click();
      if (dir && th.getAttribute("aria-sort") !== dir) th.click();
    });
  }
})();
"""


def _e(text: Any) -> str:
    """HTML-escaped text (quotes too: safe in attributes)."""
    return html.escape(str(text), quote=True)


def _finite(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    return float(value) if math.isfinite(value) else None


def _number(value: Any) -> str:
    """A number for a cell: 3 significant decimals, ∞ as "never" (t_c), none as "–"."""
    if isinstance(value, int | float) and not isinstance(value, bool):
        if math.isinf(value):
            return "never" if value > 0 else "−∞"
        if math.isnan(value):
            return "–"
        return f"{value:.3f}" if isinstance(value, float) else str(value)
    return "–" if value is None else str(value)


def _interval(ci: Any) -> str:
    if isinstance(ci, Sequence) and len(ci) == 2 and all(_finite(v) is not None for v in ci):
        return f"[{ci[0]:.3f}, {ci[1]:.3f}]"
    return ""


class _Td(NamedTuple):
    """A body cell: its inner HTML, its sort value (a finite number; None sorts last; for a
    text cell unused: the script sorts by the text), the number its text starts with (what
    the script reads without ``data-sort``) and further attributes."""

    html: str
    value: float | None = None
    shown: float | None = None
    attrs: str = ""


def _leading_number(text: str) -> float | None:
    """The number ``parseFloat`` reads at the start of a cell's text (None: NaN)."""
    match = _LEADING_NUMBER.match(text)
    return float(match.group(0)) if match else None


_LEADING_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")


def _cell(value: Any, ci: Any = None, std: Any = None, shade: bool = False) -> _Td:
    """A numeric cell: the value, its interval (or ± std) below, the value as sort key."""
    sort = _finite(value)
    extra = _interval(ci) or (f"± {std:.3f}" if _finite(std) is not None else "")
    style = f' style="background:{_shade(sort)}"' if shade and sort is not None else ""
    small = f"<i>{_e(extra)}</i>" if extra else ""
    text = _number(value)
    return _Td(f"{_e(text)}{small}", sort, _leading_number(text), style)


def _shade(ratio: float) -> str:
    """Background of a cost-ratio cell: green (≤ 1, the oracle) → yellow → red (≥ 4), on a
    log scale."""
    t = min(max(math.log(ratio) / math.log(4.0), 0.0), 1.0) if ratio > 0 else 0.0
    return f"hsl({120 * (1.0 - t):.0f},65%,88%)"


def _text_cell(text: Any) -> _Td:
    return _Td(_e(text))


def _swatch_class(name: str) -> tuple[str, str]:
    """(class, CSS rule) of a controller's swatch: its line's colour and style."""
    style = controller_style(name)
    border = {"-": "solid", "--": "dashed", "-.": "dashed", ":": "dotted"}.get(
        style.linestyle, "solid"
    )
    cls = "k" + "".join(c for c in style.color if c.isalnum()).lower() + border[:2]
    return cls, f".{cls}{{border-top-style:{border};border-top-color:{_e(style.color)}}}"


def swatch_css(names: Iterable[str]) -> str:
    """The swatch classes of these controllers, each rule once."""
    return "".join(sorted({_swatch_class(n)[1] for n in names}))


def _name_cell(name: str) -> _Td:
    return _Td(f'<span class="{_swatch_class(name)[0]}"></span>{_e(name)}')


def _head(columns: Iterable[tuple[str, str, str]]) -> str:
    """``<thead>`` of (key, header text, "number" | "lower" | "text") columns (``lower``: a
    number that is better lower, sorted ascending on the first click); the first is the
    name."""
    cells = []
    for i, (key, text, kind) in enumerate(columns):
        first = ' data-first="ascending"' if kind == "lower" else ""
        cells.append(
            f'<th data-key="{_e(key)}" data-type="{"number" if kind == "lower" else kind}"'
            + first
            + (' class="text"' if kind == "text" and i else "")
            + f">{text}</th>"
        )
    return "<thead><tr>" + "".join(cells) + "</tr></thead>"


def _same_order(values: Sequence[float | None], keys: Sequence[float | None]) -> bool:
    """Whether ``keys`` sort the cells as ``values`` do: equal values equal keys, distinct
    ones in the same order, None (last) where None."""
    pairs = sorted({(v, k) for v, k in zip(values, keys, strict=True) if v is not None})
    if any((v is None) != (k is None) for v, k in zip(values, keys, strict=True)):
        return False
    for (v0, k0), (v1, k1) in itertools.pairwise(pairs):
        if v0 == v1 or k0 is None or k1 is None or not k0 < k1:
            return False
    return True


def sort_keys(values: Sequence[float | None], shown: Sequence[float | None]) -> list[str] | None:
    """A numeric column's ``data-sort`` keys: None where the numbers its cells' texts start
    with sort them as their values do (the script reads the text), else each value at the
    fewest significant digits that keep the values' order and ties, at most 7 (values that
    differ only beyond the 7th digit tie, and keep their order in the page; "" for none)."""
    if _same_order(values, shown):
        return None
    for digits in range(1, SORT_DIGITS + 1):
        keys = ["" if v is None else f"{v:.{digits}g}" for v in values]
        if _same_order(values, [float(k) if k else None for k in keys]):
            break
    return keys


def _table(
    table_id: str,
    columns: Sequence[tuple[str, str, str]],
    body: Sequence[Sequence[_Td]],
    compact: bool = False,
    cls: str = "",
) -> str:
    """A sortable table; ``compact``: intervals beside the values, not below.  A numeric
    column carries ``data-sort`` keys only where its texts would sort otherwise
    (:func:`sort_keys`); the script sorts a text column by its texts."""
    keys: dict[int, list[str]] = {}
    for col, (_, _, kind) in enumerate(columns):
        if kind == "text":
            continue
        cells = [(row, row[col]) for row in body if col < len(row)]
        found = sort_keys([c.value for _, c in cells], [c.shown for _, c in cells])
        if found is not None:
            keys[col] = found
    where = {col: 0 for col in keys}
    rows = []
    for row in body:
        tds = []
        for col, td in enumerate(row):
            sort = ""
            if col in keys:
                sort = f' data-sort="{keys[col][where[col]]}"'
                where[col] += 1
            tds.append(f"<td{sort}{td.attrs}>{td.html}</td>")
        rows.append("<tr>" + "".join(tds) + "</tr>")
    classes = " ".join(c for c in ("sortable", "compact" if compact else "", cls) if c)
    return (
        f'<div class="scroll"><table class="{classes}" id="{_e(table_id)}">{_head(columns)}'
        f"<tbody>{''.join(rows)}</tbody></table></div>"
    )


def packed_body(table: str) -> str:
    """``table`` (:func:`_table`'s HTML) with its body's rows deflated into the body's
    ``data-gzip`` attribute (gzip, base64; the page's script unpacks them with the
    browser's ``DecompressionStream``): the long table's markup is ≈ 6 times lighter."""
    head, sep, rest = table.partition("<tbody>")
    inner, end, tail = rest.partition("</tbody>")
    if not sep or not end:
        raise ValueError("packed_body: the table has no <tbody>")
    packed = gzip.compress(inner.encode("utf-8"), compresslevel=9, mtime=0)
    data = base64.b64encode(packed).decode("ascii")
    return f'{head}<tbody data-gzip="{data}"></tbody>{tail}'


def unpacked_body(table: str) -> str:
    """The inverse of :func:`packed_body` (tests, and readers of the page's source)."""
    match = re.search(r'<tbody data-gzip="([A-Za-z0-9+/=]*)"></tbody>', table)
    if match is None:
        return table
    inner = gzip.decompress(base64.b64decode(match.group(1))).decode("utf-8")
    return table[: match.start()] + f"<tbody>{inner}</tbody>" + table[match.end() :]


# ----------------------------------------------------------------------------- sections
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
        mine = shown(page_columns(), rows)
        columns = [(c.name, _e(c.page), _sort_kind(c)) for c in mine]
        body = [[_ranking_cell(c, r, rank) for c in mine] for rank, r in enumerate(rows, 1)]
        base = split.removesuffix(PARTIAL)
        title = table_title(base)
        if is_partial(split):
            title += ": controllers that do not apply to every scenario (each on its own)"
        table = _table(f"ranking-{split}", columns, body, compact=True, cls="ranking")
        parts.append(f"<div><h3>{_e(title)}</h3>{table}</div>")
    notes = "".join(f'<p class="note">{_e(line)}</p>' for line in resolution_lines(aggregate))
    return '<div class="splits">' + "".join(parts) + "</div>" + notes


def _sort_kind(column: RankingColumn) -> str:
    """How the page sorts a ranking column (:func:`_head`): text, or numbers (``lower``:
    ascending on the first click)."""
    if column.cell in ("name", "text"):
        return "text"
    return "lower" if column.lower else "number"


def _ranking_cell(column: RankingColumn, row: Mapping[str, Any], rank: int) -> _Td:
    """A ranking row's cell in ``column``: the value, its interval below it (the count of
    trials after it where the column has one)."""
    if column.cell == "rank":
        return _Td(str(rank), -rank, rank)  # best-first on the first click
    if column.cell == "name":
        return _name_cell(row["controller"])
    if column.cell == "text":
        return _text_cell(row.get(column.key, ""))
    if column.cell == "count":
        return _cell(count(column.value(row)))
    td = _cell(column.value(row), column.interval(row))
    trials = row.get(column.trials) if column.trials else None
    if column.value(row) is None or not trials:
        return td
    return td._replace(html=f"{td.html}<i>{_e(trials)} trials</i>")


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
    columns += [(f"iqm:{sp}", f"IQM<br>{_e(sp)}", "lower") for sp in splits]
    columns += [
        (s, f'<a href="#fig-{_e(_anchor(s))}">{_e(s)}</a><br><small>{_e(split_of[s])}'
         f"{_oracle_cost(oracle.get(s))}</small>", "lower")
        for s in scenarios
    ]  # fmt: skip
    body = []
    for name in _controller_order(rows, aggregate, cell):
        if name == ORACLE:
            continue
        tds = [_name_cell(name), _text_cell(kinds.get(name, ""))]
        for sp in splits:
            agg = iqm.get((name, sp), {})
            tds.append(_cell(agg.get("cost_ratio_iqm"), agg.get("cost_ratio_iqm_ci95")))
        for s in scenarios:
            if (name, s) in not_applicable:
                tds.append(_Td("n/a", attrs=' class="na" title="does not apply"'))
            else:
                sc = cell.get((name, s), {})
                tds.append(
                    _cell(sc.get("cost_ratio_gmean"), sc.get("cost_ratio_gmean_ci95"), shade=True)
                )
        body.append(tds)
    return _table("scores", columns, body)


def _oracle_cost(entry: Mapping[str, Any] | None) -> str:
    """A scenario header's line on the oracle's mean cost (the ratios' denominator), and
    the frozen optimum's where it ran."""
    if not entry:
        return ""
    text = f"<br>{_e(ORACLE)} cost {_e(_number(entry.get('oracle_cost')))}"
    if entry.get("oracle_frozen_cost") is not None:
        text += f"<br>{_e(ORACLE_FROZEN)} cost {_e(_number(entry['oracle_frozen_cost']))}"
    return text


def headroom_html(headroom: Sequence[Mapping[str, Any]]) -> str:
    """The headroom table (:func:`shipgym_baselines.leaderboard.ranking.headroom_table` rows): one
    row per ship, one column per change family, each cell the geometric mean of C_frozen / C_oracle
    over its trials (how many beside it); empty without rows."""
    if not headroom:
        return ""
    ships, families, cells = headroom_grid(headroom)
    columns = [("ship", "ship", "text")]
    columns += [(f, _e(f.replace("_", " ")), "number") for f in families]
    body = []
    for ship in ships:
        tds = [_text_cell(ship)]
        for family in families:
            found = cells.get((ship, family))
            if found is None:
                tds.append(_Td("–"))
                continue
            trials = found["trials"]
            value = _finite(found["headroom_gmean"])
            text = _number(found["headroom_gmean"])
            small = f"<i>{trials} trial{'s' if trials != 1 else ''}</i>"
            tds.append(_Td(f"{_e(text)}{small}", value, _leading_number(text)))
        body.append(tds)
    return (
        '<h3 id="headroom">Headroom per ship and change family</h3>'
        f'<p class="note">{_e(HEADROOM_EXPLAINED)}</p>'
        f"{_table('headroom', columns, body, compact=True)}"
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
    ] + [(k, _e(ROW_METRICS[k]), "number") for k in metrics]
    body = []
    for r in rows:
        tds = [_name_cell(r["controller"])] + [
            _text_cell(r.get(k, "")) for k in ("scenario", "split", "kind")
        ]
        tds += [_cell(r.get("seeds")), _cell(r.get("training_seeds"))]
        if r.get("applies", True) is False:
            attrs = f' class="na" colspan="{len(metrics)}" style="text-align:left"'
            tds.append(_Td("does not apply", attrs=attrs))
        else:
            tds += [_cell(r.get(k), r.get(f"{k}_ci95"), r.get(f"{k}_std")) for k in metrics]
        body.append(tds)
    return _table("rows", columns, body)


# ------------------------------------------------------------------------------ figures
def _anchor(name: str) -> str:
    """The id of a scenario's figure (the stem
    :func:`shipgym_baselines.leaderboard.figures.plot_scenario` gives
    its files)."""
    return "scenario_" + figure_stem(name)


class PageImage(NamedTuple):
    """A figure as the page embeds it: MIME type, bytes, and the legends it carries as text
    (a scenario figure's :data:`~shipgym_baselines.leaderboard.figures.LEGEND_KEY`; None: in the
    image)."""

    mime: str
    data: bytes
    legends: list[tuple[str, list[tuple[str, str]]]] | None = None


def page_image(png: Path) -> PageImage:
    """A PNG as the page embeds it: the same pixels as lossless WebP where that is smaller
    (a palette figure: ≈ 20 % smaller; every current browser shows WebP; effort 4 of 6:
    0.1 s a figure, 2 % larger than 6 at 60 times its CPU), else the PNG as it is.  A
    scenario figure whose PNG says where its legends start
    (:data:`~shipgym_baselines.leaderboard.figures.LEGEND_TOP_KEY`) is cut above them and its
    legends returned as text (the page writes them under the image)."""
    data = png.read_bytes()
    from PIL import Image, features

    with Image.open(png) as image:
        image.load()
        text = dict(getattr(image, "text", {}))
        legends = None
        if LEGEND_KEY in text and LEGEND_TOP_KEY in text:
            legends = [
                (t, [tuple(e) for e in entries]) for t, entries in json.loads(text[LEGEND_KEY])
            ]
            top = round(float(text[LEGEND_TOP_KEY]) * image.height)
            image = image.crop((0, 0, image.width, top))
        if not features.check("webp"):
            if legends is None:
                return PageImage("image/png", data)
            out = io.BytesIO()
            image.save(out, format="PNG", optimize=True)
            return PageImage("image/png", out.getvalue(), legends)
        out = io.BytesIO()
        image.save(out, format="WEBP", lossless=True, quality=100, method=4)
    webp = out.getvalue()
    if legends is None and len(webp) >= len(data):
        return PageImage("image/png", data)
    return PageImage("image/webp", webp, legends)


class _Embedded(NamedTuple):
    uri: str
    file: str
    legends: list[tuple[str, list[tuple[str, str]]]] | None


def embedded_figures(figures: Iterable[str | Path]) -> dict[str, _Embedded]:
    """stem → (data URI, file name, legends) of each figure, the PNG where a stem has one (a
    page-sized palette PNG, :func:`shipgym_baselines.leaderboard.figures.write_page_png`, embedded
    as :func:`page_image` gives it: the page stays light), else the SVG; in the
    order of ``figures``."""
    by_stem: dict[str, Path] = {}
    for f in map(Path, figures):
        if f.suffix.lower() not in (".svg", ".png"):
            continue
        if f.stem not in by_stem or f.suffix.lower() == ".png":
            by_stem[f.stem] = f
    out = {}
    for stem, f in by_stem.items():
        if f.suffix.lower() == ".png":
            image = page_image(f)
        else:
            image = PageImage("image/svg+xml", f.read_bytes())
        data = base64.b64encode(image.data).decode("ascii")
        out[stem] = _Embedded(f"data:{image.mime};base64,{data}", f.name, image.legends)
    return out


#: the oracle's line in the scenario figures (black, dashed) and the frozen optimum's (its
#: grey, dash-dotted: dashed here, CSS has no dash-dot), as legend swatches
_REFERENCE_SWATCH = "kref"
_FROZEN_SWATCH = "kfrozen"
_REFERENCE_CSS = (
    f".{_REFERENCE_SWATCH}{{border-top-style:dashed;border-top-color:#000}}"
    f".{_FROZEN_SWATCH}{{border-top-style:dashed;"
    f"border-top-color:{controller_style(ORACLE_FROZEN).color}}}"
)
_REFERENCE_SWATCHES = {ORACLE: _REFERENCE_SWATCH, ORACLE_FROZEN: _FROZEN_SWATCH}


def _legend_swatch(name: str) -> str:
    """The swatch class of a legend entry: the oracle's or the frozen optimum's reference
    line, else the controller's."""
    return _REFERENCE_SWATCHES.get(name) or _swatch_class(name)[0]


def _legend_html(legends: list[tuple[str, list[tuple[str, str]]]]) -> str:
    """A scenario figure's legends as text: one block per panel column, each episode's line
    swatch and label."""
    blocks = []
    for title, entries in legends:
        items = "".join(
            f'<li><span class="{_legend_swatch(name)}"></span>{_e(label)}</li>'
            for name, label in entries
        )
        blocks.append(f"<div><b>{_e(title)}</b><ul>{items}</ul></div>")
    return f'<div class="legend">{"".join(blocks)}</div>'


def _figure(stem: str, fig: _Embedded, caption: str) -> str:
    legend = _legend_html(fig.legends) if fig.legends else ""
    return (
        f'<figure id="fig-{_e(stem)}"><img src="{fig.uri}" alt="{_e(caption)}" loading="lazy">'
        f"{legend}<figcaption>{_e(caption)} — <code>{_e(fig.file)}</code></figcaption></figure>"
    )


def figure_sections(
    figures: Iterable[str | Path], scenarios: Iterable[str] = ()
) -> tuple[str, str, list[str]]:
    """(ranking figures, scenario figures, the controllers their legends name) as HTML: per
    split its interval estimates, then its performance profiles; the scenario figures in
    the order of ``figures``, captioned with the scenario's name where ``scenarios`` has
    it."""
    names = {_anchor(s): s for s in scenarios}
    ranking: list[tuple[str, int, str]] = []
    drawn = []
    legend_names: list[str] = []
    for stem, fig in embedded_figures(figures).items():
        kind, _, split = stem.partition("_")
        legend_names += [n for _, entries in fig.legends or () for n, _ in entries]
        if stem == LEARNING_CURVES_STEM:  # after the ranking figures of every split
            caption = "learning curves of the learned agents (validation return per seed)"
            ranking.append(("~", True, _figure(stem, fig, caption)))
        elif kind in ("ranking", "profile"):
            what = "interval estimates" if kind == "ranking" else "performance profiles"
            ranking.append((split, kind == "profile", _figure(stem, fig, f"{what}, {split}")))
        else:
            label = names.get(stem, stem.removeprefix("scenario_"))
            drawn.append(_figure(stem, fig, f"scenario {label}"))
    ranking_html = "".join(h for *_, h in sorted(ranking, key=lambda r: r[:2]))
    return ranking_html, "".join(drawn), legend_names


# --------------------------------------------------------------------------------- page
def page(
    rows: Sequence[Mapping[str, Any]],
    aggregate: Sequence[Mapping[str, Any]],
    scores: Sequence[Mapping[str, Any]],
    figures: Iterable[str | Path] = (),
    title: str = "shipgym leaderboard",
    subtitle: str | None = None,
    verdict: str | None = None,
    note: str = "",
    headroom: Sequence[Mapping[str, Any]] = (),
) -> str:
    """The page's HTML (module doc); ``verdict``: the run's sentences
    (:mod:`shipgym_baselines.leaderboard.verdict`), the page's first paragraph; ``note``: what the
    run is ranked against (:func:`~shipgym_baselines.leaderboard.comparison.comparison_note`),
    under it; ``headroom``: the headroom table's rows
    (:func:`~shipgym_baselines.leaderboard.ranking.headroom_table`), after the ranking."""
    ranking_figs, scenario_figs, legend_names = figure_sections(
        figures, (r["scenario"] for r in rows)
    )
    names = [r["controller"] for r in [*rows, *aggregate]] + legend_names
    names += [c["controller"] for s in scores for c in s["controllers"]]
    sub = f'<p class="note">{_e(subtitle)}</p>' if subtitle else ""
    sub += f'<p id="verdict">{_e(verdict)}</p>' if verdict else ""
    sub += f'<p class="note" id="ranked-against">{_e(note.replace("`", ""))}</p>' if note else ""
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>{_e(title)}</title><style>{_CSS}{swatch_css(names)}{_REFERENCE_CSS}</style>"
        "</head><body>"
        f"<h1>{_e(title)}</h1>{sub}"
        '<h2 id="ranking">Ranking</h2><p class="note">'
        f"{_e(SCORE_EXPLAINED.replace('`', ''))} Click a column header to sort.</p>"
        f"{ranking_tables(aggregate) if aggregate else _no_ranking(scores)}"
        f"{headroom_html(headroom)}"
        '<h2 id="scores-per-scenario">Cost ratio per scenario</h2><p class="note">The '
        "geometric mean of each controller's cost ratio C / C_oracle on each scenario, 95 % "
        "interval below (green: the oracle's cost, red: 4× or more); under each scenario's "
        f"name the oracle's mean cost{_frozen_note(scores)}. n/a: the controller does not "
        "apply to the scenario's "
        "ship. "
        "Click a header to sort; a scenario's name links to its figure.</p>"
        f"{score_table(rows, aggregate, scores)}"
        f'<h2 id="ranking-figures">Ranking figures</h2>{ranking_figs or "<p>No figures.</p>"}'
        f'<h2 id="figures">Scenarios</h2>{scenario_figs or "<p>No figures.</p>"}'
        '<h2 id="all-rows">All rows</h2><details><summary>One row per scenario and controller '
        f"({len(rows)} rows): means with 95 % intervals</summary>{packed_body(row_table(rows))}"
        "<noscript><p>The rows need the page's script; they are also in leaderboard.md and "
        "leaderboard.csv.</p></noscript></details>"
        f"<script>{_JS}</script></body></html>\n"
    )


def _frozen_note(scores: Sequence[Mapping[str, Any]]) -> str:
    """The score table's note on the frozen optimum, where it ran."""
    if all(s.get("oracle_frozen_cost") is None for s in scores):
        return ""
    return (
        f" and {ORACLE_FROZEN}'s (the optimum that never adapts; its row's ratios are the "
        "headroom, what knowing the change is worth)"
    )


def _no_ranking(scores: Sequence[Mapping[str, Any]]) -> str:
    return f'<p class="note">{_e(no_ranking(scores).replace("`", ""))}</p>'


def write_html(
    out_dir: str | Path,
    rows: Sequence[Mapping[str, Any]],
    aggregate: Sequence[Mapping[str, Any]],
    scores: Sequence[Mapping[str, Any]],
    figures: Iterable[str | Path] = (),
    title: str = "shipgym leaderboard",
    subtitle: str | None = None,
    verdict: str | None = None,
    note: str = "",
    headroom: Sequence[Mapping[str, Any]] = (),
) -> Path:
    """Write ``leaderboard.html`` into ``out_dir`` (module doc): ``rows`` as in
    ``leaderboard.json``, ``aggregate`` as in ``aggregate.json``, ``scores`` from
    :func:`shipgym_baselines.leaderboard.ranking.scenario_scores`, ``figures`` the PNG/SVG files of
    :mod:`shipgym_baselines.leaderboard.figures`; ``subtitle``: a line under the title (e.g. the
    suite
    and seeds); ``verdict``: the paragraph the page opens with; ``note``: what the run is
    ranked against; ``headroom``: the headroom table's rows.  Returns the page's path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    path = out / PAGE_FILE
    write_bytes(
        path,
        page(rows, aggregate, scores, figures, title, subtitle, verdict, note, headroom).encode(
            "utf-8"
        ),
    )
    return path
