"""The command line's limits (issue 19, finding 8): seeds, workers, a suite's seeds and
trial ranges — refused before any work in one line naming the option and the limit;
``--workers`` above the jobs is clamped to them."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

import shipgym_baselines.leaderboard
from shipgym.limits import MAX_SEEDS, LimitError
from shipgym_baselines.cli import main
from shipgym_baselines.learned.train import train_sweep

ONE_JOB = {"name": "one", "scenarios": ["nominal"], "controllers": ["zero_rudder"], "seeds": 1}


def _suite(tmp_path: Path, **changes: object) -> str:
    file = tmp_path / "one.yaml"
    file.write_text(yaml.safe_dump({**ONE_JOB, **changes}))
    return str(file)


def _refused(capsys, argv: list[str]) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    return err


def test_finding8_seeds_beyond_the_limit_are_refused(tmp_path: Path, capsys) -> None:
    out = str(tmp_path / "out")
    err = _refused(
        capsys, ["leaderboard", "--suite", _suite(tmp_path), "--seeds", "1000000000", "--out", out]
    )
    assert f"--seeds is 1000000000, beyond the limit of {MAX_SEEDS}" in err
    err = _refused(capsys, ["leaderboard", "--suite", _suite(tmp_path, seeds=10**9), "--out", out])
    assert "seeds" in err and f"less than or equal to {MAX_SEEDS}" in err
    assert not Path(out).exists()  # before any work


def test_finding8_absurd_trial_ranges_are_refused(tmp_path: Path, capsys) -> None:
    suite = _suite(tmp_path, randomize={"heading_error_deg": [-1e9, 1e9]})
    err = _refused(capsys, ["leaderboard", "--suite", suite, "--out", str(tmp_path / "o")])
    assert "randomize.heading_error_deg" in err and "beyond the limit [-180, 180]" in err


def test_finding8_workers_below_one_are_refused(tmp_path: Path, capsys) -> None:
    out = tmp_path / "out"
    err = _refused(
        capsys, ["leaderboard", "--suite", _suite(tmp_path), "--workers", "-5", "--out", str(out)]
    )
    assert "--workers must be a whole number ≥ 1, got -5" in err
    assert not (out / "episodes.jsonl").exists()
    with pytest.raises(LimitError, match="--workers must be"):
        train_sweep([{"config": "ppo"}], workers=0)


def test_finding8_workers_beyond_the_jobs_are_clamped(tmp_path: Path, monkeypatch) -> None:
    started = []
    real = shipgym_baselines.leaderboard.iter_results

    def spy(jobs, backend, workers):
        started.append(workers)
        return real(jobs, backend, workers)

    monkeypatch.setattr(shipgym_baselines.leaderboard, "iter_results", spy)
    argv = [
        "leaderboard",
        "--suite",
        _suite(tmp_path),
        "--workers",
        "100",
        "--no-progress",
        "--no-references",
        "--out",
        str(tmp_path / "out"),
        "--json",
    ]
    assert main(argv) == 0
    assert started == [1]  # one job: one process, not 100


def test_finding8_heldout_scenarios_beyond_the_limit_are_refused(tmp_path: Path, capsys) -> None:
    suite = _suite(tmp_path, heldout_scenarios=10**9)
    err = _refused(capsys, ["leaderboard", "--suite", suite, "--out", str(tmp_path / "o")])
    assert "heldout_scenarios" in err and "less than or equal to 1000" in err
