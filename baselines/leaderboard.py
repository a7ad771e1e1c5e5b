"""The leaderboard: every controller on every suite scenario × seeds, one table (SPEC §9).

Jobs are independent (controller, scenario, seed) tasks.  ``local`` runs them in a process
pool; ``ray`` submits the same job function to a Ray cluster (``pip install shipgym[ray]``).
"""

from __future__ import annotations

import csv
import math
import os
import sys
from collections.abc import Callable, Iterable
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from baselines.errors import BackendError, ControllerError, RunError, check_seeds
from baselines.evaluation import EVAL_SEED_OFFSET, EpisodeResult, evaluate
from baselines.jsonout import dumps
from baselines.registry import applies_to, controller_kind, is_controller, unknown_controller
from baselines.suite import load_suite
from shipgym.metrics import aggregate
from shipgym.scenarios import load_scenario

#: metric columns aggregated over seeds (mean and *_std)
COLUMNS = (
    "ace",
    "ace_L",
    "t_c",
    "return",
    "rudder_travel",
    "J",
    "success",
    "compute_ms",
    "mean_abs_cross_track",
    "max_abs_cross_track",
)


#: training-cost columns, present for learned agents only
TRAINING_COLUMNS = ("train_env_steps", "train_wall_s")


def controller_label(controller: str) -> str:
    """The table name of a controller: its registry name, or a trained agent's folder name
    (the folder holding a ``.zip``, plus the zip's stem unless it is ``model``)."""
    path = Path(controller)
    if path.suffix == ".zip":
        stem = "" if path.stem == "model" else f"/{path.stem}"
        return f"{path.resolve().parent.name}{stem}"
    return path.resolve().name if path.exists() else controller


def check_controllers(names: list[str]) -> list[str]:
    """The table labels of ``names``; a clear error, before any job runs, for a name that
    is neither a controller nor a trained agent, and for two names with the same label."""
    labels = []
    for name in names:
        if not is_controller(name):
            raise ControllerError(unknown_controller(name))
        labels.append(controller_label(name))
    duplicates = sorted({label for label in labels if labels.count(label) > 1})
    if duplicates:
        raise RunError(f"controllers {names} give the same table name(s) {duplicates}")
    return labels


def scenario_split(scenario: str) -> str:
    """``heldout`` for named held-out test scenarios (``heldout:3``), else ``catalogue``."""
    return "heldout" if scenario.startswith("heldout:") else "catalogue"


def run_job(job: tuple[str, str, int]) -> EpisodeResult:
    """One (controller, scenario, seed) episode; top-level so process pools can pickle it."""
    controller, scenario, seed = job
    result = evaluate(controller, scenario, [seed])[0]
    result.controller = controller_label(controller)
    result.scenario = scenario  # as the suite names it (a YAML path stays a path)
    return result


def _run_local(jobs: list, workers: int, progress: Callable[[], None]) -> list[EpisodeResult]:
    if workers <= 1:
        out = []
        for job in jobs:
            out.append(run_job(job))
            progress()
        return out
    out = []
    with ProcessPoolExecutor(max_workers=workers) as pool:
        for fut in as_completed([pool.submit(run_job, j) for j in jobs]):
            out.append(fut.result())
            progress()
    return out


def _run_ray(jobs: list, progress: Callable[[], None]) -> list[EpisodeResult]:
    try:
        import ray
    except ImportError as exc:
        raise BackendError("--backend ray needs Ray: pip install 'shipgym[ray]'") from exc
    if not ray.is_initialized():
        ray.init(address=os.environ.get("RAY_ADDRESS"), ignore_reinit_error=True)
    remote = ray.remote(run_job)
    pending = [remote.remote(j) for j in jobs]
    out = []
    while pending:
        done, pending = ray.wait(pending)
        out.extend(ray.get(done))
        for _ in done:
            progress()
    return out


