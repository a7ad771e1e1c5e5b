"""The leaderboard's figures: per-scenario small multiples and the rliable ranking.

Every figure uses :func:`shipgym_baselines.leaderboard.style.controller_style` (one colour and line
style per controller, the same in every figure), labels its axes with units, keeps legends
outside the data and is written twice (:func:`save_figure`): drawn at
:data:`~shipgym_baselines.leaderboard.style.FIGURE_DPI` (200 dpi), as a palette PNG of at most
:data:`PAGE_WIDTH` pixels (the page's image), and as a vector copy beside it (SVG; the
scenario figures, which hold the long trajectories, as gzip-compressed SVGZ).  Matplotlib runs
on the Agg backend.

What a run hands in:

* ``drawn``: (scenario, controller) → :class:`DrawnEpisode` (or a plain ``(seed,
  trajectory)`` / ``(seed, trajectory, training_seed)`` tuple) — the episode to draw, its
  trajectory as :attr:`shipgym_baselines.records.episodes.EpisodeResult.trajectory` keeps it
  (arrays ``t`` [s], ``x``, ``y`` [m], ``cross_track_error`` [m], ``rudder_angle`` [rad], …).
  :func:`median_ace_episode` names the episode to keep (the median-ACE seed, and its training
  seed), :func:`episodes_to_draw` picks them from episode results.
* ``aggregate``: the ``aggregate.json`` rows
  (:func:`shipgym_baselines.leaderboard.ranking.aggregate_ranking`);
  ``episodes``: the ``episodes.jsonl`` records; ``splits``: scenario → split.

Functions (each returns the written files, PNG then SVG):

* :func:`plot_scenario` ``(out_dir, scenario, drawn, change_time, path_xy=None,
  ship_length=None, kinds=None, chosen_by="median-ACE")`` — one scenario: a grid with one
  column per controller family (at most :data:`PANEL_CONTROLLERS` controllers a column) and
  three rows with the same axes in every column: track x–y over the path, e(t), δ(t); the
  oracle's episode (controller ``oracle``) drawn in every column as the reference, and the
  frozen optimum's (``oracle_frozen``, dash-dotted, "never adapts"); the
  parameter-change time as a labelled vertical line ("change at t = … s") and each ship's
  position at that time; the title and legends say which episode is drawn.  File
  ``scenario_<name>``.
* :func:`plot_scenarios` ``(out_dir, drawn, scenarios=None, kinds=None,
  chosen_by="median-ACE")`` — every scenario of ``drawn``; change time, path and ship
  length read from the scenario (:func:`shipgym.scenarios.load_scenario` of
  ``scenarios[name]``, else of the name).
* :func:`plot_ranking` ``(out_dir, aggregate, episodes, splits, kinds=None)`` — per split: rliable's
  interval estimates (IQM and geometric mean of the cost ratio C / C_oracle on a log axis,
  P(improvement over pid_los) and the failure rate, 95 % intervals; with the frozen
  optimum's episodes, a dash-dotted line on each cost-ratio panel where it lies: the IQM
  and the geometric mean of its ratios C_frozen / C_oracle over the split's trials; file
  ``ranking_<split>``) and performance profiles of the cost ratio (one panel per family,
  file ``profile_<split>``).

18 scenarios and the ranking of 20 controllers take about half a minute on one core.
"""

from __future__ import annotations

import gzip
import io
import json
import math
from collections import defaultdict
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from shipgym_baselines.leaderboard.escaping import plain_text
from shipgym_baselines.leaderboard.ranking import (
    BASELINE,
    ORACLE,
    ORACLE_FROZEN,
    PROB,
    REFERENCE_KIND,
)
from shipgym_baselines.leaderboard.splits import figure_title
from shipgym_baselines.leaderboard.style import FIGURE_DPI, controller_style
from shipgym_baselines.policy import FAMILIES
from shipgym_baselines.records.outfiles import write_bytes
from shipgym_baselines.records.trajectories import DRAWN_KEYS, thin_trajectory
from shipgym_baselines.registry import declared_traits

#: most controllers drawn in one panel; a bigger family is split over several columns
PANEL_CONTROLLERS = 5
#: bootstrap replications of the performance profiles' shaded intervals (rliable's bootstrap
#: costs ≈ 10 ms a replication for 20 controllers; the bands need no more)
PROFILE_REPS = 200
#: the figures' files: text kept as text in the SVG, a fixed hash salt (reproducible ids),
#: and lines simplified to 0.5 px (matplotlib drops a vertex that moves its line by less
#: than this fraction of a pixel; default 1/9): lighter files that look the same
LIGHT_FIGURES = {
    "svg.fonttype": "none",
    "svg.hashsalt": "shipgym",
    "path.simplify": True,
    "path.simplify_threshold": 0.5,
}
#: widest PNG [px]: a figure drawn at FIGURE_DPI is written at 1/2, 1/3, … of its pixels,
#: the first that fits (a 200-dpi figure at 100 dpi or less: the page shows no more; the
#: vector copy keeps every detail; fewer pixels barely lighten a line figure: its
#: compressed bytes follow the lines' length in pixels, not the area)
PAGE_WIDTH = 1400
#: a scenario figure's PNG text chunks for the page: its legends as JSON (a list
#: of [column title, [[controller, label], …]]; the oracle's label ends ", the reference",
#: the frozen optimum's ", never adapts")
#: and where they start (the fraction of the height from the top); the page shows the
#: image above that line and the legends as text (crisp at any zoom, and ≈ 15 % of the
#: image's bytes)
LEGEND_KEY = "shipgym:legend"
LEGEND_TOP_KEY = "shipgym:legend-top"
#: most colours of a page PNG's palette: the figure's own colours (every line, marker, text
#: and patch, an alpha one as it shows on white), each also half-way to white (the
#: antialiasing of a thin line on the white axes), and a ramp of PAGE_GREYS greys (text,
#: grid); every pixel takes its nearest (so a controller keeps its colour on the
#: page; an adaptive 64-colour palette spent itself on near-whites and greyed the lines)
PAGE_COLOURS = 256
PAGE_GREYS = 9
_CHANGE_STYLE = {"color": "black", "linestyle": (0, (1, 1.5)), "linewidth": 0.9}
#: the oracle's episode, drawn in every column as the reference
_ORACLE_STYLE = {"color": "black", "linestyle": (0, (4, 1.5)), "alpha": 0.75, "zorder": 1.5}
#: the frozen optimum's episode (``oracle_frozen``: the oracle's truth frozen at the start),
#: drawn in every column beside the oracle's: its fixed colour, dash-dotted
_FROZEN_STYLE = {
    "color": controller_style(ORACLE_FROZEN).color,
    "linestyle": (0, (5, 1.5, 1, 1.5)),
    "alpha": 0.85,
    "zorder": 1.4,
}
#: the two references drawn in every column: style, legend suffix, widths (track, e, δ)
_REFERENCE_LINES = {
    ORACLE: (_ORACLE_STYLE, ", the reference", (1.2, 1.1, 1.4)),
    ORACLE_FROZEN: (_FROZEN_STYLE, ", never adapts", (1.1, 1.0, 1.2)),
}
#: the label of the frozen optimum's marks in the ranking figure
FROZEN_LABEL = "optimum that never adapts"


