"""One run per output folder: the lock on ``--out``."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from shipgym_baselines.cli import main
from shipgym_baselines.errors import RunError
from shipgym_baselines.leaderboard.run import run_leaderboard
from shipgym_baselines.records.episodes import read_episodes
from shipgym_baselines.records.locking import LOCK_FILE, out_lock
from shipgym_baselines.records.runrecord import read_run
from tests.baselines.conftest import copy_folder
from tests.baselines.records.conftest import write_suite

ROOT = Path(__file__).resolve().parents[3]
HOLD = """
import sys, time
from shipgym_baselines.records.locking import out_lock
with out_lock(sys.argv[1], "2026-01-02T03:04:05+00:00"):
    print("locked", flush=True)
    time.sleep(600)
"""


def hold(folder: Path) -> subprocess.Popen:
    """Another process holding the lock of ``folder``."""
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLD, str(folder)], cwd=ROOT, stdout=subprocess.PIPE, text=True
    )
    assert holder.stdout is not None and holder.stdout.readline() == "locked\n"
    return holder


def test_finding1_a_second_run_on_a_locked_out_is_refused_naming_the_holder(
    tmp_path: Path, capsys
) -> None:
    out, suite = tmp_path / "out", write_suite(tmp_path)
    run_leaderboard(suite, seeds=1, out_dir=out, workers=1, show_progress=False)
    assert not (out / LOCK_FILE).exists()  # a finished run leaves no lock file
    report = tmp_path / "report"
    holder, report_holder = hold(out), hold(report)
    try:
        named = f"(process {holder.pid}, started 2026-01-02T03:04:05+00:00)"
        tries = [
            (["leaderboard", "--suite", suite, "--out", str(out)], out, named),
            (["leaderboard", "--suite", suite, "--out", str(out), "--resume"], out, named),
            (["leaderboard", "--suite", suite, "--out", str(out), "--force"], out, named),
            (["evaluate", "pid_los", "--suite", suite, "--out", str(out), "--resume"], out, named),
            (["report", str(out), "--out", str(report)], report, f"(process {report_holder.pid}"),
        ]
        for argv, folder, who in tries:
            assert main([*argv, "--no-progress"] if argv[0] != "report" else argv) == 2
            err = capsys.readouterr().err
            assert err.count("\n") == 1 and f"--out {folder} is in use by another run {who}" in err
        assert read_run(out)["status"] == "complete" and len(read_episodes(out)) == 4
    finally:
        holder.kill()
        report_holder.kill()
        holder.wait()
        report_holder.wait()
    # a lock left by a killed process is free: the kernel released it with the process
    assert (out / LOCK_FILE).is_file()
    rows = run_leaderboard(suite, seeds=1, out_dir=out, show_progress=False, force=True)
    assert len(rows) == 4 and not (out / LOCK_FILE).exists()
    assert main(["report", str(out), "--out", str(report), "--json"]) == 0
    assert sorted(p.name for p in report.iterdir() if p.name.startswith(".")) == []


def test_finding1_one_process_cannot_lock_a_folder_twice(tmp_path: Path) -> None:
    with out_lock(tmp_path / "out", "now"):
        with (
            pytest.raises(RunError, match="in use by another run"),
            out_lock(tmp_path / "out", "x"),
        ):
            pass
    assert not (tmp_path / "out").exists()  # made for the lock and left empty: removed


def test_finding1_two_runs_started_together_on_one_folder(tmp_path: Path) -> None:
    """The probe: two ``shipgym leaderboard`` processes on one folder.  One runs, the other
    is refused in one line naming it; every episode is recorded once."""
    out, suite = tmp_path / "out", write_suite(tmp_path, seeds=3)
    command = [sys.executable, "-m", "shipgym_baselines.cli", "leaderboard", "--suite", suite]
    command += ["--out", str(out), "--workers", "1", "--no-progress", "--no-references", "--json"]
    runs = [
        subprocess.Popen(command, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        for _ in range(2)
    ]
    done = [(run.pid, *run.communicate(timeout=300), run.returncode) for run in runs]
    codes = sorted(code for *_, code in done)
    assert codes == [0, 2], done
    (winner,) = [pid for pid, _, _, code in done if code == 0]
    (err,) = [e.decode() for _, _, e, code in done if code == 2]
    assert err.count("\n") == 1 and f"in use by another run (process {winner}, started " in err
    lines = (out / "episodes.jsonl").read_text().splitlines()
    keys = {
        tuple(json.loads(line)[k] for k in ("scenario", "controller", "seed")) for line in lines
    }
    assert len(lines) == len(keys) == 12 and read_run(out)["episodes"] == 12
    assert not (out / LOCK_FILE).exists()


def test_finding1_the_lock_file_names_its_holder(tmp_path: Path) -> None:
    with out_lock(tmp_path, "2026-01-02T03:04:05+00:00"):
        holder = json.loads((tmp_path / LOCK_FILE).read_text())
        assert holder["pid"] == os.getpid() and holder["start_time"].startswith("2026-01-02")
    assert not (tmp_path / LOCK_FILE).exists() and tmp_path.is_dir()


def test_a_symlinked_lock_is_refused_and_its_target_unchanged(
    tmp_path: Path, smoke_run: Path, capsys
) -> None:
    """A link planted as ``.shipgym.lock`` (to a user's file outside ``--out``) is refused
    in one line naming it, by a new leaderboard, ``--force``, ``--resume`` and ``report
    --out``; the file it points to is left as it was, and so is the folder."""
    notes = tmp_path / "notes.txt"
    notes.write_text("my notes\n")
    fresh, run = tmp_path / "fresh", copy_folder(smoke_run, tmp_path / "run")
    fresh.mkdir()
    leaderboard = ["leaderboard", "--suite", "smoke", "--seeds", "1", "--no-progress"]
    tries = [
        (fresh, [*leaderboard, "--out", str(fresh)]),
        (run, [*leaderboard, "--out", str(run), "--force"]),
        (run, [*leaderboard, "--out", str(run), "--resume"]),
        (fresh, ["report", str(smoke_run), "--out", str(fresh)]),
        (fresh, ["report", str(smoke_run), "--out", str(fresh), "--force"]),
    ]
    for folder, argv in tries:
        (folder / LOCK_FILE).unlink(missing_ok=True)
        (folder / LOCK_FILE).symlink_to(notes)
        before = {p: p.lstat().st_mtime_ns for p in folder.rglob("*")}
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.count("\n") == 1, err
        assert f"{folder / LOCK_FILE} is a symbolic link to {notes}" in err
        assert notes.read_text() == "my notes\n"
        assert {p: p.lstat().st_mtime_ns for p in folder.rglob("*")} == before
    with pytest.raises(RunError, match="is a symbolic link"):  # the lock itself refuses it
        with out_lock(fresh, "now"):
            pass
    assert notes.read_text() == "my notes\n"
