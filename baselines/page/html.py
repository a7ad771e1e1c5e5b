"""``leaderboard.html``: the leaderboard as one page in its run's folder.

It opens with the run's verdict in four sentences (:mod:`shipgym_baselines.page.verdict`).
No network: the style sheet and the script are inline.  The ranking figures are embedded as
data URIs (a light WebP or PNG, else the SVG); the scenario figures, one per scenario and
most of a page's bytes (4 of 4.8 MB on the default run), are the PNG files beside the page,
linked (the page stays within 3 MB; copied alone, it shows their captions only).  The page
holds, in order:

1. the **ranking** per split (``aggregate.json`` rows: IQM and geometric mean of the cost
   ratio C / C_oracle, the probability of improvement over ``pid_los`` and the failure
   rate, the nominal ratio and the change share, 95 % intervals; a split's partial table
   below it; every ``aggregate.json`` field in a collapsed long table), the resolution of
   each split, the headroom per ship × change family (what knowing the change is worth:
   C_frozen / C_oracle, :func:`shipgym_baselines.scoring.headroom.headroom_table`), the
   change share per ship × change family of the top competitors and the figures
   (``ranking_*`` / ``profile_*`` of :mod:`shipgym_baselines.plots`);
2. the **controller × scenario table**: the oracle's mean cost, then each controller's
   geometric-mean cost ratio with its interval (``scenario_scores.json``,
   :func:`shipgym_baselines.scoring.ranking.scenario_scores`), shaded from 1 (the oracle, green)
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

import dataclasses
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from shipgym_baselines.page.cells import esc, packed_body, swatch_css
from shipgym_baselines.page.figures import figure_sections, reference_css
from shipgym_baselines.page.sections import (
    headroom_html,
    ranking_tables,
    row_table,
    score_table,
    share_html,
)
from shipgym_baselines.privileged import ORACLE_FROZEN
from shipgym_baselines.records.outfiles import write_bytes
from shipgym_baselines.scoring.ranking import SCORE_EXPLAINED, no_ranking

PAGE_FILE = "leaderboard.html"
_CSS = """
body{font:14px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;margin:24px;
color:#1b1f24;background:#fff}
h1{font-size:24px;margin:0 0 4px}h2{font-size:19px;margin:28px 0 8px;border-bottom:1px solid
#d0d7de;padding-bottom:4px}h3{font-size:16px;margin:18px 0 6px}
p.note{color:#57606a;margin:4px 0 10px;max-width:75em}
.flag{color:#b15928;cursor:help;white-space:nowrap}
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
.splits>div{min-width:0;max-width:100%}
td.na{color:#8c959f;font-style:italic}
td:first-child span{display:inline-block;width:22px;height:0;border-top-width:3px;
margin-right:6px;vertical-align:middle}
figure{margin:10px 0 22px}figure img{max-width:100%;height:auto;border:1px solid #eaeef2}
.crop{overflow:hidden;border:1px solid #eaeef2}.crop img{width:100%;display:block;border:0}
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


@dataclasses.dataclass(frozen=True)
class PageContent:
    """What the page shows: ``rows`` as in ``leaderboard.json``, ``aggregate`` as in
    ``aggregate.json``, ``scores`` from
    :func:`shipgym_baselines.scoring.ranking.scenario_scores`, ``figures`` the PNG/SVG files
    of :mod:`shipgym_baselines.plots`; ``subtitle``: a line under the title (e.g. the
    suite and seeds); ``verdict``: the run's sentences
    (:mod:`shipgym_baselines.page.verdict`), the page's first paragraph; ``note``: what the
    run is ranked against (:func:`~shipgym_baselines.scoring.comparison.comparison_note`),
    under it; ``headroom``: the headroom table's rows
    (:func:`~shipgym_baselines.scoring.headroom.headroom_table`), after the ranking;
    ``shares``: the change share per ship × change family
    (:func:`~shipgym_baselines.leaderboard.outputs.share_table`), after the headroom."""

    rows: Sequence[Mapping[str, Any]]
    aggregate: Sequence[Mapping[str, Any]]
    scores: Sequence[Mapping[str, Any]]
    figures: Iterable[str | Path] = ()
    title: str = "shipgym leaderboard"
    subtitle: str | None = None
    verdict: str | None = None
    note: str = ""
    headroom: Sequence[Mapping[str, Any]] = ()
    shares: Mapping[str, Any] | None = None


def page(content: PageContent, folder: str | Path | None = None) -> str:
    """The page's HTML of ``content`` (module doc); ``folder``: where the page is written
    (its scenario figures are then linked as the files beside it, the other figures
    embedded; None: every figure embedded)."""
    rows, aggregate, scores = content.rows, content.aggregate, content.scores
    title, subtitle, verdict, note = content.title, content.subtitle, content.verdict, content.note
    ranking_figs, scenario_figs, legend_names = figure_sections(
        content.figures, (r["scenario"] for r in rows), folder
    )
    names = [r["controller"] for r in [*rows, *aggregate]] + legend_names
    names += [c["controller"] for s in scores for c in s["controllers"]]
    sub = f'<p class="note">{esc(subtitle)}</p>' if subtitle else ""
    sub += f'<p id="verdict">{esc(verdict)}</p>' if verdict else ""
    sub += f'<p class="note" id="ranked-against">{esc(note.replace("`", ""))}</p>' if note else ""
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>{esc(title)}</title><style>{_CSS}{swatch_css(names)}{reference_css()}</style>"
        "</head><body>"
        f"<h1>{esc(title)}</h1>{sub}"
        '<h2 id="ranking">Ranking</h2><p class="note">'
        f"{esc(SCORE_EXPLAINED.replace('`', ''))} Click a column header to sort.</p>"
        f"{ranking_tables(aggregate) if aggregate else _no_ranking(scores)}"
        f"{headroom_html(content.headroom)}{share_html(content.shares or {})}"
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
    return f'<p class="note">{esc(no_ranking(scores).replace("`", ""))}</p>'


def write_html(out_dir: str | Path, content: PageContent) -> Path:
    """Write ``leaderboard.html`` of ``content`` into ``out_dir`` (module doc); returns the
    page's path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    path = out / PAGE_FILE
    write_bytes(path, page(content, folder=out).encode("utf-8"))
    return path
