"""The manifest ``--force`` deletes by (issue 19, finding 4)."""

from __future__ import annotations

from pathlib import Path

import pytest

from shipgym_baselines.errors import RunError
from shipgym_baselines.locking import LOCK_FILE
from shipgym_baselines.manifest import (
    MANIFEST_FILE,
    Manifest,
    clear_listed,
    read_manifest,
    snapshot,
)


def test_finding4_claimed_paths_are_listed_once_before_they_exist(tmp_path: Path) -> None:
    manifest = Manifest(tmp_path)
    manifest.claim("run.json", "trajectories", "trajectories/a.npz", "run.json")
    manifest.claim("run.json")
    assert (tmp_path / MANIFEST_FILE).read_text().splitlines() == [
        "run.json",
        "trajectories",
        "trajectories/a.npz",
    ]
    with manifest.claiming():
        (tmp_path / "figure.png").write_text("drawn")
        (tmp_path / "sub").mkdir()
        (tmp_path / "sub" / "page.svg").write_text("drawn")
    assert read_manifest(tmp_path) >= {"figure.png", "sub", "sub/page.svg", MANIFEST_FILE}


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
    """issue 20: a run writes each episode's trajectory (via a temporary) and removes those
    no figure draws; once it finishes its manifest lists neither the removed files nor any
    temporary, and ``--force`` still clears the folder and refuses a user's file."""
    import numpy as np

    from shipgym_baselines.evaluation import EpisodeResult
    from shipgym_baselines.runs import RunLog, episode_key, episode_record, trajectory_file

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
