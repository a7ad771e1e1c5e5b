"""``leaderboard.html``: self-contained, escaped, and rendered by a real headless browser."""

from __future__ import annotations

import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from shipgym_baselines.page.cells import unpacked_body
from shipgym_baselines.page.html import PAGE_FILE, PageContent, page, write_html
from shipgym_baselines.plots.scenarios import DrawnEpisode, plot_scenario
from shipgym_baselines.scoring.change_share import NOMINAL, SHARE
from shipgym_baselines.scoring.headroom import GAIN

CONTROLLERS = [
    "pid_los",
    "pid_lookahead_los",
    "pid_vf",
    "pid_tvvf",
    "lqr",
    "adaptive_lqr",
    "nmpc",
    "nmpc_wlssvm",
    "nmpc_lambda_lssvm",
    "l1_backstepping",
    "adaptive_backstepping",
    "ppo",
    "ppo_guidance",
    "recurrent_ppo",
    "sac",
    "td3",
    "zero_rudder",
    "my <plugin> & co",  # a plug-in's name is user input: escaped, still listed
]
SCENARIOS = {"nominal": "catalogue", "rudder_aging": "catalogue", "heldout:0": "heldout"}
LEARNED = {"ppo", "ppo_guidance", "recurrent_ppo", "sac", "td3"}


def _ratio(i: int, j: int) -> float:
    """A distinct synthetic cost ratio of controller i on scenario j."""
    return round(1.05 + 0.06 * i + 0.013 * ((i * 7 + j * 5) % 11), 4)


def synthetic_tables() -> tuple[list[dict[str, Any]], list[dict[str, Any]], list[dict[str, Any]]]:
    """(rows, aggregate, scores) shaped as leaderboard.json, aggregate.json and
    scenario_scores.json give them."""
    rows, scores, aggregate = [], [], []
    ratios: dict[tuple[str, str], float] = {}
    for j, (scenario, split) in enumerate(SCENARIOS.items()):
        cells = []
        for i, name in enumerate(CONTROLLERS):
            kind = "learned" if name in LEARNED else "classical"
            applies = not (name == "nmpc" and scenario == "heldout:0")
            row: dict[str, Any] = {"scenario": scenario, "split": split, "controller": name}
            row |= {"kind": kind, "applies": applies, "seeds": 10 if applies else 0}
            if applies:
                row |= {"ace": 1.0 + 0.1 * i, "ace_ci95": [0.9 + 0.1 * i, 1.1 + 0.1 * i]}
                row |= {"return": -10.0 - i, "return_ci95": [-11.0 - i, -9.0 - i]}
                row |= {"t_c": float("inf") if i % 5 == 0 else 30.0 + i, "success": 1.0}
                if kind == "learned":
                    row["training_seeds"] = 3
                r = ratios[(name, scenario)] = _ratio(i, j)
                cells.append(
                    {"controller": name, "kind": kind, "cost": 80.0 * r}
                    | {"cost_ratio_gmean": r, "cost_ratio_gmean_ci95": [r - 0.02, r + 0.02]}
                    | {"episodes": 10}
                )
            rows.append(row)
        scores.append(
            {"scenario": scenario, "split": split, "oracle_cost": 80.0}
            | {"oracle_cost_ci95": [78.0, 82.0], "oracle_episodes": 10, "controllers": cells}
        )
    for split in ("catalogue", "heldout"):
        for i, name in enumerate(CONTROLLERS):
            mine = [s for (c, s), _ in ratios.items() if c == name and SCENARIOS[s] == split]
            if not mine:
                continue
            m = float(np.mean([ratios[(name, s)] for s in mine]))
            aggregate.append(
                {"controller": name, "kind": rows[i]["kind"], "split": split}
                | {"scenarios": mine, "runs": 10, "training_seeds": 0}
                | {"cost_ratio_iqm": m, "cost_ratio_iqm_ci95": [m - 0.04, m + 0.04]}
                | {"cost_ratio_gmean": m, "cost_ratio_gmean_ci95": [m - 0.03, m + 0.03]}
                | {"prob_improvement_over_pid_los": 0.5}
                | {"prob_improvement_over_pid_los_ci95": [0.4, 0.6]}
                | {"failure_rate": 0.1, "failure_rate_ci95": [0.0, 0.2]}
            )
    aggregate.sort(key=lambda r: (r["split"], r["cost_ratio_iqm"]))
    return rows, aggregate, scores


