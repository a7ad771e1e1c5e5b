"""Episode records (:mod:`shipgym_baselines.records.episodes`): ``episodes.jsonl`` holds
every episode with its metrics, is read as a set keyed by the episode key, and a line that
is not an episode record, or not the suite's, is refused in one line naming the file and
the line."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from shipgym_baselines.cli import main
from shipgym_baselines.errors import RunError
from shipgym_baselines.leaderboard.run import run_leaderboard
from shipgym_baselines.records.episodes import episode_key, read_episodes
from shipgym_baselines.records.runrecord import read_run
from tests.baselines.conftest import SMOKE_CONTROLLERS, copy_folder
from tests.baselines.records.conftest import copy_run, resume_tiny, write_suite


def test_episodes_jsonl_holds_every_episode_with_its_metrics(clean_run: Path) -> None:
    lines = (clean_run / "episodes.jsonl").read_text().splitlines()
    assert len(lines) == 8
    records = [json.loads(line) for line in lines]  # strict JSON, one object per line
    keys = {(r["scenario"], r["controller"], r["seed"]) for r in records}
    assert len(keys) == 8
    for r in records:
        assert {"scenario", "controller", "kind", "seed", "training_seed"} <= set(r)
        assert r["training_seed"] is None  # classical controllers are not trained
        assert {"ace", "ace_L", "t_c", "return", "success", "compute_ms", "steps"} <= set(r)
    # never converged: t_c = inf is kept as "inf" and reads back as inf
    never = [r for r in read_episodes(clean_run) if r["controller"] == "zero_rudder"]
    assert all(r["t_c"] == float("inf") for r in never)


def test_a_learned_episode_records_its_training_seed(tmp_path: Path) -> None:
    """One episode per shipped training seed, each with its own (its meta's) seed."""
    from shipgym_baselines.learned.policy import model_zip
    from shipgym_baselines.registry import training_seeds

    suite = write_suite(tmp_path, scenarios=["nominal"], controllers=["ppo"], seeds=1)
    run_leaderboard(suite, out_dir=tmp_path / "out", workers=1, show_progress=False)
    records = read_episodes(tmp_path / "out")
    seeds = training_seeds("ppo")
    assert [r["training_seed"] for r in records] == seeds and len(seeds) >= 3
    for record, seed in zip(records, seeds, strict=True):
        meta = json.loads((model_zip("ppo", seed).parent / "meta.json").read_text())
        assert record["training_seed"] == meta["seed"] and record["kind"] == "learned"


def test_finding2_a_duplicated_line_counts_once_on_resume_and_report(
    tmp_path: Path, clean_run: Path, capsys
) -> None:
    out = copy_run(clean_run, tmp_path / "out")
    lines = (out / "episodes.jsonl").read_text().splitlines(keepends=True)
    (out / "episodes.jsonl").write_text("".join(lines[:5]) + lines[0] + lines[2])  # 2 repeated
    assert len(read_episodes(out)) == 5
    ran, rows = resume_tiny(tmp_path, out)
    assert len(ran) == 3 and all(r["episodes"] == 2 for r in rows)
    assert main(["report", str(out), "--out", str(tmp_path / "report"), "--json"]) == 0
    assert [r["episodes"] for r in json.loads(capsys.readouterr().out)] == [2, 2, 2, 2]


def test_a_later_line_of_an_episode_its_controller_ended_replaces_it(
    tmp_path: Path, clean_run: Path
) -> None:
    """A retried episode's line (--retry-failed) replaces its controller_error line; a
    line after an episode that ended otherwise is still refused."""
    out = copy_run(clean_run, tmp_path / "out")
    lines = (out / "episodes.jsonl").read_text().splitlines()
    first = json.loads(lines[0])
    failed = {**first, "termination_reason": "controller_error", "error": "ValueError: x"}
    (out / "episodes.jsonl").write_text("\n".join([json.dumps(failed), *lines]) + "\n")
    (record,) = [r for r in read_episodes(out) if episode_key(r) == episode_key(first)]
    assert record["termination_reason"] == first["termination_reason"] and "error" not in record
    assert len(read_episodes(out)) == len(lines)
    (out / "episodes.jsonl").write_text("\n".join([*lines, json.dumps(failed)]) + "\n")
    with pytest.raises(RunError, match=f"line {len(lines) + 1}: episode .* again"):
        read_episodes(out)


@pytest.mark.parametrize(
    ("change", "problem"),
    [
        (
            {"ace": 99.0},
            'episode ["nominal", "pid_los", 10000, null] again, with other values than on line 1',
        ),
        ({"controller": "pid_vf"}, "controller 'pid_vf' is not in the run's suite"),
        ({"scenario": "current_shift"}, "scenario 'current_shift' is not in the run's suite"),
        ({"seed": 77}, "seed 77 is not one of the run's seeds of 'nominal'"),
        ({"training_seed": 3}, "training seed 3 is not one of 'pid_los''s in the run"),
    ],
)
def test_finding2_an_other_duplicate_or_a_foreign_episode_is_an_error_naming_the_line(
    tmp_path: Path, clean_run: Path, capsys, change: dict, problem: str
) -> None:
    out = copy_run(clean_run, tmp_path / "out")
    first = json.loads((out / "episodes.jsonl").read_text().splitlines()[0])
    with open(out / "episodes.jsonl", "a") as fh:
        fh.write(json.dumps({**first, **change}) + "\n")
    expected = f"{out / 'episodes.jsonl'}: line 9: {problem}"
    suite = write_suite(tmp_path)
    args = ["leaderboard", "--suite", suite, "--out", str(out), "--resume", "--no-progress"]
    for argv, command in ((args, "leaderboard"), (["report", str(out)], "report")):
        assert (
            main([*argv, "--out", str(tmp_path / "report")] if command == "report" else argv) == 2
        )
        err = capsys.readouterr().err
        assert err == f"shipgym {command}: error: {expected}\n"
    assert not (tmp_path / "report").exists()


@pytest.mark.parametrize(
    ("line", "problem"),
    [
        (b"[1, 2]", "not an episode record (a JSON list)"),
        (b"{}", "not an episode record (no scenario, controller, kind, seed, training_seed)"),
        (b'{"scenario": "nominal", \xff\xfe}', "not UTF-8 text"),
        (b"{not json", "not JSON"),
        (None, 'metric ace is "fast", not a number'),
        (None, 'seed "1" is not an integer'),
    ],
)
def test_finding2_a_malformed_line_is_one_line_naming_file_and_line(
    tmp_path: Path, clean_run: Path, capsys, line: bytes | None, problem: str
) -> None:
    out = copy_run(clean_run, tmp_path / "out")
    if line is None:  # a record with one bad value
        first = json.loads((out / "episodes.jsonl").read_text().splitlines()[0])
        key = "ace" if "ace" in problem else "seed"
        line = json.dumps({**first, key: "fast" if key == "ace" else "1"}).encode()
    data = (out / "episodes.jsonl").read_bytes().splitlines(keepends=True)
    (out / "episodes.jsonl").write_bytes(b"".join([*data[:3], line + b"\n", *data[3:]]))
    assert main(["report", str(out), "--out", str(tmp_path / "report")]) == 2
    err = capsys.readouterr().err
    assert err == f"shipgym report: error: {out / 'episodes.jsonl'}: line 4: {problem}\n"
    with pytest.raises(RunError, match="line 4"):
        run_leaderboard(write_suite(tmp_path), out_dir=out, show_progress=False, resume=True)


@pytest.mark.parametrize(
    ("value", "problem"),
    [
        ("NaN", 'NaN is not strict JSON (write null or "inf")'),
        ("-Infinity", '-Infinity is not strict JSON (write null or "inf")'),
        ("1e309", "metric ace is Infinity, not a finite number"),
        ("true", "metric ace is true, not a number (only success is true or false)"),
        ("[1, 2]", "metric ace is [1, 2], not a number"),
        ('{"m": 1}', 'metric ace is {"m": 1}, not a number'),
        ("-0.5", "metric ace is -0.5, negative, which this metric never is"),
        ("1e308", "metric ace is 1e+308, beyond the limit of 1e+30 in magnitude"),
    ],
)
def test_episode_values_are_read_back_by_type(
    tmp_path: Path, smoke_run: Path, capsys, value: str, problem: str
) -> None:
    """A metric is a finite number, null, "inf" or "-inf" (``success`` a boolean): any
    other value is refused in one line naming the file and line, by ``report`` and by
    ``--resume``, and the complete run stays complete."""
    out = copy_folder(smoke_run, tmp_path / "out")
    lines = (out / "episodes.jsonl").read_text().splitlines()
    record = json.loads(lines[1])
    text = json.dumps({**record, "ace": 0.5}).replace('"ace": 0.5', f'"ace": {value}')
    lines[1] = text
    (out / "episodes.jsonl").write_text("\n".join(lines) + "\n")
    expected = f"{out / 'episodes.jsonl'}: line 2: {problem}"
    assert main(["report", str(out), "--out", str(tmp_path / "report")]) == 2
    assert capsys.readouterr().err == f"shipgym report: error: {expected}\n"
    settings = {"seeds": 1, "controllers": SMOKE_CONTROLLERS, "show_progress": False}
    with pytest.raises(RunError) as refused:
        run_leaderboard("smoke", out_dir=out, resume=True, **settings)
    assert str(refused.value) == expected
    assert read_run(out)["status"] == "complete"


def test_success_may_be_a_boolean_and_other_metrics_may_not(
    tmp_path: Path, smoke_run: Path
) -> None:
    out = copy_folder(smoke_run, tmp_path / "out")
    records = read_episodes(out)
    assert all(isinstance(r["success"], bool) for r in records)
    lines = (out / "episodes.jsonl").read_text().splitlines()
    lines[0] = json.dumps({**json.loads(lines[0]), "success": 1.0})
    (out / "episodes.jsonl").write_text("\n".join(lines) + "\n")
    with pytest.raises(RunError, match=r"line 1: metric success is 1\.0, not true or false"):
        read_episodes(out)


#: one episode record as a run writes it (a few of its metrics)
RECORD = {
    "scenario": "nominal",
    "controller": "pid_los",
    "kind": "classical",
    "seed": 10000,
    "training_seed": None,
    "ace": 0.5,
    "cost": 120.0,
    "return": -110.0,
    "t_c": "inf",
    "termination_reason": "goal",
    "controller_stats": {"pid_kp": 1.5, "note": "tuned", "converged": True, "gain": None},
}


@pytest.mark.parametrize(
    ("change", "problem"),
    [
        ({"cost": 1e308}, "metric cost is 1e+308, beyond the limit of 1e+30 in magnitude"),
        ({"cost": -3.0}, "metric cost is -3.0, negative, which this metric never is"),
        ({"t_c": "-inf"}, 'metric t_c is "-inf", negative, which this metric never is'),
        ({"return": -1e31}, "metric return is -1e+31, beyond the limit of 1e+30 in magnitude"),
        (
            {"controller_stats": [1, 2]},
            "metric controller_stats is [1, 2], not a controller's figures: it is a list, "
            "not a mapping of names to numbers",
        ),
        (
            {"controller_stats": {"gains": {"kp": 1}}},
            'metric controller_stats is {"gains": {"kp": 1}}, not a controller\'s figures: it '
            "gives 'gains' a dict, not a number, true / false, null or a text of at most 300 "
            "characters",
        ),
    ],
)
def test_an_implausible_value_is_refused_naming_file_line_and_metric(
    tmp_path: Path, change: dict, problem: str
) -> None:
    """Physical ranges: no negative distance, time or cost, nothing beyond 1e30; a
    controller's figures a flat mapping."""
    file = tmp_path / "episodes.jsonl"
    file.write_text(json.dumps(RECORD) + "\n" + json.dumps({**RECORD, **change}) + "\n")
    with pytest.raises(RunError) as refused:
        read_episodes(tmp_path)
    assert str(refused.value) == f"{file}: line 2: {problem}"


def test_a_plausible_record_reads_back_with_its_figures(tmp_path: Path) -> None:
    (tmp_path / "episodes.jsonl").write_text(json.dumps(RECORD) + "\n")
    (record,) = read_episodes(tmp_path)
    assert record["controller_stats"] == RECORD["controller_stats"]
    assert record["t_c"] == float("inf") and record["cost"] == 120.0
