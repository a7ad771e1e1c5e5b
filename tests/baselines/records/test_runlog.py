"""An open run (:mod:`shipgym_baselines.records.runlog`): each episode on disk as it ends,
Ctrl-C, a kill, a failure and a full disk recorded, ``--resume`` to the clean table, links
planted in the folder refused."""

from __future__ import annotations

import errno
import io
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import shipgym_baselines.leaderboard.jobs
from shipgym_baselines.cli import main
from shipgym_baselines.errors import RunError, RunFailed
from shipgym_baselines.leaderboard.run import run_leaderboard
from shipgym_baselines.plots import scenarios as scenario_figures
from shipgym_baselines.records.episodes import read_episodes
from shipgym_baselines.records.runlog import RunInterrupted
from shipgym_baselines.records.runrecord import read_run
from tests.baselines.conftest import SMOKE_CONTROLLERS, copy_folder
from tests.baselines.records.conftest import resume_tiny, untimed, write_suite

ROOT = Path(__file__).resolve().parents[3]


def test_each_episode_is_on_disk_when_it_ends(tmp_path: Path) -> None:
    seen: list[int] = []

    def count_lines(result: object) -> None:
        seen.append(len(read_episodes(tmp_path / "out")))

    run_leaderboard(
        write_suite(tmp_path),
        out_dir=tmp_path / "out",
        workers=2,
        show_progress=False,
        on_episode=count_lines,
    )
    assert seen == list(range(1, 9))


def test_an_interrupted_run_resumes_to_the_clean_table(tmp_path: Path, clean_run: Path) -> None:
    suite, out = write_suite(tmp_path), tmp_path / "out"

    def stop_after_three(result: object, seen: list[int] = []) -> None:  # noqa: B006
        seen.append(1)
        if len(seen) == 3:
            raise KeyboardInterrupt

    with pytest.raises(RunInterrupted) as interrupted:
        run_leaderboard(
            suite, out_dir=out, workers=2, show_progress=False, on_episode=stop_after_three
        )
    assert str(interrupted.value) == (
        f"3 of 8 episodes kept in {out / 'episodes.jsonl'}; resume with --resume"
    )
    assert read_run(out)["status"] == "interrupted" and len(read_episodes(out)) == 3
    assert not (out / "leaderboard.json").exists()
    ran, rows = resume_tiny(tmp_path, out)
    assert len(ran) == 5  # only the missing jobs
    record = read_run(out)
    assert record["status"] == "complete" and record["episodes"] == 8
    assert len(record["resumed"]) == 1
    clean = json.loads((clean_run / "leaderboard.json").read_text())
    assert untimed(json.loads((out / "leaderboard.json").read_text())) == untimed(clean)
    assert untimed(rows) == untimed(clean)
    assert sorted(p.name for p in out.glob("*.png")) == sorted(
        p.name for p in clean_run.glob("*.png")
    )


def test_resume_with_a_changed_suite_is_refused(tmp_path: Path, clean_run: Path) -> None:
    with pytest.raises(RunError, match=r"suite differs.*seeds: 10001 only in the run"):
        run_leaderboard(
            write_suite(tmp_path), seeds=1, out_dir=clean_run, show_progress=False, resume=True
        )
    # a list of controllers is told by their names, never cut short
    with pytest.raises(RunError, match=r"controllers: .* only in the run; random only now") as e:
        run_leaderboard(
            write_suite(tmp_path),
            out_dir=clean_run,
            show_progress=False,
            resume=True,
            controllers=["random"],
        )
    assert "…" not in str(e.value)
    changed = write_suite(tmp_path, scenarios=["nominal", "current_shift"])
    with pytest.raises(RunError, match=r"scenarios\.rudder_aging only in the run"):
        run_leaderboard(changed, out_dir=clean_run, show_progress=False, resume=True)
    with pytest.raises(RunError, match="no run to resume"):
        run_leaderboard(changed, out_dir=tmp_path / "new", show_progress=False, resume=True)
    assert read_run(clean_run)["status"] == "complete"


