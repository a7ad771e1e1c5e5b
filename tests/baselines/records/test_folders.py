"""A run's output folder (:mod:`shipgym_baselines.records.folders`): a used or unusable
``--out`` refused before any work, ``--force`` deleting only what a run wrote; the train
refusal."""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import pytest

from shipgym_baselines.cli import main
from shipgym_baselines.errors import RunError
from shipgym_baselines.leaderboard.run import run_leaderboard
from shipgym_baselines.records.episodes import read_episodes
from shipgym_baselines.records.folders import check_out_dir, clear_outputs
from shipgym_baselines.records.manifest import snapshot
from shipgym_baselines.records.runrecord import read_run
from tests.baselines.records.conftest import untimed, write_suite


def test_a_used_out_is_refused_before_any_episode(tmp_path: Path, capsys) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    start = time.perf_counter()
    with pytest.raises(RunError, match=r"not empty.*--resume.*--force"):
        run_leaderboard(write_suite(tmp_path), out_dir=out, show_progress=False)
    assert time.perf_counter() - start < 1.0
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]
    code = main(["leaderboard", "--suite", write_suite(tmp_path), "--out", str(out)])
    assert code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"--out {out} is not empty" in err


def test_an_unusable_out_is_refused_first(tmp_path: Path, capsys) -> None:
    file = tmp_path / "file"
    file.write_text("")
    for out, problem in ((file, "is a file"), (file / "below", f"{file} is a file")):
        # checked before the (unknown) suite is even read
        assert main(["leaderboard", "--suite", "no_such_suite", "--out", str(out)]) == 2
        assert problem in capsys.readouterr().err
    if os.geteuid() != 0:  # root writes anywhere
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        with pytest.raises(RunError, match="not writable"):
            check_out_dir(locked / "out")


def test_finding4_force_deletes_only_what_the_manifest_lists(
    tmp_path: Path, clean_run: Path
) -> None:
    """A user's files that look like outputs (``*.png``, a directory named ``*.png``, their
    own file in ``trajectories/``, a ``report.json``) make --force refuse, deleting
    nothing; without them --force deletes exactly what the earlier run listed."""
    out, suite = tmp_path / "out", write_suite(tmp_path)
    run_leaderboard(suite, seeds=1, out_dir=out, workers=1, show_progress=False)
    listed = set((out / "manifest.txt").read_text().splitlines())
    assert {"run.json", "episodes.jsonl", "leaderboard.md", "scenario_nominal.png"} <= listed
    assert snapshot(out) <= listed | {"manifest.txt"}  # every path the run wrote is listed
    mine = ["my_plot.png", "figures.png/keep.txt", "trajectories/mine.npz", "report.json"]
    for name in mine:
        (out / name).parent.mkdir(exist_ok=True)
        (out / name).write_text("mine")
    before = snapshot(out)
    with pytest.raises(RunError, match=r"--force: .* holds files no run wrote: figures\.png, "):
        run_leaderboard(suite, out_dir=out, workers=1, show_progress=False, force=True)
    assert snapshot(out) == before  # nothing deleted
    for name in mine:
        (out / name).unlink()
    (out / "figures.png").rmdir()
    rows = run_leaderboard(suite, out_dir=out, workers=1, show_progress=False, force=True)
    assert len(read_episodes(out)) == 8 and read_run(out)["status"] == "complete"
    assert untimed(rows) == untimed(json.loads((clean_run / "leaderboard.json").read_text()))
    # a folder written by no run of this version (no manifest) is refused, not guessed at
    (out / "manifest.txt").unlink()
    with pytest.raises(RunError, match=r"no manifest\.txt"):
        run_leaderboard(suite, out_dir=out, show_progress=False, force=True)
    assert (out / "run.json").is_file()


def test_finding4_report_force_deletes_only_its_listed_outputs(
    tmp_path: Path, clean_run: Path, capsys
) -> None:
    report = tmp_path / "report"
    assert main(["report", str(clean_run), "--out", str(report), "--json"]) == 0
    assert "report.json" in (report / "manifest.txt").read_text().splitlines()
    (report / "trajectories").mkdir()
    (report / "trajectories" / "mine.npz").write_text("mine")
    assert main(["report", str(clean_run), "--out", str(report), "--force", "--json"]) == 2
    assert "trajectories/mine.npz" in capsys.readouterr().err
    assert (report / "leaderboard.json").is_file()
    (report / "trajectories" / "mine.npz").unlink()
    assert main(["report", str(clean_run), "--out", str(report), "--force", "--json"]) == 2
    assert "holds files no run wrote: trajectories;" in capsys.readouterr().err  # their folder
    (report / "trajectories").rmdir()
    assert main(["report", str(clean_run), "--out", str(report), "--force", "--json"]) == 0


def test_train_refuses_a_used_agent_folder(tmp_path: Path, capsys) -> None:
    from shipgym_baselines.learned.agent_folder import TRAINING_OUTPUTS
    from shipgym_baselines.training.train import train

    out = tmp_path / "agent"
    out.mkdir()
    (out / "model.zip").write_text("an earlier run")
    assert main(["train", "ppo", "--out", str(out), "--timesteps", "64", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert f"--out {out} is not empty" in err and "agent folder of ppo" in err
    with pytest.raises(RunError, match="not empty"):
        train("ppo", out_dir=out, n_timesteps=64, progress=False)
    assert sorted(p.name for p in out.iterdir()) == ["model.zip"]
    # --force clears only what training writes
    (out / "checkpoints").mkdir()
    clear_outputs(out, TRAINING_OUTPUTS)
    assert not any(out.iterdir())
    (out / "notes.txt").write_text("mine")
    with pytest.raises(RunError, match=r"notes\.txt"):
        train("ppo", out_dir=out, n_timesteps=64, progress=False, force=True)