class DrawnEpisode(NamedTuple):
    """The episode drawn for one (scenario, controller): evaluation seed, trajectory arrays
    (``t`` [s], ``x``/``y`` [m], ``cross_track_error`` [m], ``rudder_angle`` [rad]) and the
    training seed of a learned agent (None for the rest)."""

    seed: int
    trajectory: Mapping[str, Any]
    training_seed: int | None = None


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the non-interactive Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def figure_stem(name: str) -> str:
    """A file-name stem for a scenario or split: ``heldout:0`` → ``heldout_0``, a YAML path →
    its stem."""
    if name.endswith((".yaml", ".yml")) or "/" in name:
        name = Path(name).stem
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name)


def save_figure(
    fig: Any,
    out_dir: str | Path,
    stem: str,
    tight: bool = False,
    vector: str | None = None,
    page_text: Mapping[str, str] | None = None,
) -> list[Path]:
    """Write ``fig`` as ``<stem>.png`` (the page's image, :func:`write_page_png`) and, if
    asked, its vector copy ``<stem><vector>`` (``.svg``, or ``.svgz``: the SVG deflated, for
    a figure of long trajectories; None: none, the default of a run: the page
    shows the PNG and the copy would double the figures' weight) into ``out_dir`` (made if
    missing), close it and return the paths.  ``tight``: crop to what is drawn (for a
    figure drawn outside its canvas, as rliable's interval plot is); a layout engine's
    layout is computed once (the PNG) and kept for the SVG.  ``page_text``: text chunks
    of the PNG for the page (:data:`LEGEND_KEY`, :data:`LEGEND_TOP_KEY`)."""
    from PIL import Image

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / f"{stem}.png"] + ([out / f"{stem}{vector}"] if vector else [])
    bbox = "tight" if tight else None
    with pyplot().rc_context(LIGHT_FIGURES):
        if tight:  # the crop is savefig's: through a PNG
            png = io.BytesIO()
            fig.savefig(png, format="png", dpi=FIGURE_DPI, bbox_inches=bbox)
            with Image.open(png) as image:
                rgb = image.convert("RGB")
        else:  # the canvas's pixels as drawn (no PNG written and read back)
            fig.set_dpi(FIGURE_DPI)
            fig.canvas.draw()
            rgb = Image.fromarray(np.asarray(fig.canvas.buffer_rgba())[..., :3])
        write_page_png(rgb, paths[0], page_text, figure_colours(fig))
        if not vector:
            pyplot().close(fig)
            return paths
        fig.set_layout_engine("none")
        svg = io.BytesIO()
        fig.savefig(svg, format="svg", bbox_inches=bbox, metadata={"Date": None})
    if vector == ".svgz":  # mtime 0: the same figure gives the same bytes
        write_bytes(paths[1], gzip.compress(svg.getvalue(), compresslevel=9, mtime=0))
    else:
        write_bytes(paths[1], svg.getvalue())
    pyplot().close(fig)
    return paths


def figure_colours(fig: Any) -> set[tuple[float, float, float]]:
    """The RGB colours [0, 1] that ``fig``'s artists draw with (lines, markers, text,
    patches, collections), an alpha colour as it shows on white."""
    from matplotlib.collections import Collection
    from matplotlib.colors import to_rgba, to_rgba_array
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    from matplotlib.text import Text

    rgba: list[Any] = []
    for artist in fig.findobj():
        if isinstance(artist, Line2D):
            rgba.append(to_rgba(artist.get_color(), artist.get_alpha()))
            for marker in (artist.get_markerfacecolor(), artist.get_markeredgecolor()):
                if not (isinstance(marker, str) and marker == "none"):
                    rgba.append(to_rgba(marker, artist.get_alpha()))
        elif isinstance(artist, Text) and artist.get_text():
            rgba.append(to_rgba(artist.get_color(), artist.get_alpha()))
        elif isinstance(artist, Patch | Collection):
            faces = [artist.get_facecolor(), artist.get_edgecolor()]
            for colours in faces:
                rgba += list(to_rgba_array(colours))
    colours = set()
    for r, g, b, a in rgba:
        if a > 0.0:
            colours.add(tuple(float(v) * a + (1.0 - a) for v in (r, g, b)))
    return colours


