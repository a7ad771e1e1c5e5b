"""What a run folder gets: the tables, the ranking and the figures written from its
episodes, the terminal summary, and the plot of ``shipgym run``."""

from __future__ import annotations

import contextlib
import csv
import io
import json
import os
from collections.abc import Iterator, Mapping
from concurrent.futures import Executor
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.config import is_path
from shipgym.notices import notice
from shipgym.scenarios.loader import load_scenario
from shipgym.scenarios.trials import TrialRandomization, trial_scenario
from shipgym_baselines.escaping import csv_cell, plain_text
from shipgym_baselines.executor import Inline, task_pool
from shipgym_baselines.jsonout import dumps, dumps_rows
from shipgym_baselines.leaderboard.costs import tables_line
from shipgym_baselines.page.markdown import (
    generalisation_table,
    markdown_table,
    ranking_markdown,
    ranking_tables,
)
from shipgym_baselines.page.verdict import folder_verdict, main_table, plain_name, verdict
from shipgym_baselines.plots import curves as curve_figures
from shipgym_baselines.plots import ranking as ranking_figures
from shipgym_baselines.plots import scenarios as scenario_figures
from shipgym_baselines.plots.style import FIGURE_DPI, controller_style
from shipgym_baselines.records.episodes import EpisodeResult, read_episodes
from shipgym_baselines.records.outfiles import carried, write_bytes, write_text
from shipgym_baselines.records.runrecord import RUN_FILE, read_run
from shipgym_baselines.records.trajectories import episode_result
from shipgym_baselines.records.trials import shares_trials, twins_of
from shipgym_baselines.scoring.change_share import (
    NO_SCENARIO_CELLS,
    episode_costs,
    scenario_twin_cells,
    share_controllers,
    share_grid,
)
from shipgym_baselines.scoring.comparison import (
    comparison_note,
)
from shipgym_baselines.scoring.headroom import headroom_table, scenario_ships
from shipgym_baselines.scoring.ranking import (
    PARTIAL,
    aggregate_ranking,
    no_ranking,
    resolution_lines,
)
from shipgym_baselines.scoring.ranking import scenario_scores as score_table
from shipgym_baselines.scoring.scores import REFERENCE_KIND, refused_trials, scored_episodes
from shipgym_baselines.scoring.splits import suite_families, suite_splits
from shipgym_baselines.scoring.tables import (
    AGGREGATE_FILE,
    SCENARIO_SCORES_FILE,
    aggregate_results,
    episode_rows,
    generalisation,
    rankable,
)
from shipgym_baselines.signals import worker_init


def load_results(folder: str | os.PathLike) -> list[EpisodeResult]:
    """The episodes recorded in a run folder's ``episodes.jsonl`` (trajectories if kept)."""
    return [episode_result(r, folder) for r in read_episodes(folder)]


def _order(result: EpisodeResult) -> tuple:
    ts = result.training_seed
    return (result.scenario, result.controller, ts is not None, ts or 0, result.seed)


