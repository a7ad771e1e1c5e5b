"""The chosen settings' writer: read, changed and written under the file's lock (two
studies ending together keep both sections), through no link."""

from __future__ import annotations

import multiprocessing
from pathlib import Path

import pytest

from shipgym_baselines.errors import RunError
from shipgym_baselines.records.chosen import read_chosen
from shipgym_baselines.tuning.chosen import write_chosen


def _write_sections(args: tuple[str, str, int]) -> None:
    """Write ``count`` sections named ``<prefix><i>`` into the chosen folder (a worker)."""
    folder, prefix, count = args
    for i in range(count):
        write_chosen("pid_los", f"{prefix}{i}", {"damping": float(i)}, {"study": prefix}, folder)


def test_studies_ending_together_keep_every_section(tmp_path: Path) -> None:
    """Four processes writing sections of one file at once: none is lost (each write reads
    the file under its lock), and no lock file or temporary is left."""
    jobs = [(str(tmp_path), prefix, 8) for prefix in "abcd"]
    with multiprocessing.get_context("spawn").Pool(4) as pool:
        pool.map(_write_sections, jobs)
    data = read_chosen("pid_los", tmp_path)
    assert sorted(data["ships"]) == sorted(f"{p}{i}" for p in "abcd" for i in range(8))
    assert [p.name for p in tmp_path.iterdir()] == ["pid_los.yaml"]


def test_a_link_in_place_of_the_chosen_file_is_not_written_through(tmp_path: Path) -> None:
    victim = tmp_path / "victim.yaml"
    victim.write_text("controller: pid_los\nships: {}\n")
    (tmp_path / "chosen").mkdir()
    (tmp_path / "chosen" / "pid_los.yaml").symlink_to(victim)
    with pytest.raises(RunError, match=r"pid_los\.yaml is a symbolic link"):
        write_chosen("pid_los", "nomoto2", {"damping": 1.0}, {"study": "x"}, tmp_path / "chosen")
    assert victim.read_text() == "controller: pid_los\nships: {}\n"
    assert sorted(p.name for p in (tmp_path / "chosen").iterdir()) == ["pid_los.yaml"]
