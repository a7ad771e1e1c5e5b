"""The leaderboard: every controller on every suite scenario × seeds, one table.

Each evaluation seed runs its own trial of a scenario: the suite's ``randomize`` ranges
(:mod:`shipgym.scenarios.trials`) draw the start, the jump time and the current from the
seed, and the sensor noise varies with it too.  A learned agent runs once per training seed
(:func:`shipgym_baselines.registry.training_seeds`), so its row aggregates training seeds ×
evaluation seeds.

The work is cut into jobs (:class:`Job`, names and seeds only: the worker builds each
seed's trial): a classical controller's job is one scenario for all the evaluation seeds,
a learned agent's one training seed on one scenario for all of them, the oracle's one
(scenario, seed) trial; a job's seeds run in lockstep
(:func:`shipgym_baselines.evaluation.evaluate_batch`: the rows of one evaluation trials env, one
network forward per step for a learned agent's, equal to the episodes one by one).
``local`` runs the jobs in a process pool; ``ray`` submits the same job function to a Ray
cluster (``pip install shipgym[ray]``).
The parent records each episode as it arrives (:mod:`shipgym_baselines.records.runs`: ``run.json``,
``episodes.jsonl``), and every table is aggregated from that record: the rows with
``*_ci95`` intervals, ``aggregate.json`` (the ranking of :mod:`shipgym_baselines.ranking`: cost over
the oracle's), ``scenario_scores.json``, the figures.
"""

from __future__ import annotations

import importlib
from typing import Any

#: the public names of :mod:`shipgym_baselines.leaderboard`, by the module that defines them
_DEFINED = {
    "jobs": (
        "Job",
        "announce_references",
        "check_controllers",
        "iter_results",
        "job_scenario",
        "longest_first",
        "missing",
        "plan_jobs",
        "plan_run",
        "reference_work",
        "run_batch",
        "run_job",
        "suite_record",
        "suite_scenario",
        "suite_scenarios",
        "trials",
        "work",
    ),
    "run": (
        "announce_failure",
        "check_failure_options",
        "keep_drawn",
        "row_keys",
        "run_leaderboard",
    ),
    "tables": (
        "AGGREGATE_FILE",
        "COLUMNS",
        "PROB",
        "SCENARIO_SCORES_FILE",
        "TRAINING_COLUMNS",
        "aggregate_results",
        "episode_rows",
        "generalisation",
        "rankable",
    ),
    "splits": (
        "GENERALISATION_SPLITS",
        "SPLIT_TITLES",
        "TEST_SPLITS",
        "YOURS",
        "scenario_split",
    ),
    "markdown": (
        "TWIN_HEADERS",
        "generalisation_table",
        "headroom_markdown",
        "markdown_table",
        "ranking_markdown",
        "ranking_tables",
        "scores_markdown",
    ),
    "outputs": (
        "POOLED_FIGURES",
        "learned_curves",
        "load_results",
        "plot_file",
        "plot_results",
        "subtitle",
        "terminal_summary",
        "write_results",
        "write_tables",
    ),
}
#: helpers the leaderboard module has always re-exported (their own homes are elsewhere)
_BORROWED = {
    "headroom": ("GAIN",),
    "jobs": (
        "ACT_TIMEOUT_S",
        "BACKENDS",
        "BackendError",
        "ControllerSpec",
        "EpisodeResult",
        "ReferenceCache",
        "RunError",
        "Scenario",
        "TrialRandomization",
        "announce",
        "applies_to",
        "controller_failed",
        "controller_kind",
        "controller_label",
        "evaluation",
        "grants_truth",
        "is_path",
        "load_scenario",
        "lookup",
        "result_from_entry",
        "scenario_names",
        "trial_scenario",
        "worker_init",
    ),
    "run": (
        "EVAL_SEED_OFFSET",
        "RECORD_KEY",
        "RunLog",
        "check_out_dir",
        "check_out_usable",
        "check_seeds",
        "eta_line",
        "load_suite",
        "median_ace_episode",
        "notice",
        "read_run",
        "references_record",
        "suite_folder",
        "training_seeds",
        "with_references",
        "worker_count",
    ),
    "tables": (
        "BASELINE",
        "aggregate",
        "row_intervals",
    ),
    "markdown": (
        "HEADROOM_EXPLAINED",
        "ORACLE",
        "PARTIAL",
        "SCORE_EXPLAINED",
        "headroom_grid",
        "is_partial",
        "md_cell",
        "no_ranking",
        "resolution_lines",
    ),
    "outputs": (
        "FIGURE_DPI",
        "RUN_FILE",
        "aggregate_ranking",
        "carried",
        "comparison_note",
        "controller_style",
        "csv_cell",
        "dumps",
        "dumps_rows",
        "episode_result",
        "folder_verdict",
        "headroom_table",
        "plain_name",
        "plain_text",
        "read_episodes",
        "scenario_ships",
        "score_table",
        "tables_line",
        "write_bytes",
        "write_text",
    ),
}
_HOMES = {
    name: module
    for homes in (_DEFINED, _BORROWED)
    for module, names in homes.items()
    for name in names
}
__all__ = sorted(_HOMES)


def __getattr__(name: str) -> Any:
    """A public name from its module, imported on first use, so that importing one module
    of this package (:mod:`.ranking`, say) imports no other."""
    if name not in _HOMES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{_HOMES[name]}"), name)


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