def write_results(
    out: str | os.PathLike,
    suite: Mapping[str, Any],
    results: list[EpisodeResult],
    workers: int | None = None,
    vector_figures: bool = False,
    announce: bool = True,
) -> list[dict[str, Any]]:
    """Tables, ranking and figures into ``out`` from episode results and a suite as
    ``run.json`` keeps it (:func:`~shipgym_baselines.leaderboard.jobs.suite_record`); returns the
    rows.  ``announce``: say so
    first in one line on stderr, with the time it takes (:func:`tables_line`).

    ``leaderboard.{json,csv}`` (the rows), ``leaderboard.md`` (the ranking, the
    controller × scenario cost ratios, then the rows), ``generalisation.json``,
    ``aggregate.json`` (:func:`shipgym_baselines.scoring.ranking.aggregate_ranking`),
    ``scenario_scores.json`` and the figures
    (:mod:`shipgym_baselines.plots`: per scenario the small multiples of each
    controller's median-ACE episode, per split the ranking's interval estimates and performance
    profiles) and ``leaderboard.html`` (:mod:`shipgym_baselines.page.html`: all of it on one
    page).  The ranking of each split and each figure are independent tasks, run in a
    pool of ``workers`` processes (default: the cores) when there are
    :data:`POOLED_FIGURES` scenario figures or more.  ``vector_figures``: each figure's
    vector copy too (the page shows the PNGs).
    """
    from shipgym_baselines.page import html as page

    # completion order varies between runs: aggregate in a fixed order (bit-stable means)
    results = sorted(results, key=_order)
    out = Path(out)
    kinds = {c["name"]: c["kind"] for c in suite["controllers"]}
    episodes = episode_rows(results)
    splits = suite_splits(suite)
    twins = twins_of(suite)
    # the twins' episodes are scored against the changing trials, never shown or ranked
    ranked = rankable(episodes, suite.get("scenario_seeds"), shares_trials(suite))
    shown_episodes = [e for e in ranked if e["scenario"] in splits]
    if announce:
        notice(tables_line(len(splits), workers or os.cpu_count() or 1))
    for line in refused_trials(episodes):  # a reference's failure: never a denominator
        notice(line)
    drawn = scenario_figures.episodes_to_draw([r for r in results if r.scenario in splits])
    shown = sorted({scenario for scenario, _ in drawn})
    with _pool(workers or os.cpu_count() or 1, len(shown)) as pool:
        boards = [
            pool.submit(
                aggregate_ranking,
                ranked,
                {s: sp for s, sp in splits.items() if sp == split},
                kinds,
                twins=twins,
            )
            for split in sorted(set(splits.values()))
        ]
        plots = {
            scenario: pool.submit(
                carried(scenario_figures.plot_scenarios),
                out,
                {key: ep for key, ep in drawn.items() if key[0] == scenario},
                suite["scenarios"],
                kinds,
                vector=vector_figures,
            )
            for scenario in shown
        }
        board = sorted(
            (row for future in boards for row in future.result()),
            key=lambda r: (r["split"], r["cost_ratio_iqm"], r["controller"]),
        )
        ranking_plots = [
            pool.submit(
                carried(ranking_figures.plot_ranking),
                out,
                [r for r in board if r["split"].removesuffix(PARTIAL) == split],
                shown_episodes,
                splits,
                kinds,
                vector_figures,
            )
            for split in dict.fromkeys(r["split"].removesuffix(PARTIAL) for r in board)
        ]
        rows = aggregate_results(
            results,
            list(suite["scenarios"]),
            list(kinds),
            kinds=kinds,
            not_applicable={tuple(pair) for pair in suite["does_not_apply"]},
            splits=splits,
        )
        scored = scored_episodes(ranked)  # C / C_oracle of each: the twins' numbers read it
        add_twin_cells(rows, scored, twins)
        curves = learned_curves(kinds)
        add_seed_flags([*board, *rows], curves)
        scores = score_table(shown_episodes, splits, kinds)
        write_text(out / AGGREGATE_FILE, dumps(board, indent=2) + "\n")
        write_text(out / SCENARIO_SCORES_FILE, dumps_rows(scores))  # one scenario a line
        left_out = sorted({e["scenario"] for e in episodes} - {e["scenario"] for e in ranked})
        note = comparison_note(suite, out)
        ships = scenario_ships(suite["scenarios"])
        families = suite_families(suite)
        headroom = headroom_table(ranked, ships, families, splits)
        shares = share_table(board, scored, ships, families, splits, twins)
        head = ranking_markdown(
            board,
            scores,
            list(suite["scenarios"]),
            left_out,
            shown_episodes,
            note,
            headroom,
            shares,
        )
        write_tables(rows, out, head=head)
        files = [f for future in ranking_plots for f in future.result()]
        files += [f for s in suite["scenarios"] if s in plots for f in plots[s].result()]
        files += curve_figures.plot_learning_curves(out, curves, vector_figures)
    lead = verdict(board, shown_episodes, plain_name, headroom)
    content = page.PageContent(
        rows,
        board,
        scores,
        files,
        subtitle=subtitle(suite, results),
        verdict=lead,
        note=note if board else "",
        headroom=headroom,
        shares=shares,
    )
    page.write_html(out, content)
    return rows


def add_twin_cells(
    rows: list[dict[str, Any]], scored: list[dict[str, Any]], twins: Mapping[str, str]
) -> None:
    """Each row of a changing scenario gets its controller's nominal ratio and change share
    there, with intervals that resample the scenario's trials
    (:func:`~shipgym_baselines.scoring.change_share.scenario_twin_cells`); the other rows
    None.  The references' rows have none.  ``scored``: the ranked episodes with their cost
    ratios (:func:`~shipgym_baselines.scoring.scores.scored_episodes`)."""
    costs = episode_costs(scored)
    for row in rows:
        cells = dict(NO_SCENARIO_CELLS)
        if row["scenario"] in twins and row["applies"] and row["kind"] != REFERENCE_KIND:
            cells = scenario_twin_cells(scored, row["controller"], row["scenario"], twins, costs)
        row.update(cells)


