"""Run records (docs/records.md): run.json, episodes.jsonl, refusal of a used --out, --force,
--resume, Ctrl-C; the train refusal."""

from __future__ import annotations

import datetime
import errno
import io
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

import shipgym_baselines.leaderboard.jobs
from shipgym_baselines.cli import main
from shipgym_baselines.errors import RunError, RunFailed
from shipgym_baselines.jsonout import dumps
from shipgym_baselines.leaderboard import run_leaderboard
from shipgym_baselines.records.manifest import snapshot
from shipgym_baselines.records.runs import (
    RunInterrupted,
    check_out_dir,
    clear_outputs,
    episode_key,
    read_episodes,
    read_run,
)
from tests.baselines.conftest import SMOKE_CONTROLLERS, copy_folder

ROOT = Path(__file__).resolve().parents[3]
#: 2 scenarios × 2 controllers × 2 seeds: 8 quick episodes
TINY = {
    "name": "tiny",
    "scenarios": ["nominal", "rudder_aging"],
    "controllers": ["pid_los", "zero_rudder"],
    "seeds": 2,
}
TIMING = ("compute_ms", "compute_ms_std", "compute_ms_max")


def write_suite(folder: Path, **changes: object) -> str:
    file = folder / "tiny.yaml"
    file.write_text(yaml.safe_dump({**TINY, **changes}))
    return str(file)


def untimed(rows: list[dict]) -> list[dict]:
    """Rows as leaderboard.json holds them, wall-clock timings aside."""
    return [
        {k: v for k, v in r.items() if not k.startswith(TIMING)} for r in json.loads(dumps(rows))
    ]


