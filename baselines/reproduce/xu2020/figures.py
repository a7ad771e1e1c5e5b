"""Xu & Guedes Soares (2020) §6: per case, track, ψ and ψd, e(t), δ(t) of LOS and VF."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from shipgym_baselines.records.episodes import EpisodeResult
from shipgym_baselines.reproduce.plotting import pyplot, save
from shipgym_baselines.reproduce.protocol import Outcome
from shipgym_baselines.reproduce.xu2020.experiment import FirstRuns
from shipgym_baselines.reproduce.xu2020.scenarios import CASES
from shipgym_baselines.reproduce.xu2020.tables import LAW_NAMES


def plots(outcome: Outcome, out_dir: Path) -> None:
    """``xu2020_<case>.png`` per case run (:func:`plot_case`, the first gains design)."""
    first: FirstRuns = outcome.episodes
    for case in dict.fromkeys(c for c, _ in first.scenarios):
        scenarios = {s: sc for (c, s), sc in first.scenarios.items() if c == case}
        plot_case(case, scenarios, first.gains, first.examples, out_dir)


def plot_case(
    case: str,
    scenarios: dict[str, Any],
    gains_label: str,
    examples: dict[tuple[str, str, str], tuple[EpisodeResult, list[float]]],
    out: Path,
) -> None:
    """Per setting (``scenarios``: setting -> the case's scenario): track, ψ and ψd, e(t),
    δ(t) of LOS and VF (first seed)."""
    plt = pyplot()
    columns = len(scenarios)
    fig, axes = plt.subplots(4, columns, figsize=(5.5 * columns, 13), squeeze=False)
    for j, (setting, scenario) in enumerate(scenarios.items()):
        ax_track, ax_psi, ax_e, ax_d = axes[:, j]
        pts = scenario.path.point(np.linspace(0.0, scenario.path.length, 400))
        wp = np.asarray(scenario.config.path.waypoints)
        ax_track.plot(pts[:, 0], pts[:, 1], "k--", lw=1, label="path")
        ax_track.plot(wp[:, 0], wp[:, 1], "ko", ms=3)
        for k, ctrl in enumerate(LAW_NAMES):
            if (case, setting, ctrl) not in examples:
                continue
            result, desired = examples[(case, setting, ctrl)]
            tr = result.trajectory
            label = LAW_NAMES[ctrl]
            color = f"C{k}"
            ax_track.plot(tr["x"], tr["y"], color=color, lw=1, label=label)
            n = len(desired)
            ax_psi.plot(tr["t"], np.degrees(tr["heading"]), color=color, lw=1, label=f"ψ {label}")
            ax_psi.plot(
                tr["t"][:n],
                np.degrees(np.asarray(desired)),
                color=color,
                lw=0.8,
                ls=":",
                label=f"ψd {label}",
            )
            ax_e.plot(tr["t"], tr["cross_track_error"], color=color, lw=1, label=label)
            ax_d.plot(tr["t"], np.degrees(tr["rudder_angle"]), color=color, lw=0.8, label=label)
        ax_track.set(xlabel="x [m]", ylabel="y [m]", title=f"{case}, {setting}, {gains_label}")
        ax_track.set_aspect("equal", adjustable="datalim")
        ax_psi.set(xlabel="t [s]", ylabel="heading [deg]", title="ψ (solid), ψd (dotted)")
        ax_e.set(xlabel="t [s]", ylabel="e [m]", title="cross-track error")
        ax_d.set(xlabel="t [s]", ylabel="δ [deg]", title="rudder angle")
        for ax in axes[:, j]:
            ax.legend(fontsize=6)
    fig.suptitle(f"Xu & Guedes Soares (2020) {CASES[case][1]}: look-ahead LOS vs VF, Esso Osaka")
    fig.tight_layout()
    save(fig, out / f"xu2020_{case}.png", dpi=80)
