"""A record's ``trajectory`` field names only a file inside its run folder:
``report`` never reads a file elsewhere."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from shipgym_baselines.cli import main
from shipgym_baselines.errors import RunError
from shipgym_baselines.records.runs import EPISODES_FILE, episode_result


def test_finding7_a_records_trajectory_names_only_a_file_in_its_run_folder(
    tmp_path: Path, capsys
) -> None:
    run = tmp_path / "run"
    suite = tmp_path / "one.yaml"
    suite.write_text(
        yaml.safe_dump(
            {"name": "one", "scenarios": ["nominal"], "controllers": ["zero_rudder"], "seeds": 1}
        )
    )
    assert (
        main(
            [
                "leaderboard",
                "--suite",
                str(suite),
                "--out",
                str(run),
                "--workers",
                "1",
                "--no-progress",
                "--no-references",
                "--json",
            ]
        )
        == 0
    )
    outside = tmp_path / "elsewhere.npz"
    np.savez(outside, t=np.arange(3.0))
    (record,) = [json.loads(line) for line in (run / EPISODES_FILE).read_text().splitlines()]
    for name in (str(outside), "../elsewhere.npz", "trajectories/../../elsewhere.npz"):
        with pytest.raises(RunError, match="not a file inside its run folder"):
            episode_result({**record, "trajectory": name}, run)
    (run / EPISODES_FILE).write_text(json.dumps({**record, "trajectory": str(outside)}) + "\n")
    capsys.readouterr()
    code = main(["report", str(run), "--out", str(tmp_path / "report")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "not a file inside its run folder" in err and len(err.splitlines()) == 1