@pytest.fixture(scope="module")
def clean_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The tiny suite run once, uninterrupted."""
    root = tmp_path_factory.mktemp("clean")
    run_leaderboard(write_suite(root), out_dir=root / "out", workers=1, show_progress=False)
    return root / "out"


def test_run_json_records_command_suite_versions_times_and_status(clean_run: Path) -> None:
    record = read_run(clean_run)
    assert isinstance(record["command"], list) and record["command"]
    suite = record["suite"]
    assert suite["seeds"] == [10_000, 10_001]
    assert [c["name"] for c in suite["controllers"]] == ["pid_los", "zero_rudder"]
    assert list(suite["scenarios"]) == ["nominal", "rudder_aging"]
    aging = suite["scenarios"]["rudder_aging"]  # the scenario's resolved settings
    assert aging["ship"]["model"] == "nomoto2" and aging["events"]
    versions = record["versions"]
    assert {"python", "numpy", "scipy", "gymnasium", "casadi", "shipgym"} <= set(versions)
    assert versions["stable-baselines3"] and versions["torch"]  # installed here
    commit = record["git_commit"]
    assert commit is None or (len(commit) == 40 and int(commit, 16) >= 0)
    start = datetime.datetime.fromisoformat(record["start_time"])
    end = datetime.datetime.fromisoformat(record["end_time"])
    assert start.utcoffset() == datetime.timedelta(0) and start <= end
    assert record["status"] == "complete"
    assert record["jobs"] == record["episodes"] == 8
    # the run's own wall-clock and CPU seconds (tables and figures included)
    assert 0 < record["wall_s"] <= (end - start).total_seconds() + 1.0
    assert record["cpu_s"] > 0


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


def test_each_episode_is_on_disk_when_it_ends(tmp_path: Path) -> None:
    seen: list[int] = []

    def count_lines(result: object) -> None:
        seen.append(len(read_episodes(tmp_path / "out")))

    run_leaderboard(
        write_suite(tmp_path),
        out_dir=tmp_path / "out",
        workers=2,
        show_progress=False,
        on_episode=count_lines,
    )
    assert seen == list(range(1, 9))


def test_a_used_out_is_refused_before_any_episode(tmp_path: Path, capsys) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    start = time.perf_counter()
    with pytest.raises(RunError, match=r"not empty.*--resume.*--force"):
        run_leaderboard(write_suite(tmp_path), out_dir=out, show_progress=False)
    assert time.perf_counter() - start < 1.0
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]
    code = main(["leaderboard", "--suite", write_suite(tmp_path), "--out", str(out)])
    assert code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"--out {out} is not empty" in err


def test_an_unusable_out_is_refused_first(tmp_path: Path, capsys) -> None:
    file = tmp_path / "file"
    file.write_text("")
    for out, problem in ((file, "is a file"), (file / "below", f"{file} is a file")):
        # checked before the (unknown) suite is even read
        assert main(["leaderboard", "--suite", "no_such_suite", "--out", str(out)]) == 2
        assert problem in capsys.readouterr().err
    if os.geteuid() != 0:  # root writes anywhere
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        with pytest.raises(RunError, match="not writable"):
            check_out_dir(locked / "out")


def test_finding4_force_deletes_only_what_the_manifest_lists(
    tmp_path: Path, clean_run: Path
) -> None:
    """A user's files that look like outputs (``*.png``, a directory named ``*.png``, their
    own file in ``trajectories/``, a ``report.json``) make --force refuse, deleting
    nothing; without them --force deletes exactly what the earlier run listed."""
    out, suite = tmp_path / "out", write_suite(tmp_path)
    run_leaderboard(suite, seeds=1, out_dir=out, workers=1, show_progress=False)
    listed = set((out / "manifest.txt").read_text().splitlines())
    assert {"run.json", "episodes.jsonl", "leaderboard.md", "scenario_nominal.png"} <= listed
    assert snapshot(out) <= listed | {"manifest.txt"}  # every path the run wrote is listed
    mine = ["my_plot.png", "figures.png/keep.txt", "trajectories/mine.npz", "report.json"]
    for name in mine:
        (out / name).parent.mkdir(exist_ok=True)
        (out / name).write_text("mine")
    before = snapshot(out)
    with pytest.raises(RunError, match=r"--force: .* holds files no run wrote: figures\.png, "):
        run_leaderboard(suite, out_dir=out, workers=1, show_progress=False, force=True)
    assert snapshot(out) == before  # nothing deleted
    for name in mine:
        (out / name).unlink()
    (out / "figures.png").rmdir()
    rows = run_leaderboard(suite, out_dir=out, workers=1, show_progress=False, force=True)
    assert len(read_episodes(out)) == 8 and read_run(out)["status"] == "complete"
    assert untimed(rows) == untimed(json.loads((clean_run / "leaderboard.json").read_text()))
    # a folder written by no run of this version (no manifest) is refused, not guessed at
    (out / "manifest.txt").unlink()
    with pytest.raises(RunError, match=r"no manifest\.txt"):
        run_leaderboard(suite, out_dir=out, show_progress=False, force=True)
    assert (out / "run.json").is_file()


def test_finding4_report_force_deletes_only_its_listed_outputs(
    tmp_path: Path, clean_run: Path, capsys
) -> None:
    report = tmp_path / "report"
    assert main(["report", str(clean_run), "--out", str(report), "--json"]) == 0
    assert "report.json" in (report / "manifest.txt").read_text().splitlines()
    (report / "trajectories").mkdir()
    (report / "trajectories" / "mine.npz").write_text("mine")
    assert main(["report", str(clean_run), "--out", str(report), "--force", "--json"]) == 2
    assert "trajectories/mine.npz" in capsys.readouterr().err
    assert (report / "leaderboard.json").is_file()
    (report / "trajectories" / "mine.npz").unlink()
    assert main(["report", str(clean_run), "--out", str(report), "--force", "--json"]) == 2
    assert "holds files no run wrote: trajectories;" in capsys.readouterr().err  # their folder
    (report / "trajectories").rmdir()
    assert main(["report", str(clean_run), "--out", str(report), "--force", "--json"]) == 0


def test_an_interrupted_run_resumes_to_the_clean_table(tmp_path: Path, clean_run: Path) -> None:
    suite, out = write_suite(tmp_path), tmp_path / "out"

    def stop_after_three(result: object, seen: list[int] = []) -> None:  # noqa: B006
        seen.append(1)
        if len(seen) == 3:
            raise KeyboardInterrupt

    with pytest.raises(RunInterrupted) as interrupted:
        run_leaderboard(
            suite, out_dir=out, workers=2, show_progress=False, on_episode=stop_after_three
        )
    assert str(interrupted.value) == (
        f"3 of 8 episodes kept in {out / 'episodes.jsonl'}; resume with --resume"
    )
    assert read_run(out)["status"] == "interrupted" and len(read_episodes(out)) == 3
    assert not (out / "leaderboard.json").exists()
    ran: list[object] = []
    rows = run_leaderboard(
        suite, out_dir=out, workers=1, show_progress=False, resume=True, on_episode=ran.append
    )
    assert len(ran) == 5  # only the missing jobs
    record = read_run(out)
    assert record["status"] == "complete" and record["episodes"] == 8
    assert len(record["resumed"]) == 1
    clean = json.loads((clean_run / "leaderboard.json").read_text())
    assert untimed(json.loads((out / "leaderboard.json").read_text())) == untimed(clean)
    assert untimed(rows) == untimed(clean)
    assert sorted(p.name for p in out.glob("*.png")) == sorted(
        p.name for p in clean_run.glob("*.png")
    )


def test_resume_with_a_changed_suite_is_refused(tmp_path: Path, clean_run: Path) -> None:
    with pytest.raises(RunError, match=r"suite differs.*seeds: 10001 only in the run"):
        run_leaderboard(
            write_suite(tmp_path), seeds=1, out_dir=clean_run, show_progress=False, resume=True
        )
    # a list of controllers is told by their names, never cut short
    with pytest.raises(RunError, match=r"controllers: .* only in the run; random only now") as e:
        run_leaderboard(
            write_suite(tmp_path),
            out_dir=clean_run,
            show_progress=False,
            resume=True,
            controllers=["random"],
        )
    assert "…" not in str(e.value)
    changed = write_suite(tmp_path, scenarios=["nominal", "current_shift"])
    with pytest.raises(RunError, match=r"scenarios\.rudder_aging only in the run"):
        run_leaderboard(changed, out_dir=clean_run, show_progress=False, resume=True)
    with pytest.raises(RunError, match="no run to resume"):
        run_leaderboard(changed, out_dir=tmp_path / "new", show_progress=False, resume=True)
    assert read_run(clean_run)["status"] == "complete"


def test_a_killed_run_keeps_its_episodes_and_resumes(tmp_path: Path, clean_run: Path) -> None:
    """A line cut short by a kill is dropped on resume; the rest are kept."""
    out = tmp_path / "out"
    out.mkdir()
    lines = (clean_run / "episodes.jsonl").read_text().splitlines(keepends=True)
    (out / "episodes.jsonl").write_text("".join(lines[:4]) + lines[4][:30])
    (out / "run.json").write_text((clean_run / "run.json").read_text())
    assert len(read_episodes(out)) == 4
    ran: list[object] = []
    run_leaderboard(
        write_suite(tmp_path),
        out_dir=out,
        workers=1,
        show_progress=False,
        resume=True,
        on_episode=ran.append,
    )
    assert len(ran) == 4 and len(read_episodes(out)) == 8


def test_cli_ctrl_c_says_what_was_kept(tmp_path: Path, monkeypatch, capsys) -> None:
    calls: list[object] = []
    real = shipgym_baselines.leaderboard.jobs.run_batch  # a controller's 2 seeds in lockstep

    def third_is_interrupted(job: tuple) -> object:
        calls.append(job)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(job)

    monkeypatch.setattr(shipgym_baselines.leaderboard.jobs, "run_batch", third_is_interrupted)
    out = tmp_path / "out"
    args = ["leaderboard", "--suite", write_suite(tmp_path), "--out", str(out), "--workers", "1"]
    args.append("--no-references")  # the suite's two controllers only
    assert main([*args, "--no-progress"]) == 130
    assert capsys.readouterr().err == (
        f"shipgym leaderboard: interrupted: 4 of 8 episodes kept in {out / 'episodes.jsonl'}; "
        "resume with --resume\n"
    )
    assert read_run(out)["command"] == ["shipgym", *args, "--no-progress"]


def test_plots_stay_in_the_run_folder(tmp_path: Path) -> None:
    """A scenario given by its YAML path is plotted as ``scenario_<name>.png`` (its
    ``name:``) inside --out, never beside the scenario file."""
    cases = tmp_path / "cases"
    cases.mkdir()
    nominal = (ROOT / "configs/scenarios/nominal.yaml").read_text()
    (cases / "case_v1.yaml").write_text(nominal.replace("name: nominal", "name: my_case"))
    suite = write_suite(tmp_path, scenarios=["cases/case_v1.yaml"], controllers=["pid_los"])
    out = tmp_path / "out"
    run_leaderboard(suite, seeds=1, out_dir=out, workers=1, show_progress=False)
    assert (out / "scenario_my_case.png").is_file()
    assert sorted(p.name for p in cases.iterdir()) == ["case_v1.yaml"]


def test_a_failing_run_is_recorded_as_failed(tmp_path: Path, monkeypatch) -> None:
    calls: list[object] = []
    real = shipgym_baselines.leaderboard.jobs.run_batch  # a controller's 2 seeds in lockstep

    def second_fails(job: tuple) -> object:
        calls.append(job)
        if len(calls) == 2:
            raise RuntimeError("a bug in a controller")
        return real(job)

    monkeypatch.setattr(shipgym_baselines.leaderboard.jobs, "run_batch", second_fails)
    out = tmp_path / "out"
    with pytest.raises(RuntimeError, match="a bug"):  # a bug keeps its traceback
        run_leaderboard(write_suite(tmp_path), out_dir=out, workers=1, show_progress=False)
    record = read_run(out)
    assert record["status"] == "failed" and record["error"] == "RuntimeError: a bug in a controller"
    assert record["episodes"] == len(read_episodes(out)) == 2


def test_sigint_stops_the_workers_without_tracebacks(tmp_path: Path) -> None:
    """A real Ctrl-C (SIGINT to the process group, as a terminal sends it) with 2 workers."""
    out = tmp_path / "out"
    command = [sys.executable, "-m", "shipgym_baselines.cli", "leaderboard", "--suite", "smoke"]
    command += ["--seeds", "1", "--out", str(out), "--workers", "2", "--no-progress"]
    process = subprocess.Popen(
        command,
        cwd=ROOT,
        stderr=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        text=True,
        start_new_session=True,
        # a terminal's foreground job: SIGINT at its default even when pytest runs as a
        # background job of a non-interactive shell, which ignores SIGINT for its children
        # (an ignored SIGINT is inherited, and the run then rightly finishes)
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    deadline = time.monotonic() + 120
    while not ((out / "run.json").is_file() and read_episodes(out)):  # an episode ended
        assert process.poll() is None and time.monotonic() < deadline
        time.sleep(0.05)
    os.killpg(process.pid, signal.SIGINT)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130
    assert "Traceback" not in err and err.count("\n") == 1, err
    assert err.startswith("shipgym leaderboard: interrupted: ") and "resume with --resume" in err
    record = read_run(out)
    assert record["status"] == "interrupted" and record["episodes"] == len(read_episodes(out))


def test_train_refuses_a_used_agent_folder(tmp_path: Path, capsys) -> None:
    from shipgym_baselines.learned.train import TRAINING_OUTPUTS, train

    out = tmp_path / "agent"
    out.mkdir()
    (out / "model.zip").write_text("an earlier run")
    assert main(["train", "ppo", "--out", str(out), "--timesteps", "64", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert f"--out {out} is not empty" in err and "agent folder of ppo" in err
    with pytest.raises(RunError, match="not empty"):
        train("ppo", out_dir=out, n_timesteps=64, progress=False)
    assert sorted(p.name for p in out.iterdir()) == ["model.zip"]
    # --force clears only what training writes
    (out / "checkpoints").mkdir()
    clear_outputs(out, TRAINING_OUTPUTS)
    assert not any(out.iterdir())
    (out / "notes.txt").write_text("mine")
    with pytest.raises(RunError, match=r"notes\.txt"):
        train("ppo", out_dir=out, n_timesteps=64, progress=False, force=True)


# --- episodes.jsonl is a set keyed by the episode key --------------------------------------


def copy_run(source: Path, target: Path) -> Path:
    """A copy of a finished run folder (its record and episodes)."""
    target.mkdir()
    for name in ("run.json", "episodes.jsonl"):
        (target / name).write_bytes((source / name).read_bytes())
    return target


def test_finding2_a_duplicated_line_counts_once_on_resume_and_report(
    tmp_path: Path, clean_run: Path, capsys
) -> None:
    out = copy_run(clean_run, tmp_path / "out")
    lines = (out / "episodes.jsonl").read_text().splitlines(keepends=True)
    (out / "episodes.jsonl").write_text("".join(lines[:5]) + lines[0] + lines[2])  # 2 repeated
    assert len(read_episodes(out)) == 5
    ran: list[object] = []
    rows = run_leaderboard(
        write_suite(tmp_path),
        out_dir=out,
        workers=1,
        show_progress=False,
        resume=True,
        on_episode=ran.append,
    )
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
    ("text", "problem"),
    [
        (b'{"suite": {"seeds": [1]', "line 1: not JSON (Expecting ',' delimiter)"),
        (b"[1, 2]", "not a run record (no 'suite')"),
        (b'{"suite": {}}', "not a run record (key 'suite.seeds' is null, not a list of integers)"),
        (b'{\n"suite": "\xff"}', "line 2: not UTF-8 text"),
    ],
)
def test_finding2_a_malformed_run_json_is_one_line_naming_the_file(
    tmp_path: Path, clean_run: Path, capsys, text: bytes, problem: str
) -> None:
    out = copy_run(clean_run, tmp_path / "out")
    (out / "run.json").write_bytes(text)
    assert main(["report", str(out), "--out", str(tmp_path / "report")]) == 2
    assert capsys.readouterr().err == f"shipgym report: error: {out / 'run.json'}: {problem}\n"
    suite = write_suite(tmp_path)
    args = ["leaderboard", "--suite", suite, "--out", str(out), "--resume", "--no-progress"]
    assert main(args) == 2
    assert capsys.readouterr().err == f"shipgym leaderboard: error: {out / 'run.json'}: {problem}\n"


class _FillsUp(io.FileIO):
    """A file on a disk that fills up: the first write stores half its bytes, then none."""

    full = False

    def write(self, data: bytes) -> int:  # type: ignore[override]
        if self.full:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        self.full = True
        return super().write(bytes(data)[: len(data) // 2])


def test_finding6_a_line_the_disk_cannot_hold_is_cut_off(tmp_path: Path, clean_run: Path) -> None:
    """A full disk cuts an episode's line short: it is cut off again, so no partial line
    stays between whole ones once there is room again."""
    from shipgym_baselines.records.runs import RunLog, episode_result

    records = read_episodes(clean_run)
    log = RunLog.open(
        tmp_path / "out", command=["test"], suite=read_run(clean_run)["suite"], jobs=8
    )
    with pytest.raises(RunFailed, match=r"no room to write .*episodes\.jsonl"):
        with log.recording():
            log.append(episode_result(records[0], clean_run))
            full = _FillsUp(log.episodes_file, "ab")
            log._file, spare = full, log._file
            spare.close()
            log.append(episode_result(records[1], clean_run))
    assert len((log.episodes_file).read_text().splitlines()) == 1
    assert read_run(tmp_path / "out")["status"] == "failed"
    ran: list[object] = []
    run_leaderboard(
        write_suite(tmp_path),
        out_dir=tmp_path / "out",
        workers=1,
        show_progress=False,
        resume=True,
        on_episode=ran.append,
    )
    assert len(ran) == 7 and len(read_episodes(tmp_path / "out")) == 8


@pytest.mark.parametrize(
    "name", ["leaderboard.md", "aggregate.json", ".run.json.tmp", ".manifest.txt.tmp"]
)
def test_resume_refuses_a_link_planted_as_an_output_and_leaves_its_target(
    tmp_path: Path, smoke_run: Path, capsys, name: str
) -> None:
    notes = tmp_path / "notes.txt"
    notes.write_text("my notes\n")
    out = copy_folder(smoke_run, tmp_path / "out")
    (out / name).unlink(missing_ok=True)
    (out / name).symlink_to(notes)
    argv = ["leaderboard", "--suite", "smoke", "--seeds", "1", "--out", str(out), "--resume"]
    assert main([*argv, "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"shipgym leaderboard: error: {out / name} is a symbolic link to {notes}: a run "
        "writes no file through it; remove it or choose another --out\n"
    )
    assert notes.read_text() == "my notes\n" and read_run(out)["status"] == "complete"


def test_a_link_planted_while_the_tables_are_written_is_refused(
    tmp_path: Path, smoke_run: Path, monkeypatch
) -> None:
    """A link that appears during the run, as a table the run is about to write: that
    write is refused (the run fails in one line) and the link's target is unchanged."""
    from shipgym_baselines.leaderboard import figures

    notes = tmp_path / "notes.txt"
    notes.write_text("my notes\n")
    out = copy_folder(smoke_run, tmp_path / "out")
    draw = figures.plot_scenarios

    def plant_then_draw(folder: Path, *args: object, **kwargs: object) -> list[Path]:
        (folder / "aggregate.json").unlink(missing_ok=True)
        (folder / "aggregate.json").symlink_to(notes)
        return draw(folder, *args, **kwargs)

    monkeypatch.setattr(figures, "plot_scenarios", plant_then_draw)
    with pytest.raises(RunError, match=r"aggregate\.json is a symbolic link"):
        run_leaderboard(
            "smoke",
            seeds=1,
            out_dir=out,
            controllers=SMOKE_CONTROLLERS,
            show_progress=False,
            resume=True,
        )
    assert notes.read_text() == "my notes\n" and read_run(out)["status"] == "failed"


@pytest.mark.parametrize(
    ("value", "problem"),
    [
        ("NaN", 'NaN is not strict JSON (write null or "inf")'),
        ("-Infinity", '-Infinity is not strict JSON (write null or "inf")'),
        ("1e309", "metric ace is Infinity, not a finite number"),
        ("true", "metric ace is true, not a number (only success is true or false)"),
        ("[1, 2]", "metric ace is [1, 2], not a number"),
        ('{"m": 1}', 'metric ace is {"m": 1}, not a number'),
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
