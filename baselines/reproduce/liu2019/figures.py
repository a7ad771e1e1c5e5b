"""Liu et al. (2019) §4: per case and unit reading, tracks, e(t), identified parameters
against the truth and the λ-LS-SVM change index λ_k."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from shipgym_baselines.records.episodes import EpisodeResult
from shipgym_baselines.reproduce.liu2019.experiment import CASES
from shipgym_baselines.reproduce.plotting import pyplot, save
from shipgym_baselines.reproduce.protocol import Outcome


def plots(outcome: Outcome, out_dir: Path) -> None:
    """``<case>_<reading>.png`` for every case and reading of the outcome."""
    for (case, reading), (scenario, episodes) in outcome.episodes.items():
        plot_case(case, reading, scenario, episodes, out_dir)


def plot_case(
    case: str,
    reading: str,
    scenario: Any,
    episodes: dict[str, tuple[EpisodeResult, Any]],
    out: Path,
) -> None:
    """Tracks, e(t), identified parameters vs truth and λ_k (first seed) of one case."""
    plt = pyplot()
    changed = CASES[case][1]
    truth_before, truth_after = scenario.schedule.nominal, scenario.schedule.final
    fig, axes = plt.subplots(2, 2, figsize=(12, 8))
    ax_track, ax_e, ax_p, ax_l = axes.ravel()
    pts = scenario.path.point(np.linspace(0.0, scenario.path.length, 300))
    ax_track.plot(pts[:, 0], pts[:, 1], "k--", lw=1, label="path")
    for name, (result, policy) in episodes.items():
        tr = result.trajectory
        ax_track.plot(tr["x"], tr["y"], lw=1, label=name)
        ax_e.plot(tr["t"], tr["cross_track_error"], lw=1, label=name)
        history = policy.param_history
        if history and policy.identifier is not None:
            t = [h["t"] for h in history]
            for key in changed:
                if key == "beta":  # not identifiable at these yaw rates (README)
                    continue
                scale = truth_after.as_dict()[key] or 1.0
                ax_p.plot(t, [h[key] / scale for h in history], lw=1, label=f"{name}: {key}")
        ident = policy.identifier
        if ident is not None and hasattr(ident, "lambda_c"):
            hist = [h for h in ident.history if "lambda1" in h]
            ax_l.semilogy(
                [h["t"] for h in hist],
                [max(h["lambda1"], 1e-12) for h in hist],
                lw=1,
                label=f"{name}: λ¹ (θ1)",
            )
            ax_l.semilogy(
                [h["t"] for h in hist],
                [max(h["lambda2"], 1e-12) for h in hist],
                lw=1,
                label=f"{name}: λ² (θ2)",
            )
            ax_l.axhline(ident.lambda_c[0], color="C0", ls=":", lw=1)
            ax_l.axhline(ident.lambda_c[1], color="C1", ls=":", lw=1)
    change = scenario.change_time
    for ax in (ax_e, ax_p, ax_l):
        ax.axvline(change, color="gray", ls=":", lw=1)
    ax_p.axhline(1.0, color="k", lw=0.8)
    before = [
        truth_before.as_dict()[k] / (truth_after.as_dict()[k] or 1.0)
        for k in changed
        if k != "beta"
    ]
    for value in before:
        ax_p.axhline(value, color="gray", lw=0.5, ls="--")
    ax_track.set(xlabel="x [m]", ylabel="y [m]", title=f"{case} ({reading})")
    ax_track.set_aspect("equal", adjustable="datalim")
    ax_e.set(xlabel="t [s]", ylabel="e [m]", title="cross-track error")
    ax_p.set(
        xlabel="t [s]",
        ylabel="identified / true (after change)",
        title="identified parameters (1 = truth after the change; β not shown)",
        ylim=(-0.5, 2.5),
    )
    ax_l.set(xlabel="t [s]", ylabel="λ_k", title="λ-LS-SVM change index (dotted: λ_c)")
    for ax in axes.ravel():
        ax.legend(fontsize=6)
    fig.tight_layout()
    save(fig, out / f"{case}_{reading}.png")