def share_table(
    board: list[dict[str, Any]],
    scored: list[dict[str, Any]],
    ships: Mapping[str, str],
    families: Mapping[str, str],
    splits: Mapping[str, str],
    twins: Mapping[str, str],
) -> dict[str, Any]:
    """The change share per ship × change family of the verdict's table's top competitors
    and best learned agent (:func:`~shipgym_baselines.scoring.change_share.share_grid`):
    ``split``, ``controllers`` and ``rows``; empty without twins or a ranking.  ``scored``:
    as :func:`add_twin_cells` reads them; ``ships`` / ``families``: scenario → its ship /
    change family."""
    table = main_table(board)
    if not twins or not table:
        return {}
    split = table[0]["split"]
    controllers = share_controllers(table)
    scenarios = [s for s in splits if splits[s] == split and s in table[0]["scenarios"]]
    grid = share_grid(scored, controllers, ships, families, scenarios, twins)
    return {"split": split, "controllers": controllers, "rows": grid}


def add_seed_flags(rows: list[dict[str, Any]], curves: Mapping[str, list[dict[str, Any]]]) -> None:
    """Each row of a learned agent with shipped learning curves gets ``seed_flags``: its
    flagged training seeds (:func:`~shipgym_baselines.learned.curves.seed_flags`, the rule
    :data:`~shipgym_baselines.learned.curves.SEED_FLAG_RULE`; [] when none is)."""
    from shipgym_baselines.learned.curves import seed_flags

    flags = {name: seed_flags(found) for name, found in curves.items() if found}
    for row in rows:
        if row["controller"] in flags:
            row["seed_flags"] = flags[row["controller"]]


def learned_curves(kinds: Mapping[str, str]) -> dict[str, list[dict[str, Any]]]:
    """The shipped learning curves of the suite's learned controllers (by name)."""
    from shipgym_baselines.learned.curves import agent_curves

    return {name: agent_curves(name) for name, kind in kinds.items() if kind == "learned"}


def subtitle(suite: Mapping[str, Any], results: list[EpisodeResult]) -> str:
    """The page's line under its title: suite, seeds, trials, training seeds."""
    trained = {r.training_seed for r in results if r.training_seed is not None}
    parts = [
        f"suite {suite.get('name') or '(merged)'}",
        f"{len(suite['scenarios'])} scenarios",
        f"{len(suite['controllers'])} controllers",
        f"{len(suite['seeds'])} evaluation seeds"
        + (" (randomised trials)" if suite.get("randomize") else ""),
    ]
    if trained and shares_trials(suite):
        parts.append(f"learned agents' {len(trained)} training seeds share the trials")
    elif trained:
        parts.append(f"learned agents × {len(trained)} training seeds")
    return " · ".join(parts)


#: scenario figures from which :func:`write_results` draws in a process pool
POOLED_FIGURES = 4


@contextlib.contextmanager
def _pool(workers: int, figures: int) -> Iterator[Executor | Inline]:
    """A process pool of ``workers`` for ``figures`` scenario figures and the ranking, or
    :class:`~shipgym_baselines.executor.Inline` for a few or one worker."""
    with task_pool(workers if figures >= POOLED_FIGURES else 1, worker_init) as pool:
        yield pool


def terminal_summary(folder: str | os.PathLike) -> str:
    """What ``leaderboard``, ``evaluate`` and ``report`` print: the ranking of the run
    folder's ``aggregate.json`` (or why there is none), its resolution, and the path of
    ``leaderboard.html``."""
    from shipgym_baselines.page.html import PAGE_FILE

    lead = folder_verdict(folder)
    board = json.loads((Path(folder) / AGGREGATE_FILE).read_text())
    lines = [
        *([lead, ""] if lead else []),
        "## Ranking (cost over the oracle's; lower is better)",
        "",
    ]
    lines += ranking_tables(board) + resolution_lines(board) if board else [_why_none(folder), ""]
    lines += _note_lines(folder) if board else []
    return "\n".join([*lines, f"leaderboard: {Path(folder) / PAGE_FILE}"])


def _why_none(folder: str | os.PathLike) -> str:
    """Why the run folder has no ranking
    (:func:`~shipgym_baselines.scoring.ranking.no_ranking`)."""
    file = Path(folder) / SCENARIO_SCORES_FILE
    return no_ranking(json.loads(file.read_text()) if file.is_file() else [])


