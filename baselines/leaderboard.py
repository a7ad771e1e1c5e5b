"""The leaderboard: every controller on every suite scenario × seeds, one table (SPEC §9).

Jobs are independent (controller, scenario, seed) tasks.  ``local`` runs them in a process
pool; ``ray`` submits the same job function to a Ray cluster (``pip install shipgym[ray]``).
The parent records each episode as it arrives (:mod:`baselines.runs`: ``run.json``,
``episodes.jsonl``), and the tables are aggregated from that record.
"""

from __future__ import annotations

import csv
import math
import os
import signal
import sys
from collections.abc import Callable, Iterable, Iterator, Mapping
from concurrent.futures import ProcessPoolExecutor, as_completed
from contextlib import closing
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from baselines.errors import BackendError, RunError, check_seeds
from baselines.evaluation import EVAL_SEED_OFFSET, EpisodeResult, evaluate
from baselines.jsonout import dumps
from baselines.registry import applies_to, controller_kind, controller_label
from baselines.runs import BACKENDS, RunLog, check_out_dir, episode_result, read_episodes
from baselines.suite import load_suite
from shipgym.config import is_path
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


def check_controllers(names: list[str]) -> list[str]:
    """The table labels of ``names``; a clear error, before any job runs, for a name that
    is neither a controller nor a trained agent, and for two names with the same label."""
    labels = [controller_label(name) for name in names]  # resolves each: a clear error
    duplicates = sorted({label for label in labels if labels.count(label) > 1})
    if duplicates:
        raise RunError(
            f"controllers {names} give the same table name(s) {duplicates}: give each its "
            "own name (a suite's long form {controller: ..., name: ...})"
        )
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


def _quiet_worker() -> None:
    """Pool workers ignore Ctrl-C (the parent stops them): no traceback from each."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _iter_local(jobs: list, workers: int) -> Iterator[EpisodeResult]:
    """The jobs' results as they finish (in turn, or in a pool of ``workers`` processes)."""
    if workers <= 1:
        for job in jobs:
            yield run_job(job)
        return
    pool = ProcessPoolExecutor(max_workers=workers, initializer=_quiet_worker)
    try:
        for fut in as_completed([pool.submit(run_job, j) for j in jobs]):
            yield fut.result()
    except BaseException:  # Ctrl-C, a failed job, or the consumer stopped: stop the workers
        workers_running = list((pool._processes or {}).values())  # shutdown forgets them
        pool.shutdown(wait=False, cancel_futures=True)
        for process in workers_running:
            process.terminate()
        raise
    pool.shutdown()


def _iter_ray(jobs: list) -> Iterator[EpisodeResult]:
    try:
        import ray
    except ImportError as exc:
        raise BackendError("--backend ray needs Ray: pip install 'shipgym[ray]'") from exc
    if not ray.is_initialized():
        ray.init(address=os.environ.get("RAY_ADDRESS"), ignore_reinit_error=True)
    remote = ray.remote(run_job)
    pending = [remote.remote(j) for j in jobs]
    try:
        while pending:
            done, pending = ray.wait(pending)
            yield from ray.get(done)
    except BaseException:
        for ref in pending:
            ray.cancel(ref, force=True)
        raise


def iter_results(jobs: list, backend: str, workers: int) -> Iterator[EpisodeResult]:
    """The results of ``jobs`` on ``backend`` (:data:`BACKENDS`), in completion order."""
    if backend == "local":
        return _iter_local(jobs, workers)
    if backend == "ray":
        return _iter_ray(jobs)
    raise RunError(f"unknown backend {backend!r}; valid: {', '.join(BACKENDS)}")


def _job_key(job: tuple[str, str, int]) -> tuple[str, str, int]:
    """(scenario, table name, seed): the key of the job's record in ``episodes.jsonl``."""
    controller, scenario, seed = job
    return (scenario, controller_label(controller), seed)


def suite_record(
    spec: Any, names: list[str], scenarios: Mapping[str, Any], seed_list: list[int]
) -> dict[str, Any]:
    """The resolved suite as ``run.json`` keeps it: seeds, controllers (table name, how the
    suite names it, kind), each scenario's settings and the pairs that do not apply."""
    ships = {s: sc.model.name for s, sc in scenarios.items()}
    controllers = [
        {
            "name": controller_label(c),
            "controller": c if isinstance(c, str) else c.model_dump(),  # the long form
            "kind": controller_kind(controller_label(c)),
        }
        for c in names
    ]
    return {
        "name": spec.name,
        "seeds": seed_list,
        "controllers": controllers,
        "scenarios": {s: sc.config.model_dump(mode="json") for s, sc in scenarios.items()},
        "does_not_apply": [
            [s, c["name"]]
            for s in scenarios
            for c in controllers
            if not applies_to(c["name"], ships[s])
        ],
    }