def run_leaderboard(
    suite: str = "default",
    seeds: int | None = None,
    out_dir: str | os.PathLike = "results/leaderboard",
    backend: str = "local",
    workers: int | None = None,
    controllers: Iterable[str] | None = None,
    show_progress: bool = True,
) -> list[dict[str, Any]]:
    """Run the suite, write leaderboard.{md,csv,json} and plots; return the aggregate rows."""
    spec = load_suite(suite)
    n_seeds = int(seeds if seeds is not None else spec.seeds)
    check_seeds(n_seeds, "--seeds")
    names = list(controllers) if controllers else list(spec.controllers)
    labels = check_controllers(names)
    scenarios = spec.all_scenarios()
    seed_list = [EVAL_SEED_OFFSET + i for i in range(n_seeds)]
    ships = {s: load_scenario(s).model.name for s in scenarios}
    jobs = [
        (c, s, seed)
        for s in scenarios
        for c in names
        if applies_to(controller_label(c), ships[s])
        for seed in seed_list
    ]
    bar = tqdm(total=len(jobs), desc="leaderboard", file=sys.stderr, disable=not show_progress)
    if backend == "local":
        results = _run_local(jobs, workers or os.cpu_count() or 1, lambda: bar.update(1))
    elif backend == "ray":
        results = _run_ray(jobs, lambda: bar.update(1))
    else:
        raise RunError(f"unknown backend {backend!r}; valid: local, ray")
    bar.close()
    # completion order varies between runs: aggregate in a fixed order (bit-stable means)
    results.sort(key=lambda r: (r.scenario, r.controller, r.seed))
    rows = aggregate_results(results, scenarios, labels)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_tables(rows, out)
    plot_results(results, out)
    return rows


def aggregate_results(
    results: list[EpisodeResult], scenarios: list[str], controllers: list[str]
) -> list[dict[str, Any]]:
    rows = []
    for scenario in scenarios:
        for controller in controllers:
            group = [r for r in results if r.scenario == scenario and r.controller == controller]
            if not group:  # the controller does not apply to this scenario's ship: shown
                rows.append(
                    {
                        "scenario": scenario,
                        "split": scenario_split(scenario),
                        "controller": controller,
                        "kind": controller_kind(controller),
                        "seeds": 0,
                        "applies": False,
                        **{k: None for key in COLUMNS for k in (key, f"{key}_std")},
                    }
                )
                continue
            keys = COLUMNS + tuple(k for k in TRAINING_COLUMNS if k in group[0].metrics)
            agg = aggregate([r.metrics for r in group], keys)
            rows.append(
                {
                    "scenario": scenario,
                    "split": scenario_split(scenario),
                    "controller": controller,
                    "kind": group[0].kind,
                    "applies": True,
                    "seeds": len(group),
                    **{k: v for k, v in agg.items() if k != "n"},
                }
            )
    return rows


def _fmt(value: Any, std: Any = None) -> str:
    if isinstance(value, float):
        if math.isinf(value):
            return "never" if value > 0 else "-inf"
        if math.isnan(value):
            return "–"
        text = f"{value:.3f}"
        if isinstance(std, float) and math.isfinite(std):
            text += f" ± {std:.3f}"
        return text
    return str(value)


