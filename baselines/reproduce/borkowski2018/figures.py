"""Borkowski (2018) §5: track, J(t), e(t), δ(t) of the paper's guess; â(t), ĉ(t) of all."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from shipgym_baselines.records.episodes import EpisodeResult
from shipgym_baselines.reproduce.borkowski2018.experiment import TRUTH
from shipgym_baselines.reproduce.borkowski2018.quality_index import cumulative_J
from shipgym_baselines.reproduce.plotting import pyplot, save
from shipgym_baselines.reproduce.protocol import Outcome


def plots(outcome: Outcome, out_dir: Path) -> None:
    """``borkowski2018.png`` (:func:`plot_runs`)."""
    scenario, examples, main_case = outcome.episodes
    plot_runs(scenario, examples, main_case, out_dir)


def plot_runs(
    scenario: Any,
    examples: dict[tuple[str, str], tuple[EpisodeResult, Any]],
    main_case: str,
    out: Path,
) -> None:
    """Track, J(t), e(t), δ(t) of the paper's guess; â(t), ĉ(t) of every guess."""
    plt = pyplot()
    fig, axes = plt.subplots(3, 2, figsize=(12, 11))
    ax_track, ax_J, ax_e, ax_d, ax_a, ax_c = axes.ravel()
    wp = np.asarray(scenario.path.waypoints)
    ax_track.plot(wp[:, 0], wp[:, 1], "k--", lw=1, label="track")
    dt = scenario.control_period
    for name, style in (("lqr", "--"), ("adaptive_lqr", "-")):
        result, _ = examples[(main_case, name)]
        tr = result.trajectory
        ax_track.plot(tr["x"], tr["y"], style, lw=1.2, label=name)
        ax_J.plot(tr["t"], cumulative_J(scenario, tr, dt), style, lw=1.2, label=name)
        ax_e.plot(tr["t"], tr["cross_track_error"], style, lw=1.2, label=name)
        ax_d.plot(tr["t"], np.degrees(tr["rudder_angle"]), style, lw=1.2, label=name)
    for (case, name), (_, policy) in examples.items():
        if name != "adaptive_lqr" or not policy.history:
            continue
        h = np.asarray(policy.history)
        main = case == main_case
        kw = {"lw": 1.5 if main else 0.7, "alpha": 1.0 if main else 0.6, "label": case}
        ax_a.plot(h[:, 0], h[:, 1], **kw)
        ax_c.plot(h[:, 0], h[:, 2], **kw)
    ax_a.axhline(TRUTH[0], color="k", lw=1, ls=":", label="a1 = 0.018")
    ax_c.axhline(TRUTH[1], color="k", lw=1, ls=":", label="a3 = 0.001")
    ax_track.set(xlabel="x [m]", ylabel="y [m]", title=f"mariner_track, {main_case}")
    ax_track.set_aspect("equal", adjustable="datalim")
    ax_J.set(xlabel="t [s]", ylabel="J", title="quality index J(t), eq. (29)")
    ax_e.set(xlabel="t [s]", ylabel="y_r [m]", title="cross-track error")
    ax_d.set(xlabel="t [s]", ylabel="δ [deg]", title="rudder angle")
    ax_a.set(xlabel="t [s]", ylabel="â [1/s]", title="continuous-LS estimate â")
    ax_c.set(xlabel="t [s]", ylabel="ĉ [1/s²]", title="continuous-LS estimate ĉ")
    ax_a.set_ylim(0.0, 0.07)
    ax_c.set_ylim(0.0, 0.007)
    for ax in axes.ravel():
        ax.legend(fontsize=6)
    fig.suptitle("Borkowski (2018): adaptive vs fixed LQR track-keeping (Mariner)")
    fig.tight_layout()
    save(fig, out / "borkowski2018.png")
