"""Files a run writes go through no link (:mod:`shipgym_baselines.records.outfiles`): a planted
link is refused in one line naming it, and what it points to is left as it was."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from shipgym_baselines.errors import RunError
from shipgym_baselines.records.outfiles import (
    carried,
    check_no_links,
    make_dir,
    open_regular,
    recording,
    write_bytes,
)


@pytest.fixture
def notes(tmp_path: Path) -> Path:
    """A user's file outside the run folder, which a planted link points to."""
    file = tmp_path / "notes.txt"
    file.write_text("my notes\n")
    return file


def test_a_file_written_over_a_link_is_refused_and_its_target_unchanged(
    tmp_path: Path, notes: Path
) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "leaderboard.md").symlink_to(notes)
    with pytest.raises(RunError) as refused:
        write_bytes(out / "leaderboard.md", b"# rows\n")
    message = str(refused.value)
    assert "\n" not in message
    assert f"{out / 'leaderboard.md'} is a symbolic link to {notes}" in message
    assert notes.read_text() == "my notes\n"
    assert sorted(p.name for p in out.iterdir()) == ["leaderboard.md"]  # no temporary left
    (out / "figure.png").mkdir()
    with pytest.raises(RunError, match=r"figure\.png is a folder"):
        write_bytes(out / "figure.png", b"png")


def test_a_write_replaces_the_file_and_announces_it_and_its_temporary_first(
    tmp_path: Path,
) -> None:
    target = tmp_path / "run.json"
    target.write_text("old")
    announced: list[Path] = []
    with recording(lambda paths: announced.extend(p for p in paths if not p.exists())):
        write_bytes(target, b"new")
    assert target.read_bytes() == b"new"
    (temporary,) = announced  # the target existed; its new temporary did not
    assert temporary.parent == tmp_path and temporary.name.startswith(".run.json.")
    assert temporary.name.endswith(".tmp") and not temporary.exists()


def test_a_file_changed_in_place_must_be_a_regular_file_of_its_own(
    tmp_path: Path, notes: Path
) -> None:
    (tmp_path / "link").symlink_to(notes)
    os.link(notes, tmp_path / "hard")
    os.mkfifo(tmp_path / "fifo")
    for name, what in (("link", "a symbolic link"), ("hard", "a hard link"), ("fifo", "a FIFO")):
        with pytest.raises(RunError, match=f"{name} is {what}"):
            open_regular(tmp_path / name, os.O_WRONLY | os.O_APPEND | os.O_CREAT)
    assert notes.read_text() == "my notes\n"
    fd = open_regular(tmp_path / "new", os.O_WRONLY | os.O_CREAT)
    os.close(fd)
    assert (tmp_path / "new").is_file()


def test_a_sub_folder_must_not_be_a_link(tmp_path: Path) -> None:
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    out = tmp_path / "out"
    out.mkdir()
    (out / "trajectories").symlink_to(elsewhere, target_is_directory=True)
    with pytest.raises(RunError, match="trajectories is a symbolic link"):
        make_dir(out / "trajectories")
    assert make_dir(out / "figures").is_dir()


def test_a_folder_holding_a_link_below_is_named(tmp_path: Path, notes: Path) -> None:
    out = tmp_path / "out"
    (out / "trajectories").mkdir(parents=True)
    (out / "trajectories" / "a.npz").symlink_to(notes)
    with pytest.raises(RunError, match=r"trajectories/a\.npz is a symbolic link"):
        check_no_links(out)
    linked = tmp_path / "linked_out"
    linked.symlink_to(tmp_path / "elsewhere_out", target_is_directory=True)
    (tmp_path / "elsewhere_out").mkdir()
    check_no_links(linked)  # --out itself may be a link (a results folder on another disk)


def test_a_pool_task_announces_its_files_to_the_submitting_process_recorders(
    tmp_path: Path,
) -> None:
    """:func:`carried` takes the recorders into a worker that did not inherit them (a
    spawned one): the run's manifest lists what the worker wrote."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from shipgym_baselines.records.manifest import Manifest, read_manifest

    manifest = Manifest(tmp_path)
    with manifest.recording():
        task = carried(write_bytes)
    spawn = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=1, mp_context=spawn) as pool:
        pool.submit(task, tmp_path / "figure.png", b"png").result()
        pool.submit(write_bytes, tmp_path / "other.png", b"png").result()  # not carried
    assert (tmp_path / "figure.png").read_bytes() == b"png"
    listed = read_manifest(tmp_path)
    assert "figure.png" in listed and "other.png" not in listed