def page_palette(colours: Iterable[tuple[float, float, float]]) -> list[tuple[int, int, int]]:
    """The page PNG's palette (:data:`PAGE_COLOURS`, 8-bit RGB): the grey ramp, then
    ``colours``, each also half-way to white; the first :data:`PAGE_COLOURS` distinct
    ones."""
    greys = [(g, g, g) for g in np.linspace(0.0, 1.0, PAGE_GREYS).tolist()]
    palette = []
    for c in [*greys, *sorted(colours)]:
        for t in (0.0, 0.5):
            palette.append(tuple(round(255.0 * (v * (1.0 - t) + t)) for v in c))
    return list(dict.fromkeys(palette))[:PAGE_COLOURS]


def write_page_png(
    rgb: Any,
    path: Path,
    text: Mapping[str, str] | None = None,
    colours: Iterable[tuple[float, float, float]] = (),
) -> None:
    """``rgb`` (a PIL RGB image of the figure drawn at :data:`FIGURE_DPI`) written as the
    page shows it (kept light: the page embeds it): reduced by the smallest whole factor that
    makes it at most :data:`PAGE_WIDTH` pixels wide (each pixel the mean of its block; the
    dpi recorded accordingly), each pixel the nearest colour of :func:`page_palette` of
    the figure's ``colours`` (:func:`figure_colours`; no dithering), deflated at the
    highest level; ``text``: its text chunks (key → value)."""
    from PIL import Image, PngImagePlugin

    info = PngImagePlugin.PngInfo()
    for key, value in (text or {}).items():
        info.add_itxt(key, value)
    factor = math.ceil(rgb.width / PAGE_WIDTH)
    if factor > 1:
        rgb = rgb.reduce(factor)
    entries = page_palette(colours)
    flat = [v for c in entries for v in c]
    palette_image = Image.new("P", (1, 1))
    palette_image.putpalette(flat + flat[:3] * (256 - len(entries)))
    indexed = rgb.quantize(palette=palette_image, dither=Image.Dither.NONE)
    page = io.BytesIO()
    indexed.save(page, format="PNG", optimize=True, dpi=(FIGURE_DPI / factor,) * 2, pnginfo=info)
    write_bytes(path, page.getvalue())


# ------------------------------------------------------------------ which episode to draw
def _ace(record: Mapping[str, Any]) -> float:
    value = record.get("ace")
    if value is None or not math.isfinite(float(value)):
        return math.inf  # an undefined ACE sorts last
    return float(value)


