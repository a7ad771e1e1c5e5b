"""The run summary: the ranked rows of aggregate.json in ranking order, the run's size and
times from run.json, the README's table from it; the CLI never overwrites silently."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from shipgym_baselines.cli import main
from shipgym_baselines.leaderboard.run import run_leaderboard
from shipgym_baselines.leaderboard.summary import readme_table, run_summary
from shipgym_baselines.page.verdict import folder_verdict
from shipgym_baselines.records.episodes import read_episodes
from tests.baselines.records.conftest import write_suite

RANDOMIZE = {"cross_track_offset_L": [-1.0, 1.0], "jump_time_jitter_s": [-5.0, 5.0]}


@pytest.fixture(scope="module")
def ranked_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two nomoto2 scenarios, two competitors (pid_los, lqr), both references and
    zero_rudder, 2 randomised trials."""
    root = tmp_path_factory.mktemp("summary")
    suite = write_suite(
        root,
        controllers=["pid_los", "lqr", "zero_rudder", "oracle", "oracle_frozen"],
        randomize=RANDOMIZE,
    )
    run_leaderboard(suite, out_dir=root / "out", workers=1, show_progress=False)
    return root / "out"


def test_the_summary_holds_the_ranking_and_the_runs_record(ranked_run: Path) -> None:
    summary = run_summary(ranked_run)
    board = json.loads((ranked_run / "aggregate.json").read_text())
    record = json.loads((ranked_run / "run.json").read_text())
    catalogue = summary["splits"]["catalogue"]
    expected = sorted(
        (r for r in board if r["split"] == "catalogue"), key=lambda r: r["cost_ratio_iqm"]
    )
    assert [r["controller"] for r in catalogue["rows"]] == [r["controller"] for r in expected]
    assert [r["rank"] for r in catalogue["rows"]] == list(range(1, len(expected) + 1))
    for row, source in zip(catalogue["rows"], expected, strict=True):
        for field in ("cost_ratio_iqm", "nominal_cost_ratio_gmean", "change_share_iqm"):
            assert row[field] == source[field]
            assert row[f"{field}_ci95"] == source[f"{field}_ci95"]
    assert catalogue["competitors"] == len(expected) == 2
    assert not {"oracle", "oracle_frozen"} & {r["controller"] for r in catalogue["rows"]}
    assert summary["episodes"] == len(read_episodes(ranked_run))
    assert (summary["wall_s"], summary["cpu_s"]) == (record["wall_s"], record["cpu_s"])
    commit = record["git_commit"]
    assert summary["commit"] == (commit[:7] if commit else None)
    worth = catalogue["headroom"]
    assert worth is not None and worth["gmean"] >= 1.0 and worth["trials"] > 0
    assert summary["verdict"] == folder_verdict(ranked_run)


def test_the_readme_table_prints_each_row_as_ranked(ranked_run: Path) -> None:
    summary = run_summary(ranked_run)
    lines = readme_table(summary).splitlines()
    rows = summary["splits"]["catalogue"]["rows"]
    assert len(lines) == 2 + len(rows)
    for line, row in zip(lines[2:], rows, strict=True):
        cells = [c.strip() for c in line.strip("|").split("|")]
        assert cells[:3] == [str(row["rank"]), row["controller"], row["kind"]]
        assert cells[3].startswith(f"{row['cost_ratio_iqm']:.3f} [")


def test_the_command_writes_once_and_replaces_only_by_force(
    ranked_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "run_summary.json"
    assert main(["summary", str(ranked_run), "--out", str(out)]) == 0
    written = json.loads(out.read_text())
    assert written["splits"]["catalogue"]["rows"][0]["rank"] == 1
    assert readme_table(written) in capsys.readouterr().out
    out.write_text("{}")
    assert main(["summary", str(ranked_run), "--out", str(out)]) == 2
    assert "exists; --force replaces it" in capsys.readouterr().err
    assert out.read_text() == "{}"
    assert main(["summary", str(ranked_run), "--out", str(out), "--force"]) == 0
    assert json.loads(out.read_text()) == written
    assert main(["summary", str(tmp_path)]) == 2
    assert "no run.json" in capsys.readouterr().err
    assert main(["summary", str(ranked_run), "--out", str(tmp_path / "no" / "x.json")]) == 2
    assert "cannot write it" in capsys.readouterr().err
