"""The manifest ``--force`` deletes by: only what a run wrote."""

from __future__ import annotations

from pathlib import Path

import pytest

from shipgym_baselines.errors import RunError
from shipgym_baselines.plots import scenarios as scenario_figures
from shipgym_baselines.records.locking import LOCK_FILE
from shipgym_baselines.records.manifest import (
    MANIFEST_FILE,
    Manifest,
    clear_listed,
    read_manifest,
    snapshot,
)
from shipgym_baselines.records.outfiles import make_dir, write_text
from tests.baselines.conftest import SMOKE_CONTROLLERS, copy_folder


def test_finding4_claimed_paths_are_listed_once_before_they_exist(tmp_path: Path) -> None:
    manifest = Manifest(tmp_path)
    manifest.claim("run.json", "trajectories", "trajectories/a.npz", "run.json")
    manifest.claim("run.json")
    assert (tmp_path / MANIFEST_FILE).read_text().splitlines() == [
        "run.json",
        "trajectories",
        "trajectories/a.npz",
    ]
    with manifest.recording():
        write_text(tmp_path / "figure.png", "drawn")
        make_dir(tmp_path / "sub")
        write_text(tmp_path / "sub" / "page.svg", "drawn")
        (tmp_path / "users.txt").write_text("a user's, written meanwhile")
    listed = read_manifest(tmp_path)
    assert listed >= {"figure.png", "sub", "sub/page.svg", MANIFEST_FILE}
    assert "users.txt" not in listed  # only what the run wrote itself


def test_finding4_force_deletes_the_listed_and_refuses_anything_else(tmp_path: Path) -> None:
    out, mine = tmp_path / "out", tmp_path / "mine"
    out.mkdir()
    mine.mkdir()
    (mine / "precious.txt").write_text("mine")
    manifest = Manifest(out)
    manifest.claim("trajectories", "trajectories/a.npz", "leaderboard.md", "gone.png")
    (out / "trajectories").mkdir()
    (out / "trajectories" / "a.npz").write_text("run")
    (out / "leaderboard.md").write_text("run")
    (out / LOCK_FILE).write_text("a stale lock: never listed, never deleted")
    (out / "link.png").symlink_to(mine, target_is_directory=True)  # a user's link
    with pytest.raises(RunError, match=r"holds files no run wrote: link\.png; move them away"):
        clear_listed(out)
    assert snapshot(out) == {
        "trajectories",
        "trajectories/a.npz",
        "leaderboard.md",
        "link.png",
        MANIFEST_FILE,
    }
    (out / "link.png").unlink()
    clear_listed(out)  # a listed path that is not there ("gone.png") is no problem

    assert (mine / "precious.txt").read_text() == "mine"


def test_a_finished_run_lists_what_it_kept_not_what_it_removed(tmp_path: Path) -> None:
    """A run writes each episode's trajectory (via a temporary) and removes those
    no figure draws; once it finishes its manifest lists neither the removed files nor any
    temporary, and ``--force`` still clears the folder and refuses a user's file."""
    import numpy as np

    from shipgym_baselines.records.episodes import EpisodeResult, episode_key, episode_record
    from shipgym_baselines.records.runlog import RunLog
    from shipgym_baselines.records.trajectories import trajectory_file

    out = tmp_path / "out"
    suite = {"scenarios": {"nominal": {}}, "controllers": [], "seeds": [0, 1, 2]}
    log = RunLog.open(out, command=["test"], suite=suite, jobs=3)
    t = np.arange(10.0)
    trajectory = {"t": t, "x": t, "y": t, "cross_track_error": t, "rudder_angle": t}
    with log.recording():
        results = [
            EpisodeResult("pid_los", "classical", "nominal", seed, {"ace": 1.0}, trajectory)
            for seed in (0, 1, 2)
        ]
        for r in results:
            log.append(r, keep_trajectory=True)
        dropped = [episode_key(episode_record(r)) for r in results[1:]]
        log.drop_trajectories(dropped)
    listed = (out / MANIFEST_FILE).read_text().splitlines()
    kept = trajectory_file(episode_key(episode_record(results[0])))
    assert kept in listed and (out / kept).is_file()
    assert not [p for p in listed if p.startswith("trajectories/") and p != kept]
    # temporaries: only the run record's and the manifest's own (a later run rewrites them)
    assert {p for p in listed if ".tmp" in p} <= {".run.json.tmp", f".{MANIFEST_FILE}.tmp"}
    assert all((out / p).exists() for p in listed if not p.startswith("."))
    (out / "mine.txt").write_text("a user's")
    with pytest.raises(RunError, match=r"holds files no run wrote: mine\.txt"):
        clear_listed(out)
    (out / "mine.txt").unlink()
    clear_listed(out)
    assert snapshot(out) == set()  # the lock is released when the run ends


def test_a_file_added_during_the_figures_stage_is_not_the_runs(
    tmp_path: Path, smoke_run: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A user's file that appears while the tables and figures are drawn is not listed in
    the manifest, and the next ``--force`` refuses to delete it (naming it)."""
    from shipgym_baselines.leaderboard.run import run_leaderboard

    out = copy_folder(smoke_run, tmp_path / "out")
    draw = scenario_figures.plot_scenarios

    def draw_while_the_user_saves(folder: Path, *args: object, **kwargs: object) -> list[Path]:
        (folder / "holiday.png").write_text("a user's")  # saved meanwhile, e.g. by a viewer
        return draw(folder, *args, **kwargs)

    monkeypatch.setattr(scenario_figures, "plot_scenarios", draw_while_the_user_saves)
    settings = {"seeds": 1, "controllers": SMOKE_CONTROLLERS, "show_progress": False}
    run_leaderboard("smoke", out_dir=out, resume=True, **settings)  # the tables again
    listed = read_manifest(out)
    assert "holiday.png" not in listed
    assert {"leaderboard.md", "scenario_rudder_aging.png", "run.json"} <= listed
    monkeypatch.undo()
    with pytest.raises(RunError, match=r"--force: .* holds files no run wrote: holiday\.png;"):
        run_leaderboard("smoke", out_dir=out, force=True, **settings)
    assert (out / "holiday.png").read_text() == "a user's"


def test_pool_workers_list_the_figures_they_write(
    tmp_path: Path, smoke_run: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Figures drawn in a process pool are listed by the workers as they write them."""
    from shipgym_baselines.leaderboard import outputs
    from shipgym_baselines.records.runrecord import read_run

    monkeypatch.setattr(outputs, "POOLED_FIGURES", 1)  # a pool for three figures
    out = tmp_path / "out"
    out.mkdir()
    manifest = Manifest(out)
    with manifest.recording():
        outputs.write_results(
            out, read_run(smoke_run)["suite"], outputs.load_results(smoke_run), workers=2
        )
    manifest.compact()
    written = snapshot(out) - {MANIFEST_FILE}
    assert {"scenario_heldout_0.png", "scenario_mariner_track.png"} <= written
    assert read_manifest(out) - {MANIFEST_FILE} == written  # listed: all of them, only them