class _ScoreRows(HTMLParser):
    """The first cell's text of every body row of ``<table id="scores">``, and its headers'
    ``aria-sort``."""

    def __init__(self) -> None:
        super().__init__()
        self.names: list[str] = []
        self.sorted: dict[str, str] = {}
        self._in_table = self._in_body = self._first = False
        self._cell = 0

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = dict(attrs)
        if tag == "table":
            self._in_table = a.get("id") == "scores"
        elif self._in_table and tag == "th" and a.get("aria-sort"):
            self.sorted[a["data-key"] or ""] = a["aria-sort"] or ""
        elif self._in_table and tag == "tbody":
            self._in_body = True
        elif self._in_body and tag == "tr":
            self._cell = 0
        elif self._in_body and tag == "td":
            self._cell += 1
            self._first = self._cell == 1
            if self._first:
                self.names.append("")

    def handle_endtag(self, tag: str) -> None:
        if tag == "td":
            self._first = False
        elif tag == "table":
            self._in_table = self._in_body = False

    def handle_data(self, data: str) -> None:
        if self._first:
            self.names[-1] += data


def score_rows(dom: str) -> _ScoreRows:
    parser = _ScoreRows()
    parser.feed(dom)
    return parser


def test_the_page_is_self_contained_and_escaped() -> None:
    rows, aggregate, scores = synthetic_tables()
    text = page(PageContent(rows, aggregate, scores))
    assert "<plugin>" not in text and "my &lt;plugin&gt; &amp; co" in text
    # no address outside the page: every src / href is a data URI or an anchor
    assert not re.findall(r'(?:src|href)="(?!data:|#)', text)
    assert "<link" not in text and "@import" not in text


def test_a_cell_shows_the_interval_and_n_a_where_a_controller_does_not_apply() -> None:
    rows, aggregate, scores = synthetic_tables()
    text = page(PageContent(rows, aggregate, scores))
    (nominal,) = [s for s in scores if s["scenario"] == "nominal"]
    cell = next(c for c in nominal["controllers"] if c["controller"] == "lqr")
    lo, hi = cell["cost_ratio_gmean_ci95"]
    assert f"[{lo:.3f}, {hi:.3f}]" in text
    assert "oracle cost 80.000" in text  # under the scenario's name
    assert "An episode&#x27;s cost is the sum of its step costs" in text
    assert "Resolution, catalogue: median width of the cost-ratio IQM intervals 0.080" in text
    assert 'title="does not apply">n/a</td>' in text
    assert ">never<" not in text  # the long table's rows are packed …
    assert ">never<" in unpacked_body(text)  # … t_c = inf in the long table


CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--disable-dev-shm-usage",
)


def chromium(url: str, tmp: Path, *args: str) -> str:
    """Run headless chromium on ``url``; its standard output."""
    assert CHROMIUM is not None
    done = subprocess.run(
        [CHROMIUM, *FLAGS, f"--user-data-dir={tmp / 'profile'}", *args, url],
        capture_output=True,
        text=True,
        timeout=180,
        check=True,
    )
    return done.stdout


