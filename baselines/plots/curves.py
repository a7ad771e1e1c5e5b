"""The learning-curve figure of the learned agents (the page places it with the ranking
figures)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from shipgym_baselines.plots.files import pyplot, save_figure
from shipgym_baselines.plots.panels import ORACLE_STYLE, log_ratio_axis
from shipgym_baselines.privileged import ORACLE

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
            log_ratio_axis(ax, [v for c in cs for v in c["selection"]], axis="y")
            ax.axhline(1.0, label=f"{ORACLE} = 1", **ORACLE_STYLE)
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
