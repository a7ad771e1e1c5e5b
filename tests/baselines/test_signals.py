"""Signals, killed workers and a full disk: each ends a run in one
line with its record's status, and no worker outlives the run."""

from __future__ import annotations

import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from shipgym_baselines.records.episodes import read_episodes
from shipgym_baselines.records.runrecord import read_run
from tests.baselines.records.conftest import write_suite

ROOT = Path(__file__).resolve().parents[2]


def leaderboard(out: Path, suite: str = "smoke") -> list[str]:
    """The command of ``shipgym leaderboard`` with 2 workers, one seed."""
    command = [sys.executable, "-m", "shipgym_baselines.cli", "leaderboard", "--suite", suite]
    return [*command, "--seeds", "1", "--out", str(out), "--workers", "2", "--no-progress"]


def start(out: Path, suite: str = "smoke", **popen: object) -> subprocess.Popen:
    """:func:`leaderboard` in its own session, stderr piped."""
    return subprocess.Popen(
        leaderboard(out, suite),
        cwd=ROOT,
        stderr=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        text=True,
        start_new_session=True,
        **popen,  # type: ignore[arg-type]
    )


def children(pid: int) -> set[int]:
    """The process ids of ``pid``'s children (every thread's)."""
    found: set[int] = set()
    for task in Path(f"/proc/{pid}/task").glob("*"):
        text = (task / "children").read_text() if (task / "children").exists() else ""
        found |= {int(p) for p in text.split()}
    return found


def alive(pid: int) -> bool:
    """``pid`` runs (a zombie, dead but not yet reaped, does not)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, IndexError):
        return False
    return state not in ("Z", "X")


def first_episode(process: subprocess.Popen, out: Path) -> set[int]:
    """Wait until an episode is recorded; the run's worker processes then."""
    deadline = time.monotonic() + 180
    while not ((out / "run.json").is_file() and read_episodes(out)):
        assert process.poll() is None and time.monotonic() < deadline
        time.sleep(0.05)
    workers = children(process.pid)
    assert len(workers) == 2, workers
    return workers


def gone(pids: set[int], within: float = 15.0) -> bool:
    deadline = time.monotonic() + within
    while any(alive(p) for p in pids):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.1)
    return True


def test_finding6_sigterm_ends_like_sigint(tmp_path: Path) -> None:
    """SIGTERM to the run's process alone (as ``timeout`` sends it): one line, status
    interrupted, exit code 143, workers gone."""
    out = tmp_path / "out"
    process = start(out)
    workers = first_episode(process, out)
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 143
    assert "Traceback" not in err and err.count("\n") == 1, err
    assert err.startswith("shipgym leaderboard: interrupted by SIGTERM: ")
    assert err.rstrip().endswith("; resume with --resume")
    record = read_run(out)
    assert record["status"] == "interrupted" and record["episodes"] == len(read_episodes(out))
    assert gone(workers)


def test_finding6_workers_exit_when_the_parent_is_killed(tmp_path: Path) -> None:
    """kill -9 of the parent: its pool workers exit (they used to linger)."""
    out = tmp_path / "out"
    process = start(out)
    workers = first_episode(process, out)
    process.kill()
    process.communicate(timeout=60)
    assert gone(workers)
    assert read_run(out)["status"] == "running"  # a killed run keeps its episodes
    assert read_episodes(out)


def test_finding6_a_killed_worker_ends_the_run_in_one_line(tmp_path: Path) -> None:
    out = tmp_path / "out"
    process = start(out)
    workers = first_episode(process, out)
    os.kill(min(workers), signal.SIGKILL)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 1
    assert "Traceback" not in err and "BrokenProcessPool" not in err and err.count("\n") == 1, err
    assert err.startswith(
        "shipgym leaderboard: failed: a worker process died (killed, or out of memory): "
    )
    assert err.rstrip().endswith("; resume with --resume")
    record = read_run(out)
    assert record["status"] == "failed" and record["episodes"] == len(read_episodes(out))
    assert gone(workers)


@pytest.mark.parametrize("limit", [7_000, 60_000], ids=["7kB", "60kB"])
def test_finding6_a_full_disk_is_one_line_failed_and_leaves_nothing_that_blocks_force(
    tmp_path: Path, limit: int
) -> None:
    """No file may grow beyond ``limit`` bytes (RLIMIT_FSIZE: a disk that fills up while a
    trajectory file, or later a figure, is written): one line, status failed, no stray
    temporary file; ``--force`` then starts afresh."""
    out, suite = tmp_path / "out", write_suite(tmp_path)
    env = {**os.environ, "SHIPGYM_NO_COMPILE": "1"}  # a compiled model is larger: no warning

    def small_files() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    process = start(out, suite, preexec_fn=small_files, env=env)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 1
    assert "Traceback" not in err and err.count("\n") == 1, err
    assert err.startswith("shipgym leaderboard: failed: no room to write ")
    assert "File too large" in err and err.rstrip().endswith("; resume with --resume")
    # the file that could not be written is named (trajectories are deflated to ≤ 4.2 kB and
    # run.json holds 6 kB, so the first file to fail is a figure or the page)
    assert f"no room to write {out}/" in err
    record = read_run(out)
    assert record["status"] == "failed" and record["error"].startswith("no room to write")
    assert not [p for p in out.rglob("*") if ".tmp" in p.name]
    forced = subprocess.run(
        [*leaderboard(out, suite), "--force"], cwd=ROOT, capture_output=True, text=True
    )
    assert forced.returncode == 0, forced.stderr
    assert read_run(out)["status"] == "complete"


def test_finding6_a_full_disk_under_report_is_one_line(tmp_path: Path) -> None:
    out, suite = tmp_path / "out", write_suite(tmp_path)
    assert subprocess.run(leaderboard(out, suite), cwd=ROOT, capture_output=True).returncode == 0

    def small_files() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (60_000, 60_000))

    report = tmp_path / "report"
    command = [
        sys.executable,
        "-m",
        "shipgym_baselines.cli",
        "report",
        str(out),
        "--out",
        str(report),
    ]
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, preexec_fn=small_files)
    assert done.returncode == 1 and done.stderr.count("\n") == 1, done.stderr
    assert done.stderr.startswith("shipgym report: failed: no room to write ")
    assert done.stderr.rstrip().endswith(f"the report in {report} is incomplete")
    assert not [p for p in report.rglob("*") if ".tmp" in p.name]
    forced = subprocess.run([*command, "--force"], cwd=ROOT, capture_output=True, text=True)
    assert forced.returncode == 0, forced.stderr