def median_ace_episode(
    records: Iterable[Mapping[str, Any]], scenario: str, controller: str
) -> tuple[int, int | None] | None:
    """(seed, training seed) of the median-ACE episode of one (scenario, controller) among
    ``records`` (``episodes.jsonl`` objects or result rows with ``ace``, ``seed`` and, for
    learned agents, ``training_seed``); with an even count the lower median, ties broken by
    (training seed, seed).  None if the pair has no episode."""
    mine = [
        r for r in records if r.get("scenario") == scenario and r.get("controller") == controller
    ]
    if not mine:
        return None
    mine.sort(key=lambda r: (_ace(r), _seed_key(r.get("training_seed")), int(r["seed"])))
    pick = mine[(len(mine) - 1) // 2]
    return int(pick["seed"]), pick.get("training_seed")


def _seed_key(seed: int | None) -> tuple[bool, int]:
    return (seed is None, seed if seed is not None else 0)


def episodes_to_draw(results: Iterable[Any]) -> dict[tuple[str, str], DrawnEpisode]:
    """The median-ACE episode of each (scenario, controller) of ``results``
    (:class:`~shipgym_baselines.records.episodes.EpisodeResult`), for :func:`plot_scenarios`; a
    pair whose median episode has no kept trajectory is left out."""
    results = list(results)
    records = [
        {
            "scenario": r.scenario,
            "controller": r.controller,
            "seed": r.seed,
            "training_seed": r.training_seed,
            "ace": r.metrics.get("ace"),
        }
        for r in results
    ]
    kept = {(r.scenario, r.controller, r.seed, r.training_seed): r for r in results if r.trajectory}
    drawn = {}
    for scenario, controller in dict.fromkeys((r.scenario, r.controller) for r in results):
        pick = median_ace_episode(records, scenario, controller)
        if pick is not None and (scenario, controller, *pick) in kept:
            r = kept[(scenario, controller, *pick)]
            drawn[(scenario, controller)] = DrawnEpisode(r.seed, r.trajectory, r.training_seed)
    return drawn


def _as_drawn(value: Any) -> DrawnEpisode:
    return value if isinstance(value, DrawnEpisode) else DrawnEpisode(*value)


# ---------------------------------------------------------------------------- families
def controller_family(name: str, kind: str | None = None) -> str:
    """The controller's family (one of :data:`FAMILIES`): the column it is drawn in.

    The family its registration declares (a shipped learned agent's: ``learned``,
    :func:`shipgym_baselines.registry.declared_traits`); for a name nothing declares one
    for (a plug-in, a renamed long form, a trained agent's folder), its ``kind``'s
    (``learned``; ``reference``: ``references``), else the family its name reads as,
    else ``other``."""
    family, _ = declared_traits(name)
    if family is not None:
        return family
    if kind == "learned":
        return "learned"
    if kind == REFERENCE_KIND:
        return "references"
    if name.startswith("pid"):
        return "PID"
    if name.endswith("lqr"):
        return "LQR"
    if name.startswith("nmpc"):
        return "NMPC"
    if "backstepping" in name:
        return "backstepping"
    return "other"


def family_panels(
    controllers: Iterable[str], kinds: Mapping[str, str] | None = None
) -> list[tuple[str, list[str]]]:
    """(title, controllers) of each panel column: families in :data:`FAMILIES` order, each
    split into chunks of at most :data:`PANEL_CONTROLLERS`, controllers in given order."""
    groups: dict[str, list[str]] = defaultdict(list)
    for name in controllers:
        groups[controller_family(name, (kinds or {}).get(name))].append(name)
    panels = []
    for family in FAMILIES:
        members = groups.get(family, [])
        chunks = [
            members[i : i + PANEL_CONTROLLERS] for i in range(0, len(members), PANEL_CONTROLLERS)
        ]
        for k, chunk in enumerate(chunks):
            title = family if len(chunks) == 1 else f"{family} ({k + 1}/{len(chunks)})"
            panels.append((title, chunk))
    return panels


# ------------------------------------------------------------------------ one scenario
def _episode_label(name: str, ep: DrawnEpisode) -> str:
    if ep.training_seed is None:
        return f"{name} (seed {ep.seed})"
    return f"{name} (seed {ep.seed}, training seed {ep.training_seed})"


def _which_episode(episodes: Mapping[str, DrawnEpisode], chosen_by: str) -> str:
    """The title's account of the drawn episodes (classical controllers have no training
    seed)."""
    seeds = {ep.seed for ep in episodes.values()}
    trained = {ep.training_seed for ep in episodes.values()} - {None}
    if len(seeds) > 1:
        return f"each controller's {chosen_by} episode (seed in the legend)"
    text = f"{chosen_by} seed {next(iter(seeds))}"
    if len(trained) == 1:
        return text + f" (training seed {next(iter(trained))})"
    return text + (" (training seeds in the legend)" if trained else "")


def _limits(arrays: Sequence[np.ndarray], pad: float) -> tuple[float, float]:
    """(low, high) of the finite values of ``arrays``, widened by 4 % and at least ``pad``."""
    finite = [a[np.isfinite(a)] for a in arrays]
    values = np.concatenate(finite) if finite else np.zeros(0)
    if values.size == 0:
        values = np.zeros(1)
    low, high = float(values.min()), float(values.max())
    margin = max(pad, 0.04 * (high - low))
    return low - margin, high + margin


def _equal_aspect(
    xlim: tuple[float, float], ylim: tuple[float, float], width: float, height: float
) -> tuple[tuple[float, float], tuple[float, float]]:
    """``xlim``, ``ylim`` [m] widened about their centres so that a panel of ``width`` ×
    ``height`` [in] shows x and y at the same scale."""
    dx, dy = xlim[1] - xlim[0], ylim[1] - ylim[0]
    if dy * width < dx * height:
        c, half = 0.5 * (ylim[0] + ylim[1]), 0.5 * dx * height / width
        return xlim, (c - half, c + half)
    c, half = 0.5 * (xlim[0] + xlim[1]), 0.5 * dy * width / height
    return (c - half, c + half), ylim


def _change_line(ax: Any, change_time: float | None) -> None:
    """The parameter-change time [s] as a labelled vertical line (call after the limits are
    set: the label goes to the line's roomier side)."""
    if change_time is None:
        return
    ax.axvline(change_time, **_CHANGE_STYLE)
    low, high = ax.get_xlim()
    right = change_time < low + 0.6 * (high - low)
    ax.text(
        change_time,
        0.98,
        f" change at t = {change_time:g} s ",
        transform=ax.get_xaxis_transform(),
        fontsize=6.5,
        va="top",
        ha="left" if right else "right",
        bbox={
            "boxstyle": "square,pad=0.1",
            "facecolor": "white",
            "edgecolor": "none",
            "alpha": 0.75,
        },
    )


#: layout of a scenario figure [in]: panel width, row heights (track, e, δ), margins, the gap
#: between columns, between rows, the legends' room and the extra room of an own-scale column
_PANEL_W, _ROWS_H = 2.4, (2.1, 1.6, 1.6)
_LEFT, _RIGHT, _TOP, _GAP, _ROW_GAP, _OWN_GAP = 0.8, 0.15, 0.65, 0.2, 0.5, 0.55
_LEGEND_LINE = 0.14  # [in] a legend entry


def _scales(
    lines: Mapping[str, Mapping[str, np.ndarray]],
    names: Sequence[str],
    path: np.ndarray,
    pad: float,
) -> dict[str, tuple[float, float]]:
    """Axis limits of the panels drawing ``names``: track x/y (equal scale), t, e, δ."""
    traces = [lines[n] for n in names]
    xy = _equal_aspect(
        _limits([path[:, 0]] + [tr["x"] for tr in traces], pad),
        _limits([path[:, 1]] + [tr["y"] for tr in traces], pad),
        _PANEL_W,
        _ROWS_H[0],
    )
    return {
        "x": xy[0],
        "y": xy[1],
        "t": _limits([tr["t"] for tr in traces], 0.0),
        "e": _limits([tr["cross_track_error"] for tr in traces], 0.1),
        "d": _limits([np.degrees(tr["rudder_angle"]) for tr in traces], 0.5),
    }


def _column_axes(
    fig: Any, rows_h: Sequence[float], own_scale: Sequence[bool], legend_lines: int
) -> list[list[Any]]:
    """One axes per row (heights ``rows_h`` [in]) in each of ``len(own_scale)`` columns, at
    fixed positions (no layout engine: fast, the same in every figure, and room for the
    legends below, :func:`_legend_below`); a column with its own scale gets room for its
    tick labels."""
    n = len(own_scale)
    width = _LEFT + n * _PANEL_W + (n - 1) * _GAP + _OWN_GAP * sum(own_scale[1:]) + _RIGHT
    height = _TOP + sum(rows_h) + len(rows_h) * _ROW_GAP + legend_lines * _LEGEND_LINE + 0.15
    fig.set_size_inches(width, height)
    columns, left = [], _LEFT
    for col in range(n):
        if col and own_scale[col]:
            left += _OWN_GAP
        top, axes = height - _TOP, []
        for h in rows_h:
            top -= h
            axes.append(fig.add_axes((left / width, top / height, _PANEL_W / width, h / height)))
            top -= _ROW_GAP
        columns.append(axes)
        left += _PANEL_W + _GAP
    return columns


def _legend_below(ax: Any, handles: Sequence[Any] | None = None) -> None:
    """The legend of a column under its bottom axes ``ax``, outside the data (in the room
    :func:`_column_axes` leaves)."""
    height = ax.get_position().height * ax.figure.get_figheight()
    if handles is None:
        handles, labels = ax.get_legend_handles_labels()
    else:
        labels = [h.get_label() for h in handles]
    ax.legend(
        handles,
        [plain_text(label) for label in labels],  # names drawn as typed
        loc="upper center",
        bbox_to_anchor=(0.5, -_ROW_GAP / height - 0.02),
        fontsize=6.5,
        frameon=False,
        borderaxespad=0.0,
    )


def plot_scenario(
    out_dir: str | Path,
    scenario: str,
    drawn: Mapping[str, DrawnEpisode | tuple],
    change_time: float | None,
    path_xy: np.ndarray | None = None,
    ship_length: float | None = None,
    kinds: Mapping[str, str] | None = None,
    chosen_by: str = "median-ACE",
    vector: bool = False,
) -> list[Path]:
    """Small multiples of one scenario (module doc) from ``drawn``: controller → episode;
    ``change_time`` [s] (None: no parameter change), ``path_xy`` (N, 2) points of the path
    [m], ``ship_length`` [m] (in the title), ``kinds``: controller → kind (learned agents
    outside the shipped names), ``chosen_by``: how the episodes were picked, for the title
    (:func:`median_ace_episode`'s "median-ACE", or e.g. "first").  Every column has the same
    axes, except the references' (zero_rudder, random: their own scale, so a drifting
    reference does not flatten the rest).  ``vector``: write the SVGZ copy too.  Returns
    the PNG (and SVGZ) paths."""
    plt = pyplot()
    everything = {name: _as_drawn(ep) for name, ep in drawn.items()}
    episodes = {name: ep for name, ep in everything.items() if name not in _REFERENCE_LINES}
    refs = [name for name in _REFERENCE_LINES if name in everything]
    # the shared scale fits the oracle, not the frozen optimum (which may spin a ship that
    # changed: it would flatten every column; it leaves the panels instead)
    oracle = [ORACLE] if ORACLE in everything else []
    panels = family_panels(episodes, kinds) or [("no episode kept", [])]
    lines = {  # M4: every pixel column keeps its extent (a limit cycle stays one)
        n: {
            k: np.asarray(v, dtype=np.float64)
            for k, v in thin_trajectory(ep.trajectory, DRAWN_KEYS).items()
        }
        for n, ep in everything.items()
    }
    path = np.asarray(path_xy, dtype=np.float64) if path_xy is not None else np.empty((0, 2))
    pad = ship_length or 1.0
    controlled = [n for n in episodes if controller_family(n, (kinds or {}).get(n)) != "references"]
    shared = _scales(lines, (controlled or list(episodes)) + oracle, path, pad)
    own_scale = [bool(controlled) and title.startswith("references") for title, _ in panels]
    fig = plt.figure()
    most = max(len(members) for _, members in panels) + len(refs)
    columns = _column_axes(fig, _ROWS_H, own_scale, legend_lines=max(most, 1))
    legends: list[tuple[str, list[tuple[str, str]]]] = []
    for col, ((title, members), (ax_track, ax_e, ax_d)) in enumerate(
        zip(panels, columns, strict=True)
    ):
        legend: list[tuple[str, str]] = []
        lim = _scales(lines, members + refs, path, pad) if own_scale[col] else shared
        handles: list[Any] = []
        if path.size:
            ax_track.plot(path[:, 0], path[:, 1], color="0.55", lw=2.2, alpha=0.5, zorder=1)
        for name in refs:  # the references in every column
            tr = lines[name]
            style, suffix, (w_track, w_e, w_d) = _REFERENCE_LINES[name]
            label = _episode_label(name, everything[name]) + suffix
            legend.append((name, label))
            handles += ax_track.plot(
                tr["x"], tr["y"], lw=w_track, label=label, gid=f"{name}/track", **style
            )
            ax_e.plot(tr["t"], tr["cross_track_error"], lw=w_e, gid=f"{name}/e", **style)
            ax_d.plot(
                tr["t"], np.degrees(tr["rudder_angle"]), lw=w_d, gid=f"{name}/rudder", **style
            )
        for name in members:
            tr, style = lines[name], controller_style(name)
            label = _episode_label(name, episodes[name])
            legend.append((name, label))
            handles += ax_track.plot(
                tr["x"], tr["y"], lw=1.0, label=label, gid=f"{name}/track", **style.kwargs()
            )
            if change_time is not None and tr["t"].size and tr["t"][-1] >= change_time:
                k = int(np.searchsorted(tr["t"], change_time))  # where the ship is at the change
                ax_track.plot(
                    tr["x"][k], tr["y"][k], marker=style.marker, ms=5, color=style.color, lw=0
                )
            ax_e.plot(tr["t"], tr["cross_track_error"], lw=0.9, gid=f"{name}/e", **style.kwargs())
            ax_d.plot(
                tr["t"],
                np.degrees(tr["rudder_angle"]),
                lw=0.9,
                gid=f"{name}/rudder",
                **style.kwargs(),
            )
        ax_track.set(xlim=lim["x"], ylim=lim["y"], xlabel="x [m]")
        ax_track.set_title(title + (" (own scale)" if own_scale[col] else ""), fontsize=9)
        ax_e.set(xlim=lim["t"], ylim=lim["e"], xlabel="t [s]")
        ax_d.set(xlim=lim["t"], ylim=lim["d"], xlabel="t [s]")
        for ax in (ax_e, ax_d):
            ax.axhline(0.0, color="0.7", lw=0.6, zorder=0)
            _change_line(ax, change_time)
        for ax, ylabel in zip(
            (ax_track, ax_e, ax_d),
            ("y [m]", "cross-track error e [m]", "rudder angle δ [deg]"),
            strict=True,
        ):
            ax.tick_params(labelsize=7)
            ax.xaxis.label.set_size(8)
            ax.grid(True, alpha=0.25)
            if col == 0 or own_scale[col]:
                ax.set_ylabel(ylabel if col == 0 else "", fontsize=8)
            else:
                ax.tick_params(labelleft=False)  # the same scale as the column to its left
        if handles:
            _legend_below(ax_d, handles)
        legends.append((title + (" (own scale)" if own_scale[col] else ""), legend))
    fig.suptitle(
        _scenario_title(scenario, everything, change_time, ship_length, chosen_by),
        fontsize=10,
        y=1.0 - 0.15 / fig.get_figheight(),
        va="top",
    )
    stem = "scenario_" + figure_stem(scenario)
    below = _TOP + sum(_ROWS_H) + len(_ROWS_H) * _ROW_GAP  # [in] from the top: the legends
    page_text = {
        LEGEND_KEY: json.dumps(legends, ensure_ascii=False),
        LEGEND_TOP_KEY: f"{below / fig.get_figheight():.6f}",
    }
    return save_figure(fig, out_dir, stem, vector=".svgz" if vector else None, page_text=page_text)


def _scenario_title(
    scenario: str,
    episodes: Mapping[str, DrawnEpisode],
    change_time: float | None,
    ship_length: float | None,
    chosen_by: str,
) -> str:
    change = (
        "no parameter change"
        if change_time is None
        else f"parameter change at t = {change_time:g} s (trials may jitter it)"
    )
    ship = f"ship length L = {ship_length:g} m; " if ship_length else ""
    which = _which_episode(episodes, chosen_by) if episodes else "no episode kept"
    return f"{plain_text(scenario)} — {ship}{change}; drawn: {which}"


def scenario_geometry(scenario: Any, points: int = 400) -> dict[str, Any]:
    """``change_time`` [s], ``path_xy`` (``points`` × 2) [m] and ``ship_length`` [m] of a
    :class:`~shipgym.scenarios.Scenario`: the keyword arguments of :func:`plot_scenario`."""
    path = scenario.path
    return {
        "change_time": scenario.change_time,
        "path_xy": np.asarray(path.point(np.linspace(0.0, path.length, points))),
        "ship_length": scenario.ship_length,
    }


def plot_scenarios(
    out_dir: str | Path,
    drawn: Mapping[tuple[str, str], DrawnEpisode | tuple],
    scenarios: Mapping[str, Any] | None = None,
    kinds: Mapping[str, str] | None = None,
    chosen_by: str = "median-ACE",
    vector: bool = False,
) -> list[Path]:
    """:func:`plot_scenario` for every scenario of ``drawn`` ((scenario, controller) →
    episode), in sorted order; ``scenarios``: name → what
    :func:`shipgym.scenarios.load_scenario` takes (``run.json``'s settings; default: the
    name).  Returns every written file."""
    from shipgym.scenarios import load_scenario

    by_scenario: dict[str, dict[str, DrawnEpisode | tuple]] = defaultdict(dict)
    for (scenario, controller), episode in drawn.items():
        by_scenario[scenario][controller] = episode
    files: list[Path] = []
    for name in sorted(by_scenario):
        spec = load_scenario((scenarios or {}).get(name, name))
        files += plot_scenario(
            out_dir,
            name,
            by_scenario[name],
            kinds=kinds,
            chosen_by=chosen_by,
            vector=vector,
            **scenario_geometry(spec),
        )
    return files


# ----------------------------------------------------------------------------- ranking
_RATIO_LABEL = "cost ratio C / C_oracle [–] (log)"
#: the intervals drawn per controller: key, panel title, axis label, reference lines
_INTERVAL_PANELS = (
    ("cost_ratio_iqm", "IQM cost ratio", _RATIO_LABEL, (1.0,)),
    ("cost_ratio_gmean", "geometric-mean cost ratio", _RATIO_LABEL, (1.0,)),
    (PROB, f"P(ratio < {BASELINE}'s)", "probability [–]", (0.5,)),
    ("failure_rate", "failure rate", "fraction of episodes [–]", ()),
)


def _interval(row: Mapping[str, Any], key: str) -> list[float]:
    ci = row.get(f"{key}_ci95") or [math.nan, math.nan]
    return [float(ci[0]), float(ci[1])]


def _value(row: Mapping[str, Any], key: str) -> float:
    value = row.get(key)
    return math.nan if value is None else float(value)


def plot_ranking(
    out_dir: str | Path,
    aggregate: Sequence[Mapping[str, Any]],
    episodes: Sequence[Mapping[str, Any]],
    splits: Mapping[str, str],
    kinds: Mapping[str, str] | None = None,
    vector: bool = False,
) -> list[Path]:
    """Per split of ``aggregate``: ``ranking_<split>`` (rliable's interval estimates, the
    cost ratios on a log axis; a row of the split's partial table is drawn too, its label
    saying on how many scenarios) and ``profile_<split>`` (performance profiles of the cost
    ratio from ``episodes``, one panel per family); see the module doc; ``vector``: their
    SVG copies too.  Returns every written file."""
    from shipgym_baselines.leaderboard.ranking import PARTIAL, trial_headroom

    files: list[Path] = []
    headroom = trial_headroom(episodes)
    for split in dict.fromkeys(r["split"].removesuffix(PARTIAL) for r in aggregate):
        rows = [r for r in aggregate if r["split"].removesuffix(PARTIAL) == split]
        common = max((r["scenarios"] for r in rows), key=len)
        frozen = [h for (s, _), h in headroom.items() if s in set(common)]
        files += _plot_intervals(out_dir, split, rows, vector, frozen)
        files += _plot_profiles(out_dir, split, episodes, splits, kinds, vector)
    return files


def _ranking_label(row: Mapping[str, Any], common: int) -> str:
    """A controller's name, with its scenario count when it is ranked on fewer."""
    n = len(row["scenarios"])
    return row["controller"] if n == common else f"{row['controller']} ({n} of {common} scen.)"


def frozen_marks(headroom: Sequence[float]) -> dict[str, float]:
    """Where the frozen optimum lies on the cost-ratio panels: the IQM and the geometric mean
    of its ratios C_frozen / C_oracle (``headroom``, one per trial); empty without any."""
    from shipgym_baselines.leaderboard.ranking import geometric_mean, interquartile_mean

    if not len(headroom):
        return {}
    values = np.asarray(headroom, dtype=np.float64)
    return {
        "cost_ratio_iqm": float(interquartile_mean(values)),
        "cost_ratio_gmean": float(geometric_mean(values)),
    }


def _plot_intervals(
    out_dir: str | Path,
    split: str,
    rows: Sequence[Mapping[str, Any]],
    vector: bool = False,
    frozen: Sequence[float] = (),
) -> list:
    """The interval estimates of ``rows`` (one split's); ``frozen``: the frozen optimum's
    ratios on the split's trials (:func:`frozen_marks`)."""
    from rliable import plot_utils

    marks = frozen_marks(frozen)
    plt = pyplot()
    rows = sorted(rows, key=lambda r: (-r["cost_ratio_iqm"], r["controller"]))  # best on top
    common = max(len(r["scenarios"]) for r in rows)
    # no P(ratio < pid_los's) panel where no row compares with pid_los (not ranked here)
    panels = [p for p in _INTERVAL_PANELS if any(r.get(p[0]) is not None for r in rows)]
    keys = [panel[0] for panel in panels]
    names = [r["controller"] for r in rows]
    point = {r["controller"]: np.array([_value(r, k) for k in keys]) for r in rows}
    interval = {r["controller"]: np.array([_interval(r, k) for k in keys]).T for r in rows}
    with plt.rc_context({"font.size": 8}):
        fig, axes = plot_utils.plot_interval_estimates(
            point,
            interval,
            metric_names=[panel[1] for panel in panels],
            algorithms=names,
            colors={n: controller_style(n).color for n in names},
            subfigure_width=3.4,
            row_height=0.3,
            xlabel="",
        )
    for ax, (key, _, label, refs) in zip(axes, panels, strict=True):
        if marks:  # a band above the top row for the frozen optimum's labels, in every panel
            low, high = ax.get_ylim()
            ax.set_ylim(low, high + 0.8)
        if key.startswith("cost_ratio"):
            values = [v for r in rows for v in (*_interval(r, key), _value(r, key))]
            _log_ratio_axis(ax, values + ([marks[key]] if key in marks else []))
        ax.set_xlabel(label, fontsize=9)
        ax.title.set_fontsize(11)
        ax.tick_params(labelsize=8)
        for x in refs:
            ax.axvline(x, color="0.45", lw=0.8, ls="--", zorder=0)
        if key in marks:
            _frozen_line(ax, marks[key], key)
    axes[0].set_yticklabels([plain_text(_ranking_label(r, common)) for r in rows], fontsize=9)
    for i, ax in enumerate(axes):
        for bars in ax.containers:  # rliable labels each interval bar with its controller
            for bar in bars:
                bar.set_gid(f"{bars.get_label()}/interval/{keys[i]}")
    fig.suptitle(
        f"Aggregate over {figure_title(split)}: point estimate (black) and 95 % "
        "stratified-bootstrap interval (bar), rliable; 1 = the oracle's cost, lower is better",
        fontsize=10,
        y=1.0 + 0.5 / fig.get_figheight(),  # above the panels' titles, however few rows
    )
    stem = "ranking_" + figure_stem(split)
    return save_figure(fig, out_dir, stem, tight=True, vector=".svg" if vector else None)


def _frozen_line(ax: Any, x: float, key: str) -> None:
    """The frozen optimum's place ``x`` [cost ratio] on a panel: a dash-dotted vertical line
    labelled :data:`FROZEN_LABEL` in the band :func:`_plot_intervals` adds above the top row
    (clear of the bars and of the panel's title)."""
    style = {k: v for k, v in _FROZEN_STYLE.items() if k != "zorder"}
    ax.axvline(x, lw=1.1, zorder=0.5, gid=f"{ORACLE_FROZEN}/{key}", **style)
    low_x, high_x = ax.get_xlim()
    ax.text(
        x,
        ax.get_ylim()[1] - 0.4,
        f" {FROZEN_LABEL} ({x:.2f}) ",
        fontsize=7,
        color=_FROZEN_STYLE["color"],
        va="center",
        ha="right" if x > math.sqrt(low_x * high_x) else "left",
    )


def _log_ratio_axis(ax: Any, values: Iterable[float], axis: str = "x") -> None:
    """A log ``axis`` ("x" or "y") over the finite positive ``values`` and 1 (the oracle),
    with plain number labels."""
    from matplotlib.ticker import LogLocator, NullFormatter, ScalarFormatter

    finite = [v for v in values if math.isfinite(v) and v > 0] + [1.0]
    low, high = min(finite), max(finite)
    getattr(ax, f"set_{axis}scale")("log")
    getattr(ax, f"set_{axis}lim")(low / 1.15, high * 1.15)
    scale = getattr(ax, f"{axis}axis")
    scale.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    formatter = ScalarFormatter()
    formatter.set_scientific(False)
    scale.set_major_formatter(formatter)
    scale.set_minor_formatter(NullFormatter())


def _taus(ratios: np.ndarray) -> np.ndarray:
    """Thresholds of the performance profile [cost ratio]: log-spaced from the lowest ratio
    (at most 1, the oracle) to the 99th percentile (at least 2)."""
    finite = ratios[np.isfinite(ratios) & (ratios > 0)] if ratios.size else ratios
    low, high = np.quantile(finite, [0.0, 0.99]) if finite.size else (1.0, 2.0)
    return np.geomspace(min(1.0, float(low)), max(2.0, float(high)), 121)


def _plot_profiles(
    out_dir: str | Path,
    split: str,
    episodes: Sequence[Mapping[str, Any]],
    splits: Mapping[str, str],
    kinds: Mapping[str, str] | None,
    vector: bool = False,
) -> list[Path]:
    from rliable import plot_utils

    from shipgym_baselines.leaderboard.ranking import performance_profiles, scored_episodes

    plt = pyplot()
    in_split = {s for s, sp in splits.items() if sp == split}
    ratios = np.array(
        [
            ep["cost_ratio"]
            for ep in scored_episodes(episodes)
            if ep["scenario"] in in_split and ep["cost_ratio"] is not None
        ]
    )
    taus = _taus(ratios)
    profiles, cis = performance_profiles(episodes, splits, split, taus, reps=PROFILE_REPS)
    panels = family_panels(profiles, kinds)
    if not panels:
        return []
    fig = plt.figure()
    most = max(len(members) for _, members in panels)
    columns = _column_axes(fig, (2.2,), [False] * len(panels), legend_lines=most)
    for col, ((title, members), (ax,)) in enumerate(zip(panels, columns, strict=True)):
        plot_utils.plot_performance_profiles(
            {m: profiles[m] for m in members},
            taus,
            performance_profile_cis={m: cis[m] for m in members},
            ax=ax,
            colors={m: controller_style(m).color for m in members},
            linestyles={m: controller_style(m).linestyle for m in members},
            xlabel="cost ratio τ [–] (log)",
            ylabel="" if col else "fraction of runs with ratio > τ",
            labelsize=8,
            ticklabelsize=7,
            wrect=4,
            hrect=4,
        )
        if col:
            ax.tick_params(labelleft=False)  # the same scale as the column to its left
        for line in ax.get_lines():  # rliable applies a linewidth keyword to its first line only
            line.set_linewidth(1.3)
            line.set_gid(f"{line.get_label()}/profile")
        ax.axvline(1.0, color="0.45", lw=0.8, ls="--", zorder=0)
        ax.set_title(title, fontsize=9)
        _log_ratio_axis(ax, [taus[0], taus[-1]])
        ax.set_xlim(taus[0], taus[-1])
        _legend_below(ax)
    fig.suptitle(
        f"Performance profiles of the cost ratio, {figure_title(split)} (95 % "
        "intervals shaded; dashed: the oracle = 1; lower curves are better)",
        fontsize=10,
        y=1.0 - 0.15 / fig.get_figheight(),
        va="top",
    )
    return save_figure(
        fig, out_dir, "profile_" + figure_stem(split), vector=".svg" if vector else None
    )


# ------------------------------------------------------------------ learning curves
#: stem of the learning-curve figure (the page places it with the ranking figures)
LEARNING_CURVES_STEM = "learning_curves"


def plot_learning_curves(
    out_dir: str | Path,
    curves: Mapping[str, Sequence[Mapping[str, Any]]],
    vector: bool = False,
    stem: str = LEARNING_CURVES_STEM,
) -> list[Path]:
    """``learning_curves``: one panel per learned agent, one line per training seed over
    env steps.  An agent whose every curve holds its selection metric (the validation cost
    ratio, C / C_oracle, geometric mean over the validation trials) is drawn on that, on a
    log axis with the oracle = 1 dashed: the gap to the oracle (a DAgger student's teacher)
    is the height above it, and the best point of each seed (the shipped model) is ringed;
    another on its validation mean return (a band of ± one std over the validation
    episodes).  ``curves``: agent → its seeds' curves (:func:`shipgym_baselines.learned.
    curves.agent_curves`); agents without curves are left out, nothing is drawn without
    any.  ``stem``: the file name without suffix."""
    drawn = {name: cs for name, cs in curves.items() if cs}
    if not drawn:
        return []
    plt = pyplot()
    n = len(drawn)
    cols = min(n, 3)
    rows = -(-n // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.0 * rows), squeeze=False)
    for ax, (name, cs) in zip(axes.flat, drawn.items(), strict=False):
        by_cost = all("selection" in c for c in cs)
        for curve in cs:
            steps = np.asarray(curve["env_steps"], dtype=float)
            label = f"seed {curve.get('seed', '?')}"
            if by_cost:
                ratio = np.asarray(curve["selection"], dtype=float)
                (line,) = ax.plot(steps, ratio, marker=".", label=label)
                best = int(np.argmin(ratio))
                ax.plot(steps[best], ratio[best], "o", mfc="none", color=line.get_color(), ms=9)
                continue
            mean = np.asarray(curve["mean_return"], dtype=float)
            std = np.asarray(curve["std_return"], dtype=float)
            (line,) = ax.plot(steps, mean, marker=".", label=label)
            ax.fill_between(steps, mean - std, mean + std, color=line.get_color(), alpha=0.15)
        if by_cost:
            _log_ratio_axis(ax, [v for c in cs for v in c["selection"]], axis="y")
            ax.axhline(1.0, label=f"{ORACLE} = 1", **_ORACLE_STYLE)
            ax.set_ylabel("validation cost / oracle's")
        else:
            ax.set_ylabel("validation mean return")
        ax.set_title(name)
        ax.set_xlabel("env steps")
        ax.legend(fontsize="small")
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    fig.tight_layout()
    return save_figure(fig, out_dir, stem, vector=".svg" if vector else None)
