"""The package keeps the public names the one-file ``shipgym_baselines.leaderboard`` had."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

import shipgym_baselines.leaderboard as leaderboard

#: every public name of the one-file module (its own and the project helpers it imported),
#: except ``verdict``, now the name of the submodule that defines that function
FORMER_NAMES = (
    "ACT_TIMEOUT_S",
    "AGGREGATE_FILE",
    "BACKENDS",
    "BASELINE",
    "BackendError",
    "COLUMNS",
    "ControllerSpec",
    "EVAL_SEED_OFFSET",
    "EpisodeResult",
    "FIGURE_DPI",
    "GAIN",
    "GENERALISATION_SPLITS",
    "HEADROOM_EXPLAINED",
    "Job",
    "ORACLE",
    "PARTIAL",
    "POOLED_FIGURES",
    "PROB",
    "RECORD_KEY",
    "RUN_FILE",
    "ReferenceCache",
    "RunError",
    "RunLog",
    "SCENARIO_SCORES_FILE",
    "SCORE_EXPLAINED",
    "SPLIT_TITLES",
    "Scenario",
    "TEST_SPLITS",
    "TRAINING_COLUMNS",
    "TWIN_HEADERS",
    "TrialRandomization",
    "YOURS",
    "aggregate",
    "aggregate_ranking",
    "aggregate_results",
    "announce",
    "announce_failure",
    "announce_references",
    "applies_to",
    "carried",
    "check_controllers",
    "check_failure_options",
    "check_out_dir",
    "check_out_usable",
    "check_seeds",
    "comparison_note",
    "controller_failed",
    "controller_kind",
    "controller_label",
    "controller_style",
    "csv_cell",
    "dumps",
    "dumps_rows",
    "episode_result",
    "episode_rows",
    "eta_line",
    "evaluation",
    "folder_verdict",
    "generalisation",
    "generalisation_table",
    "grants_truth",
    "headroom_grid",
    "headroom_markdown",
    "headroom_table",
    "is_partial",
    "is_path",
    "iter_results",
    "job_scenario",
    "keep_drawn",
    "learned_curves",
    "load_results",
    "load_scenario",
    "load_suite",
    "longest_first",
    "lookup",
    "markdown_table",
    "md_cell",
    "median_ace_episode",
    "missing",
    "no_ranking",
    "notice",
    "plain_name",
    "plain_text",
    "plan_jobs",
    "plot_file",
    "plot_results",
    "rankable",
    "ranking_markdown",
    "ranking_tables",
    "read_episodes",
    "read_run",
    "reference_work",
    "references_record",
    "resolution_lines",
    "result_from_entry",
    "row_intervals",
    "row_keys",
    "run_batch",
    "run_job",
    "run_leaderboard",
    "scenario_names",
    "scenario_ships",
    "scenario_split",
    "score_table",
    "scores_markdown",
    "subtitle",
    "suite_folder",
    "suite_record",
    "suite_scenario",
    "suite_scenarios",
    "tables_line",
    "terminal_summary",
    "training_seeds",
    "trial_scenario",
    "trials",
    "with_references",
    "work",
    "worker_count",
    "worker_init",
    "write_bytes",
    "write_results",
    "write_tables",
    "write_text",
)


@pytest.mark.parametrize("name", FORMER_NAMES)
def test_former_public_name_still_imports(name: str) -> None:
    """``from shipgym_baselines.leaderboard import NAME`` gives the object its module holds."""
    namespace: dict[str, object] = {}
    exec(f"from shipgym_baselines.leaderboard import {name}", namespace)
    home = importlib.import_module(f"shipgym_baselines.leaderboard.{leaderboard._HOMES[name]}")
    assert namespace[name] is getattr(home, name)


def test_unknown_name_is_an_attribute_error() -> None:
    with pytest.raises(AttributeError, match="no_such_name"):
        leaderboard.no_such_name  # noqa: B018


@pytest.mark.parametrize(
    "first",
    ["shipgym_baselines.evaluation", "shipgym_baselines.privileged", "shipgym_baselines.cli"],
)
def test_modules_that_read_the_ranking_import_first(first: str) -> None:
    """A module below the leaderboard that reads :mod:`.ranking` imports on its own in a
    fresh interpreter (the package imports its modules on first use, so no import loop)."""
    code = f"import {first}; from shipgym_baselines.leaderboard import run_leaderboard"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