def write_tables(rows: list[dict[str, Any]], out: Path) -> None:
    (out / "leaderboard.json").write_text(dumps(rows, indent=2))
    keys = list(dict.fromkeys(k for r in rows for k in r))  # learned rows add training cost
    with open(out / "leaderboard.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=keys, restval="")
        writer.writeheader()
        writer.writerows(rows)
    (out / "leaderboard.md").write_text(markdown_table(rows) + generalisation_table(rows))
    (out / "generalisation.json").write_text(dumps(generalisation(rows), indent=2))


def generalisation(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per controller: mean ACE/L, return and success on catalogue vs held-out scenarios.

    Means are over the scenarios of each split on which *every* controller of the table
    ran (so that all controllers are compared on the same set; ``*_scenarios`` counts them).
    """
    controllers = list(dict.fromkeys(r["controller"] for r in rows))
    common = {}
    for split in ("catalogue", "heldout"):
        scenarios = dict.fromkeys(r["scenario"] for r in rows if r["split"] == split)
        common[split] = [
            s for s in scenarios if all(r.get("applies", True) for r in rows if r["scenario"] == s)
        ]
    out = []
    for controller in controllers:
        mine = [r for r in rows if r["controller"] == controller]
        entry: dict[str, Any] = {"controller": controller, "kind": mine[0]["kind"]}
        for split in ("catalogue", "heldout"):
            group = [r for r in mine if r["scenario"] in common[split]]
            entry[f"{split}_scenarios"] = len(group)
            for key in ("ace_L", "return", "success"):
                values = [r[key] for r in group if isinstance(r[key], float)]
                entry[f"{split}_{key}"] = float(np.mean(values)) if values else math.nan
        out.append(entry)
    return out


def generalisation_table(rows: list[dict[str, Any]]) -> str:
    """Markdown of :func:`generalisation` (empty when the suite has no held-out scenarios)."""
    if not any(r["split"] == "heldout" for r in rows):
        return ""
    gen = generalisation(rows)
    lines = [
        "\n## Generalisation: catalogue vs held-out scenarios\n\nMeans over the scenarios "
        "of each split on which every controller ran "
        f"({gen[0]['catalogue_scenarios']} catalogue, {gen[0]['heldout_scenarios']} held-out).\n",
        "| controller | kind | ACE/L catalogue | ACE/L held-out | return catalogue | "
        "return held-out | success catalogue | success held-out |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for g in gen:
        cells = [g["controller"], g["kind"]]
        cells += [
            _fmt(g[f"{split}_{key}"])
            for key in ("ace_L", "return", "success")
            for split in ("catalogue", "heldout")
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def markdown_table(rows: list[dict[str, Any]]) -> str:
    head = [
        "scenario",
        "controller",
        "kind",
        "ACE [m]",
        "ACE/L",
        "t_c [s]",
        "return",
        "rudder travel [rad]",
        "J",
        "success",
        "compute [ms]",
    ]
    keys = ["ace", "ace_L", "t_c", "return", "rudder_travel", "J", "success", "compute_ms"]
    head.append("training")
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        cells = [r["scenario"], r["controller"], r["kind"]]
        if not r.get("applies", True):
            lines.append("| " + " | ".join(cells + ["does not apply"] + [""] * len(keys)) + " |")
            continue
        cells += [_fmt(r[k], r.get(f"{k}_std")) for k in keys]
        cost = ""
        if "train_env_steps" in r:
            cost = f"{r['train_env_steps'] / 1e3:.0f} k steps, {r['train_wall_s'] / 60:.1f} min"
        cells.append(cost)
        lines.append("| " + " | ".join(cells) + " |")
    note = (
        "\nMean ± std over seeds. t_c: moment (s of simulation time) from which |e| stays "
        "below the threshold after the first parameter change; 'never' when it does not. "
        "training: env steps and wall time of a learned agent's training run.\n"
    )
    return "\n".join(lines) + "\n" + note


def plot_results(results: list[EpisodeResult], out: Path) -> None:
    """Per scenario: tracks over the path, e(t) and δ(t) of the first seed of each controller."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    for scenario in sorted({r.scenario for r in results}):
        sc = load_scenario(scenario)
        first: dict[str, EpisodeResult] = {}
        for r in sorted(results, key=lambda r: r.seed):
            if r.scenario == scenario:
                first.setdefault(r.controller, r)
        fig, axes = plt.subplots(1, 3, figsize=(15, 4))
        pts = sc.path.point(np.linspace(0, sc.path.length, 300))
        axes[0].plot(pts[:, 0], pts[:, 1], "k--", lw=1, label="path")
        for name, r in first.items():
            tr = r.trajectory
            axes[0].plot(tr["x"], tr["y"], lw=1, label=name)
            axes[1].plot(tr["t"], tr["cross_track_error"], lw=1, label=name)
            axes[2].plot(tr["t"], np.degrees(tr["rudder_angle"]), lw=1, label=name)
        if sc.change_time is not None:
            for ax in axes[1:]:
                ax.axvline(sc.change_time, color="gray", ls=":", lw=1)
        axes[0].set(xlabel="x [m]", ylabel="y [m]", title=f"{scenario}: tracks")
        axes[0].set_aspect("equal", adjustable="datalim")
        axes[1].set(xlabel="t [s]", ylabel="e [m]", title="cross-track error")
        axes[2].set(xlabel="t [s]", ylabel="δ [deg]", title="rudder angle")
        axes[0].legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(out / f"{scenario.replace(':', '_')}.png", dpi=90)
        plt.close(fig)
