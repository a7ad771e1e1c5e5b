"""``shipgym report`` and ``evaluate``'s folders: separate runs merge into one
table, equal to the leaderboard of the same controllers."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from shipgym_baselines.cli import main
from shipgym_baselines.errors import RunError
from shipgym_baselines.leaderboard.report import merge_runs, write_report
from shipgym_baselines.records.runrecord import read_run
from tests.baselines.records.conftest import untimed, write_suite


@pytest.fixture(scope="module")
def evaluated(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """``evaluate pid_los`` and ``evaluate zero_rudder`` in their own folders, and the
    leaderboard of both, on the tiny suite (the references not added: test_comparison)."""
    root = tmp_path_factory.mktemp("runs")
    suite = write_suite(root)
    folders = {name: root / name for name in ("pid_los", "zero_rudder", "both")}
    quiet = ["--workers", "1", "--no-progress", "--json", "--no-references"]
    for policy in ("pid_los", "zero_rudder"):
        args = ["evaluate", policy, "--suite", suite, "--out", str(folders[policy])]
        assert main([*args, *quiet]) == 0
    args = ["leaderboard", "--suite", suite, "--out", str(folders["both"])]
    assert main([*args, *quiet]) == 0
    return folders


def test_report_merges_two_evaluate_runs_into_the_leaderboard_table(
    evaluated: dict[str, Path], tmp_path: Path, capsys
) -> None:
    capsys.readouterr()
    out = tmp_path / "report"
    runs = [str(evaluated["pid_los"]), str(evaluated["zero_rudder"])]
    assert main(["report", *runs, "--out", str(out), "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    board = json.loads((evaluated["both"] / "leaderboard.json").read_text())
    assert untimed(rows) == untimed(board)
    assert untimed(json.loads((out / "leaderboard.json").read_text())) == untimed(board)
    for name in ("leaderboard.md", "leaderboard.csv", "generalisation.json", "aggregate.json"):
        assert (out / name).is_file(), name
    assert (out / "scenario_nominal.png").is_file()
    # the ranking of the merged runs is the leaderboard's
    aggregate = (out / "aggregate.json").read_text()
    assert aggregate == (evaluated["both"] / "aggregate.json").read_text()
    assert json.loads(aggregate) == []  # no ranking without the oracle's episodes
    report = json.loads((out / "report.json").read_text())
    assert [r["folder"] for r in report["runs"]] == runs
    assert [r["episodes"] for r in report["runs"]] == [4, 4]


def test_report_of_one_run_rebuilds_its_tables(evaluated: dict[str, Path], tmp_path) -> None:
    rows, _ = write_report([evaluated["both"]], tmp_path / "again")
    board = json.loads((evaluated["both"] / "leaderboard.json").read_text())
    assert untimed(rows) == untimed(board)
    for name in ("leaderboard.md", "leaderboard.csv", "generalisation.json"):  # same episodes
        assert (tmp_path / "again" / name).read_text() == (evaluated["both"] / name).read_text()


def test_report_refuses_runs_that_disagree(evaluated: dict[str, Path], tmp_path: Path) -> None:
    other = tmp_path / "other"
    other.mkdir()
    record = read_run(evaluated["pid_los"])
    record["suite"]["scenarios"]["nominal"]["ship"]["params"]["K"] *= 2
    (other / "run.json").write_text(json.dumps(record))
    (other / "episodes.jsonl").write_text("")
    with pytest.raises(RunError, match=r"scenario 'nominal' has other settings.*ship\.params\.K"):
        write_report([evaluated["zero_rudder"], other], tmp_path / "out")
    record["suite"]["scenarios"]["nominal"]["ship"]["params"]["K"] /= 2
    record["suite"]["randomize"] = {"heading_error_deg": [-5.0, 5.0]}  # other trials
    (other / "run.json").write_text(json.dumps(record))
    with pytest.raises(RunError, match=r"draws its trials with randomize .*heading_error_deg"):
        write_report([evaluated["zero_rudder"], other], tmp_path / "out")
    with pytest.raises(RunError, match=r"is in .* and in"):  # the same episodes twice
        write_report([evaluated["pid_los"], evaluated["both"]], tmp_path / "out")
    with pytest.raises(RunError, match="one of the runs read"):
        write_report([evaluated["both"]], evaluated["both"], force=True)
    with pytest.raises(RunError, match="not empty"):
        write_report([evaluated["both"]], evaluated["pid_los"])
    with pytest.raises(RunError, match="not a run folder"):
        write_report([tmp_path], tmp_path / "out2")
    assert not (tmp_path / "out").exists()


def test_report_keeps_the_twins_and_refuses_runs_that_disagree_on_them(
    evaluated: dict[str, Path], tmp_path: Path
) -> None:
    """The merged suite keeps the runs' no-change twins (rudder_aging's is the tiny suite's
    nominal), their players united, and refuses a run that pairs a scenario with another
    twin or gives a twin other settings."""
    suite, _, _ = merge_runs([evaluated["pid_los"], evaluated["zero_rudder"]])
    assert suite["twins"] == {"rudder_aging": "nominal"}
    assert suite["twin_players"] == ["pid_los"]  # zero_rudder, a reference, plays no twin
    record = read_run(evaluated["pid_los"])
    nominal = record["suite"]["scenarios"]["nominal"]
    record["suite"]["twins"] = {"rudder_aging": "twin:rudder_aging"}
    record["suite"]["twin_scenarios"] = {"twin:rudder_aging": nominal}
    folders = []
    for name in ("one", "two"):
        folder = tmp_path / name
        folder.mkdir()
        (folder / "run.json").write_text(json.dumps(record))
        (folder / "episodes.jsonl").write_text("")
        folders.append(folder)
        record["suite"]["twin_scenarios"]["twin:rudder_aging"] = {**nominal, "time_limit": 20.0}
    with pytest.raises(RunError, match=r"'rudder_aging' has the twin 'twin:rudder_aging' in"):
        merge_runs([evaluated["zero_rudder"], folders[0]])
    with pytest.raises(RunError, match=r"twin 'twin:rudder_aging' has other settings.*time_limit"):
        merge_runs(folders)
    suite, _, _ = merge_runs(folders[:1])
    assert suite["twin_scenarios"] == {"twin:rudder_aging": nominal}


def test_evaluate_writes_a_folder_per_policy(tmp_path: Path, monkeypatch, capsys) -> None:
    monkeypatch.chdir(tmp_path)
    suite = write_suite(tmp_path, scenarios=["nominal"], seeds=1)
    for policy in ("pid_los", "zero_rudder"):
        assert main(["evaluate", policy, "--suite", suite, "--no-progress", "--json"]) == 0
        folder = tmp_path / "results" / "evaluate" / "tiny" / policy  # the suite file's stem
        assert read_run(folder)["status"] == "complete"
    capsys.readouterr()
    assert main(["evaluate", "pid_los", "--suite", suite, "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "results/evaluate/tiny/pid_los is not empty" in err and "evaluate's folder" in err


def test_report_writes_results_report_by_default_and_never_over_it(
    evaluated: dict[str, Path], tmp_path: Path, monkeypatch, capsys
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["report", str(evaluated["both"]), "--json"]) == 0
    assert (tmp_path / "results" / "report" / "leaderboard.json").is_file()
    capsys.readouterr()
    assert main(["report", str(evaluated["both"])]) == 2
    assert "results/report is not empty" in capsys.readouterr().err
    assert main(["report", str(evaluated["both"]), "--force", "--json"]) == 0


def test_a_renamed_run_merges_with_the_one_of_its_own_name(
    evaluated: dict[str, Path], tmp_path: Path, capsys
) -> None:
    """``--name`` shows a controller under another name, so ``report`` merges it
    with a run of the controller under its own (a trained agent beside the shipped one)."""
    suite = str(evaluated["pid_los"].parent / "tiny.yaml")
    again = tmp_path / "again"
    args = ["leaderboard", "--suite", suite, "--out", str(again), "--workers", "1"]
    args += ["--controllers", "pid_los", "--name", "pid_los=pid_again", "--no-progress"]
    assert main([*args, "--json", "--no-references"]) == 0
    assert {r["controller"] for r in json.loads(capsys.readouterr().out)} == {"pid_again"}
    assert read_run(again)["suite"]["controllers"][0]["controller"] == {
        "controller": "pid_los",
        "name": "pid_again",
        "settings": {},
    }
    out = tmp_path / "report"
    assert main(["report", str(evaluated["pid_los"]), str(again), "--out", str(out)]) == 0
    rows = json.loads((out / "leaderboard.json").read_text())
    by_name = {r["controller"]: untimed([r])[0] for r in rows}
    assert set(by_name) == {"pid_los", "pid_again"}
    mine, shipped = by_name.pop("pid_again"), by_name.pop("pid_los")
    mine.pop("controller"), shipped.pop("controller")
    assert mine == shipped  # the same controller's episodes under two names


def test_evaluate_name_and_its_errors(evaluated: dict[str, Path], tmp_path: Path, capsys) -> None:
    suite = str(evaluated["pid_los"].parent / "tiny.yaml")
    out = ["--suite", suite, "--workers", "1", "--no-progress", "--json", "--no-references"]
    assert main(["evaluate", "zero_rudder", "--name", "still", "--out", str(tmp_path), *out]) == 0
    assert {r["controller"] for r in json.loads(capsys.readouterr().out)} == {"still"}
    bad = ["leaderboard", "--controllers", "pid_los", "--out", str(tmp_path / "x"), *out]
    assert main([*bad, "--name", "pid_los"]) == 2
    assert "--name 'pid_los': give CONTROLLER=NAME" in capsys.readouterr().err
    assert main([*bad, "--name", "lqr=mine"]) == 2
    assert "--name names ['lqr'], not among the run's controllers: pid_los" in (
        capsys.readouterr().err
    )
    assert not (tmp_path / "x").exists()
