"""The leaderboard's figures: page-sized palette PNG + SVG (SVGZ), one look per controller."""

from __future__ import annotations

import gzip
import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from shipgym_baselines.plots import ranking as ranking_figures
from shipgym_baselines.plots.files import (
    LEGEND_KEY,
    LEGEND_TOP_KEY,
    PAGE_COLOURS,
    PAGE_WIDTH,
)
from shipgym_baselines.plots.ranking import plot_ranking
from shipgym_baselines.plots.scenarios import (
    DrawnEpisode,
    episodes_to_draw,
    median_ace_episode,
    plot_scenario,
)
from shipgym_baselines.plots.style import FIGURE_DPI, controller_style
from shipgym_baselines.scoring.ranking import aggregate_ranking

SVG = "{http://www.w3.org/2000/svg}"


def trajectory(offset: float, n: int = 120) -> dict[str, np.ndarray]:
    """A ship running along y = 0 with a decaying cross-track error of ``offset`` [m]."""
    t = np.linspace(0.0, 120.0, n)
    e = offset * np.exp(-t / 30.0)
    return {
        "t": t,
        "x": 2.0 * t,
        "y": e,
        "cross_track_error": e,
        "heading": np.zeros(n),
        "rudder_angle": -0.01 * e,
        "rudder_command": -0.01 * e,
    }


def parse(svg: Path) -> ET.ElementTree:
    """An SVG or SVGZ (gzip-compressed SVG) file's tree."""
    if svg.suffix == ".svgz":
        with gzip.open(svg) as file:
            return ET.parse(file)
    return ET.parse(svg)


def stroke(svg: Path, gid: str) -> str:
    """The colour (stroke, else fill) of the first drawn path in the SVG group ``gid``."""
    group = next(g for g in parse(svg).iter(f"{SVG}g") if g.get("id") == gid)
    style = next(p.get("style") for p in group.iter(f"{SVG}path") if p.get("style"))
    props = dict(part.split(":", 1) for part in style.replace(" ", "").split(";") if part)
    colour = props["stroke"] if props.get("stroke", "none") != "none" else props["fill"]
    return colour.lower()


def svg_text(svg: Path) -> str:
    return " ".join(t.text or "" for t in parse(svg).iter(f"{SVG}text"))


