"""Xu et al. (2021) §5.2: tracks, current, errors, rudder, command spectra and b̂."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import scipy.signal

from shipgym_baselines.records.episodes import EpisodeResult
from shipgym_baselines.reproduce.plotting import pyplot, save
from shipgym_baselines.reproduce.protocol import Outcome
from shipgym_baselines.reproduce.xu2021.controllers import Recorded
from shipgym_baselines.reproduce.xu2021.current import current_speed
from shipgym_baselines.reproduce.xu2021.experiment import FirstRuns
from shipgym_baselines.reproduce.xu2021.metrics import CUTOFF, DEG
from shipgym_baselines.reproduce.xu2021.scenario import switch_time


def plots(outcome: Outcome, out_dir: Path) -> None:
    """``xu2021.png`` (:func:`plot_runs`)."""
    first: FirstRuns = outcome.episodes
    plot_runs(first.scenario, first.examples, out_dir)


def plot_runs(
    scenario: Any,
    examples: dict[str, tuple[EpisodeResult, Recorded, dict[str, np.ndarray]]],
    out: Path,
) -> None:
    """Tracks, current speed (of the longest episode), e(t), ψ − ψd, δ(t) per controller,
    δc spectra, b̂(t)."""
    plt = pyplot()
    labels = list(examples)
    n_rudder = math.ceil(len(labels) / 2)
    fig, axes = plt.subplots(3 + n_rudder, 2, figsize=(13, 3.2 * (3 + n_rudder)))
    ax_track, ax_cur = axes[0]
    ax_e, ax_ref = axes[1]
    ax_psd, ax_b = axes[2]
    wp = np.asarray(scenario.path.waypoints)
    ax_track.plot(wp[:, 0], wp[:, 1], "k--o", lw=1, ms=3, label="path")
    t_switch = switch_time(scenario)
    dt = scenario.control_period
    longest, _, disturbances = max(examples.values(), key=lambda e: e[0].trajectory["t"].size)
    seed = longest.seed
    tc, vc = current_speed(disturbances)
    ax_cur.plot(tc, vc, lw=0.8, color="C7", label=f"seed {seed}")
    for k, label in enumerate(labels):
        result, rec, _ = examples[label]
        tr = result.trajectory
        style = {"color": f"C{k}", "lw": 1.0}
        ax_track.plot(tr["x"], tr["y"], label=label, **style)
        ax_e.plot(tr["t"], tr["cross_track_error"], label=label, **style)
        ax_ref.plot(rec.log["t"], DEG * np.array(rec.log["ref_error"]), label=label, **style)
        f, psd = scipy.signal.welch(DEG * tr["rudder_command"], fs=1.0 / dt, nperseg=256)
        ax_psd.semilogy(2.0 * math.pi * f[1:], psd[1:], label=label, **style)
        if np.isfinite(rec.log["b_hat"]).all():
            ax_b.plot(rec.log["t"], DEG * np.array(rec.log["b_hat"]), label=label, **style)
        ax = axes[3 + k // 2, k % 2]
        ax.plot(tr["t"], DEG * tr["rudder_command"], lw=0.6, color="0.6", label="command δc")
        ax.plot(tr["t"], DEG * tr["rudder_angle"], label="rudder δ", **style)
        ax.set(xlabel="t [s]", ylabel="δ [deg]", title=label)
    for ax in (ax_cur, ax_e, ax_ref, ax_b):
        ax.axvline(t_switch, color="k", lw=0.6, ls=":")
    ax_psd.axvline(CUTOFF, color="k", lw=0.8, ls=":", label="ω = 0.25 rad/s")
    ax_track.set(xlabel="x [m]", ylabel="y [m]", title=f"{scenario.name}, seed {seed}")
    ax_cur.set(xlabel="t [s]", ylabel="current speed [m/s]", title="current (towards 180°)")
    ax_e.set(xlabel="t [s]", ylabel="e [m]", title="cross-track error")
    ax_ref.set(xlabel="t [s]", ylabel="ψ − ψd [deg]", title="heading error to the reference")
    ax_psd.set(xlabel="ω [rad/s]", ylabel="PSD δc [deg²/Hz]", title="rudder command spectrum")
    ax_b.set(xlabel="t [s]", ylabel="b̂ [deg/s]", title="bias estimate b̂")
    for ax in axes.ravel():
        if ax.has_data():
            ax.legend(fontsize=6)
        else:
            ax.set_visible(False)
    fig.suptitle("Xu, Oliveira & Guedes Soares (2021) §5.2: Esso Osaka in a two-phase current")
    fig.tight_layout()
    save(fig, out / "xu2021.png")