def test_a_killed_run_keeps_its_episodes_and_resumes(tmp_path: Path, clean_run: Path) -> None:
    """A line cut short by a kill is dropped on resume; the rest are kept."""
    out = tmp_path / "out"
    out.mkdir()
    lines = (clean_run / "episodes.jsonl").read_text().splitlines(keepends=True)
    (out / "episodes.jsonl").write_text("".join(lines[:4]) + lines[4][:30])
    (out / "run.json").write_text((clean_run / "run.json").read_text())
    assert len(read_episodes(out)) == 4
    ran, _ = resume_tiny(tmp_path, out)
    assert len(ran) == 4 and len(read_episodes(out)) == 8


def test_cli_ctrl_c_says_what_was_kept(tmp_path: Path, monkeypatch, capsys) -> None:
    calls: list[object] = []
    real = shipgym_baselines.leaderboard.jobs.run_batch  # a controller's 2 seeds in lockstep

    def third_is_interrupted(job: tuple) -> object:
        calls.append(job)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(job)

    monkeypatch.setattr(shipgym_baselines.leaderboard.jobs, "run_batch", third_is_interrupted)
    out = tmp_path / "out"
    args = ["leaderboard", "--suite", write_suite(tmp_path), "--out", str(out), "--workers", "1"]
    args.append("--no-references")  # the suite's two controllers only
    assert main([*args, "--no-progress"]) == 130
    assert capsys.readouterr().err == (
        f"shipgym leaderboard: interrupted: 4 of 8 episodes kept in {out / 'episodes.jsonl'}; "
        "resume with --resume\n"
    )
    assert read_run(out)["command"] == ["shipgym", *args, "--no-progress"]


def test_plots_stay_in_the_run_folder(tmp_path: Path) -> None:
    """A scenario given by its YAML path is plotted as ``scenario_<name>.png`` (its
    ``name:``) inside --out, never beside the scenario file."""
    cases = tmp_path / "cases"
    cases.mkdir()
    nominal = (ROOT / "configs/scenarios/nominal.yaml").read_text()
    (cases / "case_v1.yaml").write_text(nominal.replace("name: nominal", "name: my_case"))
    suite = write_suite(tmp_path, scenarios=["cases/case_v1.yaml"], controllers=["pid_los"])
    out = tmp_path / "out"
    run_leaderboard(suite, seeds=1, out_dir=out, workers=1, show_progress=False)
    assert (out / "scenario_my_case.png").is_file()
    assert sorted(p.name for p in cases.iterdir()) == ["case_v1.yaml"]


def test_a_failing_run_is_recorded_as_failed(tmp_path: Path, monkeypatch) -> None:
    calls: list[object] = []
    real = shipgym_baselines.leaderboard.jobs.run_batch  # a controller's 2 seeds in lockstep

    def second_fails(job: tuple) -> object:
        calls.append(job)
        if len(calls) == 2:
            raise RuntimeError("a bug in a controller")
        return real(job)

    monkeypatch.setattr(shipgym_baselines.leaderboard.jobs, "run_batch", second_fails)
    out = tmp_path / "out"
    with pytest.raises(RuntimeError, match="a bug"):  # a bug keeps its traceback
        run_leaderboard(write_suite(tmp_path), out_dir=out, workers=1, show_progress=False)
    record = read_run(out)
    assert record["status"] == "failed" and record["error"] == "RuntimeError: a bug in a controller"
    assert record["episodes"] == len(read_episodes(out)) == 2


