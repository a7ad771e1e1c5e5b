"""A run's record, ``run.json`` (:mod:`shipgym_baselines.records.runrecord`): what it
holds after a run, and a malformed one refused in one line naming the file."""

from __future__ import annotations

import datetime
from pathlib import Path

import pytest

from shipgym_baselines.cli import main
from shipgym_baselines.records.runrecord import read_run
from tests.baselines.records.conftest import copy_run, write_suite


def test_run_json_records_command_suite_versions_times_and_status(clean_run: Path) -> None:
    record = read_run(clean_run)
    assert isinstance(record["command"], list) and record["command"]
    suite = record["suite"]
    assert suite["seeds"] == [10_000, 10_001]
    assert [c["name"] for c in suite["controllers"]] == ["pid_los", "zero_rudder"]
    assert list(suite["scenarios"]) == ["nominal", "rudder_aging"]
    aging = suite["scenarios"]["rudder_aging"]  # the scenario's resolved settings
    assert aging["ship"]["model"] == "nomoto2" and aging["events"]
    versions = record["versions"]
    assert {"python", "numpy", "scipy", "gymnasium", "casadi", "shipgym"} <= set(versions)
    assert versions["stable-baselines3"] and versions["torch"]  # installed here
    commit = record["git_commit"]
    assert commit is None or (len(commit) == 40 and int(commit, 16) >= 0)
    start = datetime.datetime.fromisoformat(record["start_time"])
    end = datetime.datetime.fromisoformat(record["end_time"])
    assert start.utcoffset() == datetime.timedelta(0) and start <= end
    assert record["status"] == "complete"
    assert record["jobs"] == record["episodes"] == 8
    # the run's own wall-clock and CPU seconds (tables and figures included)
    assert 0 < record["wall_s"] <= (end - start).total_seconds() + 1.0
    assert record["cpu_s"] > 0


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        (b'{"suite": {"seeds": [1]', "line 1: not JSON (Expecting ',' delimiter)"),
        (b"[1, 2]", "not a run record (no 'suite')"),
        (b'{"suite": {}}', "not a run record (key 'suite.seeds' is null, not a list of integers)"),
        (b'{\n"suite": "\xff"}', "line 2: not UTF-8 text"),
    ],
)
def test_finding2_a_malformed_run_json_is_one_line_naming_the_file(
    tmp_path: Path, clean_run: Path, capsys, text: bytes, problem: str
) -> None:
    out = copy_run(clean_run, tmp_path / "out")
    (out / "run.json").write_bytes(text)
    assert main(["report", str(out), "--out", str(tmp_path / "report")]) == 2
    assert capsys.readouterr().err == f"shipgym report: error: {out / 'run.json'}: {problem}\n"
    suite = write_suite(tmp_path)
    args = ["leaderboard", "--suite", suite, "--out", str(out), "--resume", "--no-progress"]
    assert main(args) == 2
    assert capsys.readouterr().err == f"shipgym leaderboard: error: {out / 'run.json'}: {problem}\n"
