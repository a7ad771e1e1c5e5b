"""The command line's limits (docs/records.md, "Limits"): seeds, workers, a suite's seeds and
trial ranges — refused before any work in one line naming the option and the limit;
``--workers`` above the jobs is clamped to them."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

import shipgym_baselines.leaderboard.run
from shipgym.limits import (
    MAX_CONFIG_BYTES,
    MAX_CONFIG_DEPTH,
    MAX_NAME_CHARS,
    MAX_SEEDS,
    LimitError,
)
from shipgym.scenarios.loader import catalogue_dir
from shipgym_baselines.cli import main
from shipgym_baselines.training.train import train_sweep

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
    real = shipgym_baselines.leaderboard.run.iter_results

    def spy(jobs, backend, workers):
        started.append(workers)
        return real(jobs, backend, workers)

    monkeypatch.setattr(shipgym_baselines.leaderboard.run, "iter_results", spy)
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


def test_a_240_character_scenario_name_is_refused_by_validate(tmp_path: Path, capsys) -> None:
    """Its figure's file name would be too long (ENAMETOOLONG after every episode): the
    name is refused up front, by ``--validate`` and by a leaderboard, in one line each."""
    scenario = yaml.safe_load(catalogue_dir().joinpath("nominal.yaml").read_text())
    file = tmp_path / "long.yaml"
    file.write_text(yaml.safe_dump({**scenario, "name": "s" * 240}))
    limit = f"the name has 240 characters, beyond the limit of {MAX_NAME_CHARS}"
    assert main(["scenarios", "--validate", str(file)]) == 2
    out, err = capsys.readouterr()
    problem = [line for line in (out + err).splitlines() if line.startswith(f"{file}:")]
    assert len(problem) == 1 and problem[0].endswith(f": key 'name': Value error, {limit}")
    assert "Traceback" not in out + err
    suite = _suite(tmp_path, scenarios=[str(file)])
    err = _refused(capsys, ["leaderboard", "--suite", suite, "--out", str(tmp_path / "o")])
    assert limit in err and not (tmp_path / "o").exists()
    suite = _suite(tmp_path, name="n" * 240)
    for argv in (["scenarios", "--validate", suite], ["leaderboard", "--suite", suite]):
        assert main([*argv, "--out", str(tmp_path / "o")] if "leaderboard" in argv else argv)
        shown = "".join(capsys.readouterr())
        assert "key 'name'" in shown and "the name has 240 characters" in shown


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ("[" * 5000 + "]" * 5000, f"nested deeper than the limit of {MAX_CONFIG_DEPTH} levels"),
        ("#" * (MAX_CONFIG_BYTES + 1), f"larger than the limit of {MAX_CONFIG_BYTES} bytes"),
    ],
)
def test_a_deep_or_oversized_yaml_is_refused_in_one_line(
    tmp_path: Path, capsys, text: str, problem: str
) -> None:
    """A scenario or suite file of 5,000 nested lists or over the size limit: one line
    naming the file and the limit, never a RecursionError's traceback."""
    file = tmp_path / "deep.yaml"
    file.write_text(f"name: deep\nscenarios: {text}\n")
    assert main(["scenarios", "--validate", str(file)]) == 2
    out, err = capsys.readouterr()
    assert problem in out + err and "Traceback" not in out + err
    err = _refused(capsys, ["leaderboard", "--suite", str(file), "--out", str(tmp_path / "o")])
    assert str(file) in err and problem in err
