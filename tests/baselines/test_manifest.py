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
    assert sorted(p.name for p in out.iterdir()) == [LOCK_FILE]
    assert (mine / "precious.txt").read_text() == "mine"
