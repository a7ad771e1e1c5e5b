"""Reading the settings a study chose (the writer: shipgym_baselines.tuning.chosen)."""

from __future__ import annotations

from pathlib import Path

import pytest

from shipgym_baselines.records import chosen
from shipgym_baselines.tuning import chosen as tuning_chosen


def test_a_controller_without_a_file_has_no_chosen_settings(tmp_path: Path) -> None:
    assert chosen.read_chosen("pid_los", tmp_path) == {}
    assert chosen.section_record("pid_los", "mariner", tmp_path) is None


def test_the_ship_section_else_the_all_section(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    tuning_chosen.write_chosen("agent", "all", {"lr": 0.001}, {"study": "s"}, tmp_path)
    tuning_chosen.write_chosen("agent", "mariner", {"lr": 0.01}, {}, tmp_path)
    assert chosen.section_record("agent", "all", tmp_path) == ({"lr": 0.001}, {"study": "s"})
    monkeypatch.setattr(chosen, "chosen_dir", lambda: tmp_path)
    chosen.packaged_chosen.cache_clear()
    try:
        assert chosen.tuned_settings("agent", "mariner") == {"lr": 0.01}
        assert chosen.tuned_settings("agent", "nomoto2") == {"lr": 0.001}
    finally:
        chosen.packaged_chosen.cache_clear()


@pytest.mark.parametrize("text", ["untouched\n", "ships: [1, 2]\n", "ships: {a: 1\n"])
def test_a_file_that_is_no_chosen_settings_is_one_line(tmp_path: Path, text: str) -> None:
    from shipgym_baselines.errors import RunError

    (tmp_path / "pid_los.yaml").write_text(text)
    with pytest.raises(RunError) as refused:
        chosen.read_chosen("pid_los", tmp_path)
    assert str(refused.value).startswith(f"{tmp_path / 'pid_los.yaml'}: ")
    assert "\n" not in str(refused.value)
