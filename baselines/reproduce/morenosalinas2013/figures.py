"""Moreno-Salinas et al. (2013) §4: u, v, r of every case, measured, plant and identified."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from shipgym.models.blanke import Blanke
from shipgym_baselines.reproduce.morenosalinas2013.experiment import (
    CASES,
    CONTROLLERS,
    DEG,
    SAMPLING_TIME,
)
from shipgym_baselines.reproduce.plotting import pyplot, save
from shipgym_baselines.reproduce.protocol import Outcome


def plots(outcome: Outcome, out_dir: Path) -> None:
    """``morenosalinas2013.png`` (:func:`plot_series`)."""
    plot_series(*outcome.episodes, out_dir)


def plot_series(
    plant: Blanke,
    truth: dict[str, np.ndarray],
    examples: dict[Any, Any],
    step: int,
    out: Path,
) -> None:
    """u, v, r of every case: measured (seed 0), plant, and the identified models."""
    plt = pyplot()
    fig, axes = plt.subplots(len(CASES), 3, figsize=(14, 3.0 * len(CASES)), squeeze=False)
    measured = examples["measured"]
    for i, case in enumerate(CASES):
        clean = truth[case][::step]
        t = SAMPLING_TIME * np.arange(clean.shape[0])
        for j, (key, label, scale) in enumerate(
            (("u", "u [m/s]", 1.0), ("v", "v [m/s]", 1.0), ("r", "r [deg/s]", 1.0 / DEG))
        ):
            ax = axes[i, j]
            ax.plot(t, measured[case][key] * scale, color="0.7", lw=0.6, label="measured")
            ax.plot(t, clean[:, 3 + j] * scale, "k", lw=1.2, label="plant")
            for k, controller in enumerate(CONTROLLERS):
                pred = examples[(case, controller)]
                ax.plot(
                    t, pred[:, 3 + j] * scale, ls="--" if k == 0 else ":", lw=1.2, label=controller
                )
            ax.set(xlabel="t [s]", ylabel=label)
            if j == 0:
                ax.set_title(case, loc="left", fontsize=9)
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("Moreno-Salinas et al. (2013): plant vs LS-SVM-identified Blanke model")
    fig.tight_layout()
    save(fig, out / "morenosalinas2013.png")