def _note_lines(folder: str | os.PathLike) -> list[str]:
    """What a run folder's ranking is against (its ``run.json``), as lines; none for a
    report's folder or a run that added no reference."""
    if not (Path(folder) / RUN_FILE).is_file():
        return []
    note = comparison_note(read_run(folder).get("suite", {}), folder)
    return [note, ""] if note else []


def _csv_value(key: str, value: Any) -> Any:
    """A row's value as its CSV cell holds it: a learned row's flagged seeds in words."""
    if key == "seed_flags" and isinstance(value, list):
        from shipgym_baselines.learned.curves import flag_text

        return "; ".join(flag_text(f) for f in value)
    return value


def write_tables(rows: list[dict[str, Any]], out: Path, head: str = "") -> None:
    """``leaderboard.{json,csv,md}`` and ``generalisation.json``; ``head``: the markdown
    before the rows (the ranking)."""
    write_text(out / "leaderboard.json", dumps_rows(rows))  # one row a line
    keys = list(dict.fromkeys(k for r in rows for k in r))  # learned rows add training cost
    table = io.StringIO(newline="")
    writer = csv.DictWriter(table, fieldnames=keys, restval="")
    writer.writeheader()
    writer.writerows([{k: csv_cell(_csv_value(k, v)) for k, v in r.items()} for r in rows])
    write_text(out / "leaderboard.csv", table.getvalue())
    rows_part = "## All rows\n\n" + markdown_table(rows) if head else markdown_table(rows)
    write_text(
        out / "leaderboard.md",
        (head + "\n" if head else "") + rows_part + generalisation_table(rows),
    )
    write_text(out / "generalisation.json", dumps(generalisation(rows), indent=2))


def plot_file(scenario: str) -> str:
    """The plot's file name for a scenario: inside the run's folder, whatever the scenario is
    (``heldout:0`` → ``heldout_0.png``, a YAML path → its stem)."""
    name = Path(scenario).stem if is_path(scenario) else scenario
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) + ".png"


def plot_results(
    results: list[EpisodeResult],
    out: Path,
    scenarios: Mapping[str, Any] | None = None,
    randomize: Mapping[str, Any] | None = None,
) -> list[Path]:
    """Per scenario: tracks over the path, e(t) and δ(t) of the first evaluation seed (of
    the first training seed) of each controller whose trajectory was kept; returns the
    files written (:func:`plot_file`).  ``scenarios``: name → settings (as ``run.json``
    records them; default: each scenario loaded by name); ``randomize``: the trial
    randomisation (the jump time drawn is that seed's)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    randomization = None if randomize is None else TrialRandomization(**randomize)
    written = []
    for scenario in sorted({r.scenario for r in results if r.trajectory}):
        first: dict[str, EpisodeResult] = {}
        for r in sorted(results, key=_order):
            if r.scenario == scenario and r.trajectory:
                first.setdefault(r.controller, r)
        seed = min(r.seed for r in first.values())
        sc = load_scenario(scenarios[scenario] if scenarios else scenario)
        sc = trial_scenario(sc, randomization, seed)
        fig, axes = plt.subplots(1, 3, figsize=(15, 4))
        pts = sc.path.point(np.linspace(0, sc.path.length, 300))
        axes[0].plot(pts[:, 0], pts[:, 1], "k--", lw=1, label="path")
        for name, r in first.items():
            tr, look, label = r.trajectory, controller_style(name).kwargs(), plain_text(name)
            axes[0].plot(tr["x"], tr["y"], lw=1, label=label, **look)
            axes[1].plot(tr["t"], tr["cross_track_error"], lw=1, label=label, **look)
            axes[2].plot(tr["t"], np.degrees(tr["rudder_angle"]), lw=1, label=label, **look)
        if sc.change_time is not None:
            for ax in axes[1:]:
                ax.axvline(sc.change_time, color="gray", ls=":", lw=1)
        title = f"{plain_text(scenario)}: tracks (seed {seed})"
        axes[0].set(xlabel="x [m]", ylabel="y [m]", title=title)
        axes[0].set_aspect("equal", adjustable="datalim")
        axes[1].set(xlabel="t [s]", ylabel="e [m]", title="cross-track error")
        axes[2].set(xlabel="t [s]", ylabel="δ [deg]", title="rudder angle")
        axes[0].legend(fontsize=7)
        fig.tight_layout()
        image = io.BytesIO()
        fig.savefig(image, format="png", dpi=FIGURE_DPI)
        plt.close(fig)
        written.append(out / plot_file(scenario))
        write_bytes(written[-1], image.getvalue())
    return written
