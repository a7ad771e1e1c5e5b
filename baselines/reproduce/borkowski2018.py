"""Borkowski (2018) §5: adaptive vs fixed LQR track-keeping of the Mariner.

The experiment: the ``mariner_track`` scenario (the de Wit–Oppe Mariner from (0, −500) m at
7.7 m/s, waypoints (0, 0), (3000, 0), (3000, 1000), (10000, 1000) m, along-track switching
with R = 500 m, 1000 s, and the scenario's wind-wave yaw disturbance, our stand-in for the
paper's unspecified "signal characteristic of wind-induced sea waves") under ``lqr`` (the
gain of the initial guess, fixed) and ``adaptive_lqr`` (the gain re-solved from the
continuous-LS estimates), both with λy = 1/2000, λψ = 1, λδ = 5
(:mod:`baselines.classical.lqr`), from several initial guesses (a0, c0): the paper's
(0.02, 0.002) against the plant's linear part a1 = 0.018 1/s, a3 = 0.001 1/s², and our
choices around it (both ×½, ×1.5, ×⅓, ×3; c0 alone ×½ (= the truth) and ×3).

Rows per case: J of each controller (eq. (29), :func:`shipgym.metrics.compute_metrics`), the
ratio J_adaptive/J_fixed, whether the adaptive J is lower (SPEC §11: "adaptive LQR lowers J
against fixed LQR in every case tried" — the paper gives no J values), the final estimates
â, ĉ; and one summary row, the largest reduction 1 − J_adaptive/J_fixed over the cases next
to the paper's "reduction of the control quality indicator value to 15 %" (§5), read as
"by up to 15 %" (the literal reading, J_adaptive = 0.15·J_fixed, would be an 85 %
reduction; the sentence is ambiguous).  The wave realisation depends on the seed: ``ours``
is the mean over ``seeds`` episodes (``ours_std`` the population spread; the ratio is that
of the means).  Writes ``borkowski2018.md`` / ``.json`` and ``borkowski2018.png`` (track,
J(t), e(t), δ(t) for the paper's guess; â(t), ĉ(t) for every guess, against the truth).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from baselines.classical.lqr import LQR, AdaptiveLQR
from baselines.evaluation import EVAL_SEED_OFFSET, EpisodeResult, run_episode
from baselines.jsonout import dumps
from baselines.reproduce.rows import reproduction_row as _row
from shipgym.metrics import DEFAULT_SETTINGS
from shipgym.paths import wrap_angle
from shipgym.scenarios import load_scenario, scenario_from_dict
from shipgym.tracking import PathTracker

SCENARIO = "mariner_track"
#: Borkowski (2018) §5: the plant's linear part (a1 [1/s], a3 [1/s²]) and the initial guess
TRUTH = (0.018, 0.001)
PAPER_GUESS = (0.02, 0.002)
#: initial guesses (a0 [1/s], c0 [1/s²]): the paper's first, then ours
GUESSES = (
    PAPER_GUESS,
    (0.01, 0.001),
    (0.03, 0.003),
    (0.02 / 3, 0.002 / 3),
    (0.06, 0.006),
    (0.02, 0.001),
    (0.02, 0.006),
)
CONTROLLERS = (LQR, AdaptiveLQR)
#: Borkowski (2018) §5: "reduction of the control quality indicator value to 15 %"
PAPER_MAX_REDUCTION = 0.15


def case_name(a0: float, c0: float) -> str:
    return f"a0={a0:.4g}, c0={c0:.4g}"


def cumulative_J(scenario: Any, trajectory: dict[str, np.ndarray], dt: float) -> np.ndarray:
    """J(t) of eq. (29) along a trajectory, as :func:`compute_metrics` sums it (per step).

    Replays the env's path tracker on the logged positions; the heading is the logged
    (measured) one, equal to the true heading in this noise-free scenario.
    """
    s = DEFAULT_SETTINGS
    tracker = PathTracker(scenario.path, scenario.acceptance_radius, scenario.config.path.switching)
    x, y, psi, delta = (trajectory[k] for k in ("x", "y", "heading", "rudder_angle"))
    tracker.reset(float(x[0]), float(y[0]))
    terms = [0.0]
    for k in range(1, x.shape[0]):
        f = tracker.update(float(x[k]), float(y[k]))
        psi_r = wrap_angle(float(psi[k]) - f.path_angle)
        terms.append(
            s.lambda_y * f.cross_track**2 + s.lambda_psi * psi_r**2 + s.lambda_delta * delta[k] ** 2
        )
    return np.cumsum(terms) * dt


def run(
    out_dir: str | Path = "results/reproduce/borkowski2018",
    seeds: int = 1,
    progress: Any = None,
    guesses: tuple[tuple[float, float], ...] = GUESSES,
    time_limit: float | None = None,
    plot: bool = True,
) -> list[dict[str, Any]]:
    """Run the reproduction; returns the rows of SPEC §9b (plus ``seeds``).

    ``guesses``: initial (a0, c0) pairs; ``time_limit`` [s] shortens the 1000 s episode.
    """
    if seeds < 1:
        raise ValueError(f"seeds must be ≥ 1, got {seeds}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    scenario = load_scenario(SCENARIO)
    if time_limit is not None:
        data = scenario.config.model_dump()
        data["time_limit"] = float(time_limit)
        scenario = scenario_from_dict(data)
    rows: list[dict[str, Any]] = []
    examples: dict[tuple[str, str], tuple[EpisodeResult, Any]] = {}
    ratios: list[float] = []
    for a0, c0 in guesses:
        case = case_name(a0, c0)
        J: dict[str, float] = {}
        for cls in CONTROLLERS:
            values, stats = [], []
            for i in range(seeds):
                policy = cls(a0, c0)
                result = run_episode(policy, scenario, EVAL_SEED_OFFSET + i)
                values.append(result.metrics["J"])
                stats.append(policy.episode_stats())
                if i == 0:
                    examples[(case, cls.name)] = (result, policy)
                if progress is not None:
                    progress()
            J[cls.name] = float(np.mean(values))
            rows.append(_row(case, cls.name, "J", J[cls.name], None, seeds, np.std(values)))
            if cls is AdaptiveLQR:
                for key in ("a_hat", "c_hat"):
                    est = [s[key] for s in stats]
                    rows.append(_row(case, cls.name, key, np.mean(est), None, seeds, np.std(est)))
        ratio = J["adaptive_lqr"] / J["lqr"]
        ratios.append(ratio)
        rows.append(_row(case, "adaptive_lqr", "J_ratio", ratio, None, seeds))
        rows.append(_row(case, "adaptive_lqr", "adaptive_lower_J", ratio < 1.0, True, seeds))
    rows.append(
        _row(
            "all", "adaptive_lqr", "max_J_reduction", 1.0 - min(ratios), PAPER_MAX_REDUCTION, seeds
        )
    )
    rows.append(
        _row("all", "adaptive_lqr", "adaptive_lower_J", all(r < 1.0 for r in ratios), True, seeds)
    )
    (out / "borkowski2018.json").write_text(dumps(rows, indent=2))
    (out / "borkowski2018.md").write_text(markdown(rows))
    if plot:
        plot_runs(scenario, examples, case_name(*guesses[0]), out)
    return rows


def _fmt(value: Any, digits: int = 4) -> str:
    if value is None:
        return "–"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return f"{value:.{digits}g}"


def markdown(rows: list[dict[str, Any]]) -> str:
    """Table: one line per initial guess with J fixed, J adaptive, the ratio and â, ĉ."""
    index = {(r["case"], r["controller"], r["metric"]): r for r in rows}
    cases = list(dict.fromkeys(r["case"] for r in rows if r["case"] != "all"))
    head = ["initial guess", "J lqr", "J adaptive_lqr", "J_adaptive/J_fixed", "adaptive lower"]
    head += ["â [1/s]", "ĉ [1/s²]"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for case in cases:
        cells = [
            case + (" (paper)" if case == case_name(*PAPER_GUESS) else ""),
            _fmt(index[(case, "lqr", "J")]["ours"], 6),
            _fmt(index[(case, "adaptive_lqr", "J")]["ours"], 6),
            _fmt(index[(case, "adaptive_lqr", "J_ratio")]["ours"], 4),
            _fmt(index[(case, "adaptive_lqr", "adaptive_lower_J")]["ours"]),
            _fmt(index[(case, "adaptive_lqr", "a_hat")]["ours"], 4),
            _fmt(index[(case, "adaptive_lqr", "c_hat")]["ours"], 4),
        ]
        lines.append("| " + " | ".join(cells) + " |")
    red = index.get(("all", "adaptive_lqr", "max_J_reduction"))
    every = index.get(("all", "adaptive_lqr", "adaptive_lower_J"))
    note = "\n"
    if red is not None and every is not None:
        note += (
            f"Largest reduction 1 − J_adaptive/J_fixed: {_fmt(red['ours'], 3)} (paper: "
            f"'to 15 %', read as up to {red['paper']:.2f}).  Adaptive J lower in every case: "
            f"{_fmt(every['ours'])} (paper: yes).\n"
        )
    seeds = rows[0]["seeds"] if rows else 0
    note += (
        "\nJ: Borkowski (2018) eq. (29), ∫(λy·y_r² + λψ·ψ_r² + λδ·δ²)dt over the 1000 s run, "
        f"λy = 1/2000, λψ = 1, λδ = 5, mean over {seeds} seed(s).  Plant: mariner_track "
        "(a1 = 0.018 1/s, a2 = 37.2 s/rad², a3 = 0.001 1/s², wind-wave yaw disturbance).  "
        "â, ĉ: final continuous-LS estimates; â exceeds a1 because the linear fit absorbs the "
        "cubic damping a2·r³ of the turns.\n"
    )
    return "\n".join(lines) + "\n" + note


def plot_runs(
    scenario: Any,
    examples: dict[tuple[str, str], tuple[EpisodeResult, Any]],
    main_case: str,
    out: Path,
) -> None:
    """Track, J(t), e(t), δ(t) of the paper's guess; â(t), ĉ(t) of every guess."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

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
    fig.savefig(out / "borkowski2018.png", dpi=90)
    plt.close(fig)
