"""The common shape of every paper reproduction and the shared markdown formatter."""

from __future__ import annotations

import inspect
import json
import math

import pytest

from shipgym_baselines.cli import build_parser
from shipgym_baselines.reproduce import PAPERS, borkowski2018
from shipgym_baselines.reproduce.borkowski2018 import experiment
from shipgym_baselines.reproduce.borkowski2018.claims import case_claims
from shipgym_baselines.reproduce.protocol import Outcome, Reproduction
from shipgym_baselines.reproduce.report import cell, index, seeds_of, table
from shipgym_baselines.reproduce.rows import reproduction_row


@pytest.mark.parametrize("name", sorted(PAPERS))
def test_every_paper_is_a_reproduction_the_cli_can_run(name: str) -> None:
    paper = PAPERS[name]
    # what shipgym_baselines.cli calls: run(out_dir=, seeds=, progress=) and markdown(rows)
    assert isinstance(paper, Reproduction) and paper.name == name
    params = inspect.signature(paper.run_experiment).parameters
    assert list(params)[:2] == ["seeds", "progress"]
    assert params["seeds"].default == 1 and params["progress"].default is None
    assert all(callable(f) for f in (paper.report, paper.plots))
    assert build_parser().parse_args(["reproduce", name]).paper == name


def test_run_writes_rows_report_documents_and_figures(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """Reproduction.run: the experiment's rows as strict JSON (∞ -> null), the report of
    those rows, each extra document, the figures only when asked; returns the rows."""
    calls: dict[str, object] = {}

    def experiment(seeds: int = 1, progress=None, scale: float = 1.0) -> Outcome:  # type: ignore[no-untyped-def]
        calls["experiment"] = (seeds, scale)
        rows = [reproduction_row("c", "ctrl", "t_c", math.inf, 1.0, seeds)]
        return Outcome(rows, episodes="figure data", documents={"extra.json": {"k": 2}})

    def plots(outcome: Outcome, out_dir) -> None:  # type: ignore[no-untyped-def]
        calls["plots"] = (outcome.episodes, out_dir)

    paper = Reproduction("paper", experiment, lambda rows: f"{len(rows)} row(s)\n", plots)
    rows = paper.run(tmp_path / "a", seeds=3, plot=False, scale=0.5)
    assert calls == {"experiment": (3, 0.5)}
    assert json.loads((tmp_path / "a" / "paper.json").read_text()) == [
        {"case": "c", "controller": "ctrl", "metric": "t_c", "ours": None, "paper": 1.0, "seeds": 3}
    ]
    assert rows[0]["ours"] == math.inf
    assert (tmp_path / "a" / "paper.md").read_text() == "1 row(s)\n"
    assert json.loads((tmp_path / "a" / "extra.json").read_text()) == {"k": 2}
    paper.run(tmp_path / "b")
    assert calls["plots"] == ("figure data", tmp_path / "b")


def test_cells() -> None:
    assert cell(None) == "–"  # no number (the paper gives none)
    assert (cell(True), cell(False)) == ("yes", "no")
    assert cell(0.000979512) == "0.0009795"  # default 4 significant digits
    assert cell(26512.07, ".6g") == "26512.1"
    assert cell(35.5, ".3f") == "35.500"
    assert cell(math.inf, ".3f", inf="never") == "never"
    assert (cell(math.inf), cell(-math.inf), cell(math.nan)) == ("inf", "-inf", "nan")


def test_table_of_known_rows() -> None:
    """Header, separator, one line per row; the '|' of |e| is escaped inside a cell."""
    rows = [
        reproduction_row("straight", "pid_vf", "mean_abs_e", 0.5, 0.53, 1),
        reproduction_row("straight", "pid_vf", "settled", False, True, 1),
    ]
    body = [[r["case"], "|e|", cell(r["ours"]), cell(r["paper"])] for r in rows]
    assert table(["case", "reading", "ours", "paper"], body) == [
        "| case | reading | ours | paper |",
        "|---|---|---|---|",
        "| straight | \\|e\\| | 0.5 | 0.53 |",
        "| straight | \\|e\\| | no | yes |",
    ]
    assert index(rows)[("straight", "pid_vf", "settled")] is rows[1]
    assert seeds_of(rows) == 1 and seeds_of([]) == 0


def test_a_paper_report_of_known_rows() -> None:
    """Borkowski's table line of the paper's initial guess from its rows (the numbers of
    the 1-seed run)."""
    case = experiment.case_name(*experiment.PAPER_GUESS)
    figures = {
        ("lqr", "J"): 26512.07,
        ("adaptive_lqr", "J"): 21934.31,
        ("adaptive_lqr", "a_hat"): 0.0275512,
        ("adaptive_lqr", "c_hat"): 0.000979512,
    }
    rows = [reproduction_row(case, c, m, v, None, 1) for (c, m), v in figures.items()]
    rows += case_claims(case, 21934.31 / 26512.07, 1)
    md = borkowski2018.REPRODUCTION.markdown(rows)
    line = "| a0=0.02, c0=0.002 (paper) | 26512.1 | 21934.3 | 0.8273 | yes | 0.02755 | 0.0009795 |"
    assert line in md.splitlines()


def test_borkowski_keeps_the_papers_1000_s_runs() -> None:
    """mariner_track's time limit lets a controller finish the route; the reproduction still
    cuts the episode at the paper's 1000 s (its J is over those)."""
    from shipgym.scenarios.loader import load_scenario

    assert experiment.build_scenario().config.time_limit == 1000.0
    assert load_scenario("mariner_track").config.time_limit > 1000.0
    assert experiment.build_scenario(150.0).config.time_limit == 150.0
