"""The ranking figures, per split: rliable's interval estimates (``ranking_<split>``, the
frozen optimum marked) and the performance profiles of the cost ratio
(``profile_<split>``; module doc of :mod:`.figures`)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from shipgym_baselines.escaping import plain_text
from shipgym_baselines.plots.files import figure_stem, pyplot, save_figure
from shipgym_baselines.plots.panels import (
    column_axes,
    family_panels,
    frozen_style,
    legend_below,
    log_ratio_axis,
)
from shipgym_baselines.plots.style import controller_style
from shipgym_baselines.privileged import ORACLE_FROZEN
from shipgym_baselines.registry import BASELINE
from shipgym_baselines.scoring.headroom import trial_headroom
from shipgym_baselines.scoring.intervals import geometric_mean, interquartile_mean
from shipgym_baselines.scoring.ranking import PARTIAL, PROB, performance_profiles
from shipgym_baselines.scoring.scores import scored_episodes
from shipgym_baselines.scoring.splits import figure_title

#: bootstrap replications of the performance profiles' shaded intervals (rliable's bootstrap
#: costs ≈ 10 ms a replication for 20 controllers; the bands need no more)
PROFILE_REPS = 200


#: the label of the frozen optimum's marks in the ranking figure
FROZEN_LABEL = "optimum that never adapts"


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
            log_ratio_axis(ax, values + ([marks[key]] if key in marks else []))
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
    style = {k: v for k, v in frozen_style().items() if k != "zorder"}
    ax.axvline(x, lw=1.1, zorder=0.5, gid=f"{ORACLE_FROZEN}/{key}", **style)
    low_x, high_x = ax.get_xlim()
    ax.text(
        x,
        ax.get_ylim()[1] - 0.4,
        f" {FROZEN_LABEL} ({x:.2f}) ",
        fontsize=7,
        color=frozen_style()["color"],
        va="center",
        ha="right" if x > math.sqrt(low_x * high_x) else "left",
    )


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
    columns = column_axes(fig, (2.2,), [False] * len(panels), legend_lines=most)
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
        log_ratio_axis(ax, [taus[0], taus[-1]])
        ax.set_xlim(taus[0], taus[-1])
        legend_below(ax)
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
