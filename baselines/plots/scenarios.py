"""The scenario figures: per scenario, small multiples of each controller's drawn episode
(track, cross-track error, rudder angle) by family, with both references in every column
(module doc of :mod:`.figures`), and which episode each draws."""

from __future__ import annotations

import json
import math
from collections import defaultdict
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from shipgym_baselines.escaping import plain_text
from shipgym_baselines.plots.files import (
    LEGEND_KEY,
    LEGEND_TOP_KEY,
    figure_stem,
    pyplot,
    save_figure,
)
from shipgym_baselines.plots.panels import (
    ORACLE_STYLE,
    PANEL_W,
    ROW_GAP,
    ROWS_H,
    TOP,
    column_axes,
    controller_family,
    family_panels,
    frozen_style,
    legend_below,
)
from shipgym_baselines.plots.style import controller_style
from shipgym_baselines.privileged import ORACLE, ORACLE_FROZEN
from shipgym_baselines.records.trajectories import DRAWN_KEYS, thin_trajectory

_CHANGE_STYLE = {"color": "black", "linestyle": (0, (1, 1.5)), "linewidth": 0.9}


#: the two references drawn in every column: legend suffix, widths (track, e, δ); their
#: styles: :func:`_reference_style`
_REFERENCE_LINES = {
    ORACLE: (", the reference", (1.2, 1.1, 1.4)),
    ORACLE_FROZEN: (", never adapts", (1.1, 1.0, 1.2)),
}


def _reference_style(name: str) -> dict[str, Any]:
    return ORACLE_STYLE if name == ORACLE else frozen_style()


class DrawnEpisode(NamedTuple):
    """The episode drawn for one (scenario, controller): evaluation seed, trajectory arrays
    (``t`` [s], ``x``/``y`` [m], ``cross_track_error`` [m], ``rudder_angle`` [rad]) and the
    training seed of a learned agent (None for the rest)."""

    seed: int
    trajectory: Mapping[str, Any]
    training_seed: int | None = None


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
        PANEL_W,
        ROWS_H[0],
    )
    return {
        "x": xy[0],
        "y": xy[1],
        "t": _limits([tr["t"] for tr in traces], 0.0),
        "e": _limits([tr["cross_track_error"] for tr in traces], 0.1),
        "d": _limits([np.degrees(tr["rudder_angle"]) for tr in traces], 0.5),
    }


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
    columns = column_axes(fig, ROWS_H, own_scale, legend_lines=max(most, 1))
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
            suffix, (w_track, w_e, w_d) = _REFERENCE_LINES[name]
            style = _reference_style(name)
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
            legend_below(ax_d, handles)
        legends.append((title + (" (own scale)" if own_scale[col] else ""), legend))
    fig.suptitle(
        _scenario_title(scenario, everything, change_time, ship_length, chosen_by),
        fontsize=10,
        y=1.0 - 0.15 / fig.get_figheight(),
        va="top",
    )
    stem = "scenario_" + figure_stem(scenario)
    below = TOP + sum(ROWS_H) + len(ROWS_H) * ROW_GAP  # [in] from the top: the legends
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
    :class:`~shipgym.scenarios.loader.Scenario`: the keyword arguments of :func:`plot_scenario`."""
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
    :func:`shipgym.scenarios.loader.load_scenario` takes (``run.json``'s settings; default: the
    name).  Returns every written file."""
    from shipgym.scenarios.loader import load_scenario

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