def test_sigint_stops_the_workers_without_tracebacks(tmp_path: Path) -> None:
    """A real Ctrl-C (SIGINT to the process group, as a terminal sends it) with 2 workers."""
    out = tmp_path / "out"
    command = [sys.executable, "-m", "shipgym_baselines.cli", "leaderboard", "--suite", "smoke"]
    command += ["--seeds", "1", "--out", str(out), "--workers", "2", "--no-progress"]
    process = subprocess.Popen(
        command,
        cwd=ROOT,
        stderr=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        text=True,
        start_new_session=True,
        # a terminal's foreground job: SIGINT at its default even when pytest runs as a
        # background job of a non-interactive shell, which ignores SIGINT for its children
        # (an ignored SIGINT is inherited, and the run then rightly finishes)
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    deadline = time.monotonic() + 120
    while not ((out / "run.json").is_file() and read_episodes(out)):  # an episode ended
        assert process.poll() is None and time.monotonic() < deadline
        time.sleep(0.05)
    os.killpg(process.pid, signal.SIGINT)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130
    assert "Traceback" not in err and err.count("\n") == 1, err
    assert err.startswith("shipgym leaderboard: interrupted: ") and "resume with --resume" in err
    record = read_run(out)
    assert record["status"] == "interrupted" and record["episodes"] == len(read_episodes(out))


class _FillsUp(io.FileIO):
    """A file on a disk that fills up: the first write stores half its bytes, then none."""

    full = False

    def write(self, data: bytes) -> int:  # type: ignore[override]
        if self.full:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        self.full = True
        return super().write(bytes(data)[: len(data) // 2])


def test_finding6_a_line_the_disk_cannot_hold_is_cut_off(tmp_path: Path, clean_run: Path) -> None:
    """A full disk cuts an episode's line short: it is cut off again, so no partial line
    stays between whole ones once there is room again."""
    from shipgym_baselines.records.runlog import RunLog
    from shipgym_baselines.records.trajectories import episode_result

    records = read_episodes(clean_run)
    log = RunLog.open(
        tmp_path / "out", command=["test"], suite=read_run(clean_run)["suite"], jobs=8
    )
    with pytest.raises(RunFailed, match=r"no room to write .*episodes\.jsonl"):
        with log.recording():
            log.append(episode_result(records[0], clean_run))
            full = _FillsUp(log.episodes_file, "ab")
            log._file, spare = full, log._file
            spare.close()
            log.append(episode_result(records[1], clean_run))
    assert len((log.episodes_file).read_text().splitlines()) == 1
    assert read_run(tmp_path / "out")["status"] == "failed"
    ran, _ = resume_tiny(tmp_path, tmp_path / "out")
    assert len(ran) == 7 and len(read_episodes(tmp_path / "out")) == 8


@pytest.mark.parametrize(
    "name", ["leaderboard.md", "aggregate.json", ".run.json.tmp", ".manifest.txt.tmp"]
)
def test_resume_refuses_a_link_planted_as_an_output_and_leaves_its_target(
    tmp_path: Path, smoke_run: Path, capsys, name: str
) -> None:
    notes = tmp_path / "notes.txt"
    notes.write_text("my notes\n")
    out = copy_folder(smoke_run, tmp_path / "out")
    (out / name).unlink(missing_ok=True)
    (out / name).symlink_to(notes)
    argv = ["leaderboard", "--suite", "smoke", "--seeds", "1", "--out", str(out), "--resume"]
    assert main([*argv, "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"shipgym leaderboard: error: {out / name} is a symbolic link to {notes}: a run "
        "writes no file through it; remove it or choose another --out\n"
    )
    assert notes.read_text() == "my notes\n" and read_run(out)["status"] == "complete"


def test_a_link_planted_while_the_tables_are_written_is_refused(
    tmp_path: Path, smoke_run: Path, monkeypatch
) -> None:
    """A link that appears during the run, as a table the run is about to write: that
    write is refused (the run fails in one line) and the link's target is unchanged."""

    notes = tmp_path / "notes.txt"
    notes.write_text("my notes\n")
    out = copy_folder(smoke_run, tmp_path / "out")
    draw = scenario_figures.plot_scenarios

    def plant_then_draw(folder: Path, *args: object, **kwargs: object) -> list[Path]:
        (folder / "aggregate.json").unlink(missing_ok=True)
        (folder / "aggregate.json").symlink_to(notes)
        return draw(folder, *args, **kwargs)

    monkeypatch.setattr(scenario_figures, "plot_scenarios", plant_then_draw)
    with pytest.raises(RunError, match=r"aggregate\.json is a symbolic link"):
        run_leaderboard(
            "smoke",
            seeds=1,
            out_dir=out,
            controllers=SMOKE_CONTROLLERS,
            show_progress=False,
            resume=True,
        )
    assert notes.read_text() == "my notes\n" and read_run(out)["status"] == "failed"