@pytest.fixture(scope="module")
def scenario_files(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    drawn = {
        "pid_los": DrawnEpisode(10003, trajectory(5.0), None),
        "lqr": (10003, trajectory(3.0)),
        "ppo": DrawnEpisode(10003, trajectory(4.0), 1),
        "zero_rudder": DrawnEpisode(10003, trajectory(20.0), None),
        "oracle": DrawnEpisode(10003, trajectory(0.5), None),
    }
    path = np.array([[0.0, 0.0], [240.0, 0.0]])
    out = tmp_path_factory.mktemp("figures")
    return plot_scenario(
        out, "heldout:0", drawn, change_time=60.0, path_xy=path, ship_length=3.25, vector=True
    )


def test_a_scenario_figure_is_a_page_sized_png_and_an_svgz(scenario_files: list[Path]) -> None:
    """Drawn at 200 dpi, written at half (≤ PAGE_WIDTH px) as a palette PNG; the
    vector copy deflated."""
    png, svg = scenario_files
    assert (png.name, svg.name) == ("scenario_heldout_0.png", "scenario_heldout_0.svgz")
    with Image.open(png) as image:
        assert image.info["dpi"] == pytest.approx((FIGURE_DPI / 2, FIGURE_DPI / 2), abs=0.01)
        assert PAGE_WIDTH / 2 < image.width <= PAGE_WIDTH  # not a thumbnail
        assert image.mode == "P" and len(image.getcolors()) <= PAGE_COLOURS
    assert parse(svg).getroot().tag == f"{SVG}svg"


def test_the_page_png_keeps_each_controllers_colour(scenario_files: list[Path]) -> None:
    """The page PNG's palette holds each drawn controller's exact colour (an
    adaptive palette had turned them grey), and those pixels are there; the legends' text
    and where they start ride in the PNG for the page."""
    with Image.open(scenario_files[0]) as image:
        palette = image.getpalette()
        used = {tuple(palette[3 * i : 3 * i + 3]) for _, i in image.getcolors()}
        text = dict(image.text)
    for name in ("pid_los", "lqr", "ppo"):
        colour = controller_style(name).color.lstrip("#")
        assert tuple(int(colour[k : k + 2], 16) for k in (0, 2, 4)) in used, name
    legends = json.loads(text[LEGEND_KEY])
    labels = [label for _, entries in legends for _, label in entries]
    assert "ppo (seed 10003, training seed 1)" in labels
    assert "oracle (seed 10003), the reference" in labels
    assert 0.5 < float(text[LEGEND_TOP_KEY]) < 1.0


def test_the_figure_says_what_is_drawn_with_units(scenario_files: list[Path]) -> None:
    text = svg_text(scenario_files[1])
    assert "change at t = 60 s" in text
    assert "median-ACE seed 10003" in text
    assert "ppo (seed 10003, training seed 1)" in text  # the legend names each episode
    for unit in ("x [m]", "y [m]", "t [s]", "cross-track error e [m]", "rudder angle δ [deg]"):
        assert unit in text


def two_scenario_episodes(*extra: tuple[str, str, float]) -> list[dict]:
    """Synthetic episodes on scenarios ``a`` and ``b``, seeds 10000–10002: the oracle (cost
    8), ``extra`` (name, kind, cost), pid_los (10) and lqr (12), each cost plus seed % 3."""
    rows = (("oracle", "reference", 8.0), *extra, ("pid_los", "classical", 10.0))
    return [
        {"scenario": s, "controller": c, "kind": k, "seed": seed, "cost": r + seed % 3}
        for s in ("a", "b")
        for seed in (10000, 10001, 10002)
        for c, k, r in (*rows, ("lqr", "classical", 12.0))
    ]


def test_a_controller_has_its_colour_in_every_figure(
    scenario_files: list[Path], tmp_path: Path
) -> None:
    episodes = two_scenario_episodes(("zero_rudder", "reference", 50.0))
    splits = {"a": "catalogue", "b": "catalogue"}
    aggregate = aggregate_ranking(episodes, splits, {}, reps=50)
    files = plot_ranking(tmp_path, aggregate, episodes, splits, vector=True)
    assert [f.name for f in files] == [
        "ranking_catalogue.png",
        "ranking_catalogue.svg",
        "profile_catalogue.png",
        "profile_catalogue.svg",
    ]
    for name in ("pid_los", "lqr"):
        colour = controller_style(name).color.lower()
        assert stroke(scenario_files[1], f"{name}/track") == colour
        assert stroke(scenario_files[1], f"{name}/e") == colour
        assert stroke(files[1], f"{name}/interval/cost_ratio_iqm") == colour
        assert stroke(files[3], f"{name}/profile") == colour
    with Image.open(files[0]) as image:  # 200 dpi reduced by a whole factor to fit PAGE_WIDTH
        factor = FIGURE_DPI / image.info["dpi"][0]
        assert factor == pytest.approx(round(factor), abs=1e-3) and image.width <= PAGE_WIDTH
    ranking = svg_text(files[1])
    assert "cost ratio C / C_oracle [–] (log)" in ranking and "zero_rudder" not in ranking


def test_without_pid_los_the_ranking_figure_has_no_panel_against_it(tmp_path: Path) -> None:
    episodes = [
        {"scenario": "a", "controller": c, "kind": k, "seed": seed, "cost": r + seed % 3}
        for seed in (10000, 10001, 10002)
        for c, k, r in (("oracle", "reference", 8.0), ("lqr", "classical", 12.0))
    ]
    aggregate = aggregate_ranking(episodes, {"a": "catalogue"}, {}, reps=50)
    files = plot_ranking(tmp_path, aggregate, episodes, {"a": "catalogue"}, vector=True)
    text = svg_text(files[1])
    assert "IQM cost ratio" in text and "failure rate" in text and "pid_los" not in text


def test_the_oracle_is_drawn_in_every_column_as_the_reference(scenario_files: list[Path]) -> None:
    """The oracle's track, e(t) and δ(t) in each family's column (PID, LQR, learned,
    references), named in the legends; it has no column of its own."""
    root = parse(scenario_files[1]).getroot()
    tracks = [g for g in root.iter(f"{SVG}g") if g.get("id") == "oracle/track"]
    assert len(tracks) == 4
    assert stroke(scenario_files[1], "oracle/track") == "#000000"
    text = svg_text(scenario_files[1])
    assert text.count("oracle (seed 10003), the reference") == 4


def test_the_median_ace_episode_is_an_episode_of_the_pair() -> None:
    records = [
        {"scenario": "s", "controller": "ppo", "seed": 1, "training_seed": 0, "ace": 3.0},
        {"scenario": "s", "controller": "ppo", "seed": 2, "training_seed": 0, "ace": 1.0},
        {"scenario": "s", "controller": "ppo", "seed": 1, "training_seed": 1, "ace": 2.0},
        {"scenario": "s", "controller": "ppo", "seed": 2, "training_seed": 1, "ace": math.nan},
        {"scenario": "s", "controller": "lqr", "seed": 1, "training_seed": None, "ace": 0.5},
    ]
    # ACEs 1, 2, 3, nan (last): the lower median is 2, seed 1 of training seed 1
    assert median_ace_episode(records, "s", "ppo") == (1, 1)
    assert median_ace_episode(records, "s", "lqr") == (1, None)
    assert median_ace_episode(records, "s", "pid_los") is None


def test_episodes_to_draw_keeps_the_median_episode_with_its_trajectory() -> None:
    class Result:
        def __init__(self, seed: int, ace: float, kept: bool) -> None:
            self.scenario, self.controller, self.seed, self.training_seed = "s", "lqr", seed, None
            self.metrics = {"ace": ace}
            self.trajectory = trajectory(ace) if kept else {}

    drawn = episodes_to_draw([Result(1, 5.0, True), Result(2, 1.0, True), Result(3, 2.0, True)])
    assert drawn[("s", "lqr")].seed == 3
    assert episodes_to_draw([Result(1, 5.0, True), Result(3, 2.0, False)]) == {}


def test_both_references_are_drawn_in_every_column(tmp_path: Path) -> None:
    """The frozen optimum's episode beside the oracle's in each column, in its own colour
    and line, labelled; it has no column of its own and does not set the shared scale (a
    references column, with its own scale, would fit it)."""
    drawn = {
        "pid_los": DrawnEpisode(10003, trajectory(5.0), None),
        "lqr": DrawnEpisode(10003, trajectory(3.0), None),
        "oracle": DrawnEpisode(10003, trajectory(0.5), None),
        "oracle_frozen": DrawnEpisode(10003, trajectory(400.0), None),  # spins far away
    }
    path = np.array([[0.0, 0.0], [240.0, 0.0]])
    png, svgz = plot_scenario(
        tmp_path, "s", drawn, change_time=60.0, path_xy=path, ship_length=3.25, vector=True
    )
    root = parse(svgz).getroot()
    for name in ("oracle", "oracle_frozen"):
        assert len([g for g in root.iter(f"{SVG}g") if g.get("id") == f"{name}/track"]) == 2
    assert stroke(svgz, "oracle_frozen/track") == controller_style("oracle_frozen").color
    assert stroke(svgz, "oracle_frozen/track") != stroke(svgz, "oracle/track")
    text = svg_text(svgz)
    assert text.count("oracle_frozen (seed 10003), never adapts") == 2
    assert text.count("oracle (seed 10003), the reference") == 2
    with Image.open(png) as image:
        legends = json.loads(image.text[LEGEND_KEY])
    assert [title for title, _ in legends] == ["PID", "LQR"]
    assert all(("oracle_frozen", "oracle_frozen (seed 10003), never adapts") in [
        tuple(e) for e in entries] for _, entries in legends)  # fmt: skip
    # the shared scale fits the oracle and the controllers (e ≤ 5 m), not the frozen
    # optimum's 400 m
    ticks = {t.text.strip() for t in root.iter(f"{SVG}text") if (t.text or "").strip()}
    assert "5" in ticks and not {"300", "400"} & ticks


def test_the_ranking_figure_marks_the_frozen_optimum(tmp_path: Path) -> None:
    """A dash-dotted line on each cost-ratio panel at the frozen optimum's IQM and geometric
    mean of C_frozen / C_oracle over the split's trials, labelled; none without it."""
    episodes = two_scenario_episodes(("oracle_frozen", "reference", 24.0))
    splits = {"a": "catalogue", "b": "catalogue"}
    aggregate = aggregate_ranking(episodes, splits, {}, reps=50)
    assert {r["controller"] for r in aggregate} == {"pid_los", "lqr"}
    files = plot_ranking(tmp_path, aggregate, episodes, splits, vector=True)
    ratios = np.array([(24.0 + k) / (8.0 + k) for k in (1, 2, 0)] * 2)  # seeds 10000-10002
    marks = ranking_figures.frozen_marks(ratios)
    assert marks["cost_ratio_gmean"] == pytest.approx(np.exp(np.mean(np.log(ratios))))
    text = svg_text(files[1])
    for key in ("cost_ratio_iqm", "cost_ratio_gmean"):
        assert stroke(files[1], f"oracle_frozen/{key}") == controller_style("oracle_frozen").color
        assert f"optimum that never adapts ({marks[key]:.2f})" in text
    assert "oracle_frozen" in svg_text(files[3])  # its profile among the references
    without = [e for e in episodes if e["controller"] != "oracle_frozen"]
    files = plot_ranking(tmp_path / "bare", aggregate, without, splits, vector=True)
    assert "optimum that never adapts" not in svg_text(files[1])