@pytest.fixture(scope="module")
def built_page(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("page")
    t = np.linspace(0.0, 60.0, 60)
    traj = {"t": t, "x": 2.0 * t, "y": np.exp(-t / 20), "cross_track_error": np.exp(-t / 20)}
    traj["rudder_angle"] = -0.1 * np.exp(-t / 20)
    drawn = {"pid_los": DrawnEpisode(10000, traj), "lqr": DrawnEpisode(10000, traj)}
    figs = plot_scenario(out / "fig", "nominal", drawn, 30.0, np.array([[0, 0], [120, 0]]))
    rows, aggregate, scores = synthetic_tables()
    return write_html(
        out, PageContent(rows, aggregate, scores, figs, subtitle="synthetic: 18 controllers")
    )


def test_the_written_page_links_its_scenario_figures_beside_it(built_page: Path) -> None:
    """The scenario figures (most of a run page's bytes) are the PNG files beside the page,
    cropped above their legends (written as text); everything else stays inside the page."""
    text = built_page.read_text(encoding="utf-8")
    figure = re.search(r'<figure id="fig-scenario_nominal">(.*?)</figure>', text, re.S)
    assert figure is not None
    (src,) = re.findall(r'src="([^"]+)"', figure.group(1))
    assert src == "fig/scenario_nominal.png" and (built_page.parent / src).is_file()
    assert 'class="crop"' in figure.group(1) and 'class="legend"' in figure.group(1)
    others = [a for a in re.findall(r'(?:src|href)="([^"]+)"', text) if a != src]
    assert others and all(a.startswith(("data:", "#")) for a in others)


@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (.ci/run installs it)")
def test_the_page_renders_in_a_headless_browser_with_every_controller(built_page: Path) -> None:
    assert built_page.name == PAGE_FILE
    tmp = built_page.parent
    shot = tmp / "screenshot.png"
    chromium(built_page.as_uri(), tmp, f"--screenshot={shot}", "--window-size=1400,2000")
    with Image.open(shot) as image:
        assert image.size == (1400, 2000)
        rgb = np.asarray(image.convert("RGB"))
    colours = np.unique(rgb.reshape(-1, 3), axis=0)
    assert len(colours) > 50  # text, swatches, shaded cells: not a blank page
    assert (rgb < 200).any(axis=2).mean() > 0.01  # ink on at least 1 % of the pixels

    # the DOM after the script ran (and its promises: the long table unpacks asynchronously)
    dom = chromium(built_page.as_uri(), tmp, "--virtual-time-budget=10000", "--dump-dom")
    assert sorted(score_rows(dom).names) == sorted(CONTROLLERS)
    cells = _Cells()  # the long table's rows, unpacked by the page's script
    cells.feed(dom)
    rows, _, _ = synthetic_tables()
    assert len(cells.rows["rows"]) == len(rows)
    shown = [(r[0][1], r[1][1]) for r in cells.rows["rows"]]
    assert shown == [(r["controller"], r["scenario"]) for r in rows]
    # the scenario figure's legends as text under its image, the oracle's swatch aside
    assert "pid_los (seed 10000)" in dom and 'class="legend"' in dom


#: a script appended to a copy of the page: the document's width after layout, in the DOM
WIDTH_PROBE = (
    "<script>addEventListener('load', () => document.body.setAttribute('data-widths', "
    "document.documentElement.scrollWidth + ' ' + innerWidth))</script>"
)


def page_widths(page: Path, tmp: Path, width: int) -> tuple[int, int]:
    """(the page's scroll width, the window's inner width) [px] in a ``width``-px window."""
    probe = tmp / "probed.html"
    probe.write_text(page.read_text(encoding="utf-8").replace("</body>", WIDTH_PROBE + "</body>"))
    dom = chromium(
        probe.as_uri(),
        tmp,
        f"--window-size={width},2000",
        "--virtual-time-budget=5000",
        "--dump-dom",
    )
    found = re.search(r'data-widths="(\d+) (\d+)"', dom)
    assert found is not None, dom[:300]
    return int(found.group(1)), int(found.group(2))


@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (.ci/run installs it)")
@pytest.mark.parametrize("width", [1400, 800])
def test_the_page_fits_its_window_wide_tables_scroll_in_their_boxes(
    built_page: Path, width: int
) -> None:
    """18 controllers' ranking with every column: nothing runs off a 1400-px window, nor an
    800-px one, narrower than the ranking (a table wider than its box scrolls inside it)."""
    scroll_width, inner = page_widths(built_page, built_page.parent, width)
    assert inner == width and scroll_width <= inner


@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (.ci/run installs it)")
@pytest.mark.parametrize(
    ("fragment", "order"),
    [("#sort=rudder_aging", "ascending"), ("#sort=iqm:heldout:desc", "descending")],
)
def test_the_table_sorts_by_a_clicked_header(built_page: Path, fragment: str, order: str) -> None:
    # the page clicks the header named in its address's hash (twice for the other order)
    dom = chromium(built_page.as_uri() + fragment, built_page.parent, "--dump-dom")
    shown = score_rows(dom)
    key = fragment.removeprefix("#sort=").removesuffix(":desc")
    assert shown.sorted == {key: order}
    _, aggregate, scores = synthetic_tables()
    if key == "rudder_aging":  # a cost ratio: lowest first on the first click
        (cells,) = [s["controllers"] for s in scores if s["scenario"] == key]
        value = {c["controller"]: c["cost_ratio_gmean"] for c in cells}
    else:
        value = {r["controller"]: r["cost_ratio_iqm"] for r in aggregate if r["split"] == "heldout"}
    ranked = sorted(value, key=value.__getitem__, reverse=order == "descending")
    missing = [n for n in CONTROLLERS if n not in value]  # n/a: last in either order
    assert shown.names == ranked + missing


class _Cells(HTMLParser):
    """Per table id: its header kinds and, per body row, each cell's (data-sort, text)."""

    def __init__(self) -> None:
        super().__init__()
        self.kinds: dict[str, list[str]] = {}
        self.rows: dict[str, list[list[tuple[str | None, str]]]] = {}
        self._table, self._body = "", False
        self._cell: list[Any] | None = None

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = dict(attrs)
        if tag == "table":
            self._table = a.get("id") or ""
            self.kinds[self._table], self.rows[self._table] = [], []
        elif tag == "th" and self._table:
            self.kinds[self._table].append(a.get("data-type") or "")
        elif tag == "tbody" and self._table:
            self._body = True
        elif tag == "tr" and self._table and self._body:
            self.rows[self._table].append([])
        elif tag == "td" and self._table and self._body:
            self._cell = [a.get("data-sort"), ""]
            self.rows[self._table][-1].append(self._cell)  # type: ignore[arg-type]

    def handle_endtag(self, tag: str) -> None:
        if tag == "td":
            self._cell = None
        elif tag == "table":
            self._table, self._body = "", False

    def handle_data(self, data: str) -> None:
        if self._cell is not None:
            self._cell[1] += data


def _script_key(cell: list[Any] | None, numeric: bool) -> Any:
    """The page script's sort key of a cell (data-sort, else the text; parseFloat)."""
    if cell is None:
        return None
    v = cell[0] if cell[0] is not None else cell[1]
    if v == "":
        return None
    if not numeric:
        return v.lower()
    match = re.match(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?", v.strip())
    return float(match.group(0)) if match else None


def test_every_numeric_column_of_the_long_table_sorts_as_its_values() -> None:
    """With data-sort at ≤ 7 digits, or none where a column's texts sort the same,
    every column of the long table sorts its rows as the full-precision values do."""
    rows, aggregate, scores = synthetic_tables()
    for i, r in enumerate(rows):  # values that tie at the 3 decimals shown, differ after
        if "ace" in r:
            r["ace"] = round(r["ace"], 1) + 1e-5 * (i % 7)
    parser = _Cells()
    parser.feed(unpacked_body(page(PageContent(rows, aggregate, scores))))
    kinds, body = parser.kinds["rows"], parser.rows["rows"]
    assert len(body) == len(rows)
    for col, key in enumerate(["controller", "scenario", "split", "kind", "seeds"]):
        numeric = kinds[col] == "number"
        shown = [_script_key(cells[col] if col < len(cells) else None, numeric) for cells in body]
        truth = [r.get(key) for r in rows]
        if not numeric:
            truth = [str(t).lower() for t in truth]
        assert _order(shown) == _order(truth), key
    metric_cols = {"ace": 6, "return": 8}
    for key, col in metric_cols.items():
        shown = [_script_key(cells[col] if col < len(cells) else None, True) for cells in body]
        truth = [r.get(key) if r.get("applies", True) else None for r in rows]
        assert _order(shown) == _order(truth), key
    assert any(cells[6][0] for cells in body if len(cells) > 6)  # ace needs its keys
    assert all(cells[4][0] is None for cells in body)  # seeds: the text sorts the same


def _order(keys: list[Any]) -> list[int]:
    """The row order a stable ascending sort gives (None last), as the script does."""
    present = sorted((i for i, k in enumerate(keys) if k is not None), key=lambda i: keys[i])
    return present + [i for i, k in enumerate(keys) if k is None]


def _with_the_frozen_optimum() -> tuple[list, list, list, list]:
    """synthetic_tables() with the gap fields, the twins' fields, the frozen optimum's costs
    and a headroom table (rows as headroom_table gives them)."""
    rows, aggregate, scores = synthetic_tables()
    for i, r in enumerate(aggregate):
        r |= {GAIN: 1.5 - 0.01 * i, f"{GAIN}_ci95": [1.3, 1.7]}
        r |= {"prob_beats_frozen": 0.625, "prob_beats_frozen_ci95": [0.5, 0.75]}
        r |= {"gap_closed_iqm": 0.375, "gap_closed_iqm_ci95": [0.25, 0.5], "gap_trials": 17}
        r |= {NOMINAL: 1.25, f"{NOMINAL}_ci95": [1.125, 1.5], "change_trials": 20}
        r |= {SHARE: 0.4375, f"{SHARE}_ci95": [0.3125, 0.5625], "share_trials": 13}
    for s in scores:
        s |= {"oracle_frozen_cost": 240.0, "oracle_frozen_cost_ci95": [200.0, 280.0]}
        s |= {"headroom": 3.0, "headroom_ci95": [2.5, 3.5]}
    headroom = [
        {"ship": "nomoto2", "family": "nominal", "scenarios": ["nominal"], "trials": 10}
        | {"headroom_gmean": 1.0},
        {"ship": "nomoto2", "family": "rudder_aging", "scenarios": ["rudder_aging"]}
        | {"trials": 10, "headroom_gmean": 2.875},
        {"ship": "mariner", "family": "current_shift", "scenarios": ["mariner_current_shift"]}
        | {"trials": 1, "headroom_gmean": 1.25},
    ]
    return rows, aggregate, scores, headroom


def test_the_page_shows_the_gap_columns_and_the_headroom_table() -> None:
    rows, aggregate, scores, headroom = _with_the_frozen_optimum()
    text = page(PageContent(rows, aggregate, scores, headroom=headroom))
    # the main ranking: the nominal ratio and the change share, nothing against C_frozen
    main = text[text.index('id="ranking-catalogue"') :]
    main = main[: main.index("</table>")]
    assert ">nominal ratio</th>" in main and ">change share</th>" in main
    assert "1.250<i>[1.125, 1.500]</i>" in main  # the nominal ratio's cell
    assert "0.438<i>[0.312, 0.562]</i><i>13 trials</i>" in main  # the change share's
    assert "C_frozen" not in main and "gap closed" not in main
    # the long ranking, collapsed under it: every field, those against C_frozen too
    long = text[text.index('id="ranking-long-catalogue"') :]
    long = long[: long.index("</table>")]
    assert text.index("<details>") < text.index('id="ranking-long-catalogue"')
    assert ">C_frozen / C</th>" in long and ">P(C &lt; C_frozen)</th>" in long
    assert ">gap closed IQM</th>" in long and ">nominal ratio</th>" in long
    assert "1.500<i>[1.300, 1.700]</i>" in long  # pid_los's C_frozen / C
    assert "0.375<i>[0.250, 0.500]</i><i>17 trials</i>" in long  # the gap closed's cell
    assert "oracle_frozen cost 240.000" in text  # under each scenario's name
    assert text.index('id="ranking-catalogue"') < text.index('id="headroom"')
    table = text[text.index('id="headroom"') :]
    table = table[: table.index("</table>")]
    assert "<th" in table and "rudder aging" in table and "current shift" in table
    assert "2.875<i>10 trials</i>" in table and "1.250<i>1 trial</i>" in table
    assert table.index(">nomoto2<") < table.index(">mariner<")  # ships in the rows' order
    assert "maneuverability" not in table  # no column for a family without trials
    # without the frozen optimum: no gap column, no headroom table, no frozen cost
    bare = page(PageContent(*synthetic_tables()))
    assert "C_frozen" not in bare and 'id="headroom"' not in bare
    assert "ranking-long-" not in bare and "nominal ratio" not in bare
    assert "oracle_frozen cost" not in bare


def test_the_frozen_optimum_has_its_own_legend_swatch() -> None:
    from shipgym_baselines.page.figures import _legend_html
    from shipgym_baselines.plots.style import controller_style

    html = _legend_html([("PID", [("oracle", "o"), ("oracle_frozen", "f"), ("pid_los", "p")])])
    assert '<span class="kref"></span>o' in html and '<span class="kfrozen"></span>f' in html
    text = page(PageContent(*synthetic_tables()))
    grey = controller_style("oracle_frozen").color
    assert f".kfrozen{{border-top-style:dashed;border-top-color:{grey}}}" in text