def run_leaderboard(
    suite: str = "default",
    seeds: int | None = None,
    out_dir: str | os.PathLike = "results/leaderboard",
    backend: str = "local",
    workers: int | None = None,
    controllers: Iterable[str] | None = None,
    show_progress: bool = True,
    resume: bool = False,
    force: bool = False,
    command: list[str] | None = None,
    on_episode: Callable[[EpisodeResult], None] | None = None,
) -> list[dict[str, Any]]:
    """Run the suite, write leaderboard.{md,csv,json}, generalisation.json and plots; return
    the aggregate rows.

    ``out_dir`` must be empty unless ``resume`` (run only the jobs missing from its
    ``episodes.jsonl``) or ``force`` (clear its earlier outputs); ``command``: the argv
    recorded in ``run.json`` (default ``sys.argv``); ``on_episode``: called in this process
    after each episode is recorded.  Ctrl-C raises :class:`~baselines.runs.RunInterrupted`.
    """
    check_out_dir(out_dir, resume=resume, force=force)  # before any work
    if backend not in BACKENDS:
        raise RunError(f"unknown backend {backend!r}; valid: {', '.join(BACKENDS)}")
    spec = load_suite(suite)
    n_seeds = int(seeds if seeds is not None else spec.seeds)
    check_seeds(n_seeds, "--seeds")
    names = list(controllers) if controllers else list(spec.controllers)
    check_controllers(names)
    seed_list = [EVAL_SEED_OFFSET + i for i in range(n_seeds)]
    scenarios = {s: load_scenario(s) for s in spec.all_scenarios()}
    record = suite_record(spec, names, scenarios, seed_list)
    skip = {tuple(pair) for pair in record["does_not_apply"]}
    jobs = [
        (c, s, seed)
        for s in scenarios
        for c in names
        if (s, controller_label(c)) not in skip
        for seed in seed_list
    ]
    log = RunLog.open(
        out_dir,
        command=sys.argv if command is None else command,
        suite=record,
        jobs=len(jobs),
        resume=resume,
        force=force,
    )
    todo = [job for job in jobs if _job_key(job) not in log.done]
    bar = tqdm(
        total=len(jobs),
        initial=len(jobs) - len(todo),
        desc="leaderboard",
        file=sys.stderr,
        disable=not show_progress,
    )
    with (
        log.recording(),
        closing(iter_results(todo, backend, workers or os.cpu_count() or 1)) as results,
    ):
        try:
            for result in results:
                log.append(result, keep_trajectory=result.seed == seed_list[0])
                bar.update(1)
                if on_episode is not None:
                    on_episode(result)
        finally:
            bar.close()
        return write_results(log.folder, log.record["suite"], load_results(log.folder))


def load_results(folder: str | os.PathLike) -> list[EpisodeResult]:
    """The episodes recorded in a run folder's ``episodes.jsonl`` (trajectories if kept)."""
    return [episode_result(r, folder) for r in read_episodes(folder)]


def write_results(
    out: str | os.PathLike, suite: Mapping[str, Any], results: list[EpisodeResult]
) -> list[dict[str, Any]]:
    """Tables and plots into ``out`` from episode results and a suite as ``run.json`` keeps
    it (:func:`suite_record`); returns the rows."""
    # completion order varies between runs: aggregate in a fixed order (bit-stable means)
    results = sorted(results, key=lambda r: (r.scenario, r.controller, r.seed))
    kinds = {c["name"]: c["kind"] for c in suite["controllers"]}
    rows = aggregate_results(
        results,
        list(suite["scenarios"]),
        list(kinds),
        kinds=kinds,
        not_applicable={tuple(pair) for pair in suite["does_not_apply"]},
    )
    write_tables(rows, Path(out))
    plot_results(results, Path(out), suite["scenarios"])
    return rows


def aggregate_results(
    results: list[EpisodeResult],
    scenarios: list[str],
    controllers: list[str],
    kinds: Mapping[str, str] | None = None,
    not_applicable: set[tuple[str, str]] | None = None,
) -> list[dict[str, Any]]:
    """One row per (scenario, controller): means and ``*_std`` over seeds, or "does not
    apply".  ``kinds``: controller kinds (default: the registry's); ``not_applicable``: the
    (scenario, controller) pairs that do not apply (None: every pair without episodes);
    a pair without episodes that is not listed has no row (a partial or merged record)."""
    rows = []
    for scenario in scenarios:
        for controller in controllers:
            group = [r for r in results if r.scenario == scenario and r.controller == controller]
            listed = not_applicable is None or (scenario, controller) in not_applicable
            if not group and not listed:
                continue  # not run (yet): no row
            if not group:  # the controller does not apply to this scenario's ship: shown
                rows.append(
                    {
                        "scenario": scenario,
                        "split": scenario_split(scenario),
                        "controller": controller,
                        "kind": (kinds or {}).get(controller) or controller_kind(controller),
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
    ran = {(r["scenario"], r["controller"]) for r in rows if r.get("applies", True)}
    common = {}
    for split in ("catalogue", "heldout"):
        scenarios = dict.fromkeys(r["scenario"] for r in rows if r["split"] == split)
        common[split] = [s for s in scenarios if all((s, c) in ran for c in controllers)]
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


def plot_file(scenario: str) -> str:
    """The plot's file name for a scenario: inside the run's folder, whatever the scenario is
    (``heldout:0`` → ``heldout_0.png``, a YAML path → its stem)."""
    name = Path(scenario).stem if is_path(scenario) else scenario
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) + ".png"


def plot_results(
    results: list[EpisodeResult], out: Path, scenarios: Mapping[str, Any] | None = None
) -> None:
    """Per scenario: tracks over the path, e(t) and δ(t) of the first seed of each controller
    whose trajectory was kept.  ``scenarios``: name → settings (as ``run.json`` records
    them; default: each scenario loaded by name)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    for scenario in sorted({r.scenario for r in results if r.trajectory}):
        sc = load_scenario(scenarios[scenario] if scenarios else scenario)
        first: dict[str, EpisodeResult] = {}
        for r in sorted(results, key=lambda r: r.seed):
            if r.scenario == scenario and r.trajectory:
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
        fig.savefig(out / plot_file(scenario), dpi=90)
        plt.close(fig)
