"""``shipgym run SCENARIO CONTROLLER``: one episode, its metrics (text and ``--json``), its
``metrics.json`` and track plot in ``--out``, the same episode as the evaluation loop's."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from shipgym.scenarios.loader import load_scenario
from shipgym.scenarios.trials import trial_scenario
from shipgym_baselines.cli import main
from shipgym_baselines.cli.run import default_out
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET, evaluate
from shipgym_baselines.suite import load_suite

#: wall-clock figures differ between two runs of the same episode
TIMING = ("compute_ms", "compute_ms_max")


def run_json(capsys: pytest.CaptureFixture[str], *argv: str) -> dict:
    assert main(["run", *argv, "--json"]) == 0
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err
    return json.loads(captured.out)


def test_json_is_the_episode_of_the_evaluation_loop(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    doc = run_json(capsys, "rudder_aging", "pid_los", "--seed", "3", "--out", str(out))
    assert (doc["scenario"], doc["controller"], doc["kind"], doc["seed"]) == (
        "rudder_aging",
        "pid_los",
        "classical",
        3,
    )
    # the default suite's trial of seed 3 (its randomize: block), as its leaderboard runs it
    trial = trial_scenario(load_scenario("rudder_aging"), load_suite("default").randomize, 3)
    (reference,) = evaluate("pid_los", trial, [3])
    for key, value in reference.metrics.items():
        if key not in TIMING and isinstance(value, float | int | bool | str):
            # --json writes a non-finite number (e.g. t_c = inf: never settled) as null
            finite = not isinstance(value, float) or math.isfinite(value)
            assert doc[key] == (value if finite else None), key
    assert doc["termination_reason"] == reference.metrics["termination_reason"]
    assert json.loads((out / "metrics.json").read_text()) == doc
    assert sorted(p.name for p in out.iterdir()) == [
        "manifest.txt",
        "metrics.json",
        "rudder_aging.png",
    ]
    assert (out / "rudder_aging.png").stat().st_size > 10_000


def test_text_output_and_the_default_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["run", "nominal", "zero_rudder"]) == 0
    captured = capsys.readouterr()
    rows = dict(line.split(maxsplit=1) for line in captured.out.splitlines())
    assert rows["scenario"] == "nominal" and rows["seed"] == str(EVAL_SEED_OFFSET)
    assert {"ace", "t_c", "return", "success", "termination_reason"} <= set(rows)
    folder = Path("results/run") / f"nominal_zero_rudder_{EVAL_SEED_OFFSET}"
    assert default_out("nominal", "zero_rudder", EVAL_SEED_OFFSET) == folder
    assert (folder / "metrics.json").is_file() and (folder / "nominal.png").is_file()
    assert str(folder) in captured.err


def test_a_second_run_into_the_same_folder_needs_force(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = str(tmp_path / "out")
    first = run_json(capsys, "nominal", "zero_rudder", "--out", out)
    assert main(["run", "nominal", "pid_los", "--out", out]) == 2
    assert "is not empty" in capsys.readouterr().err
    assert json.loads((tmp_path / "out" / "metrics.json").read_text()) == first
    second = run_json(capsys, "nominal", "pid_los", "--out", out, "--force")
    assert second["controller"] == "pid_los"
    assert json.loads((tmp_path / "out" / "metrics.json").read_text()) == second


def test_default_folder_parts_are_file_names() -> None:
    assert default_out("heldout:3", "runs/ppo/model", 7) == Path(
        "results/run/heldout_3_runs_ppo_model_7"
    )


def test_a_scenario_file_runs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    file = Path("configs/scenarios/nominal.yaml").resolve()
    doc = run_json(capsys, str(file), "zero_rudder", "--out", str(tmp_path / "out"))
    assert doc["scenario"] == "nominal"  # as the leaderboard names it: its name:
    assert (tmp_path / "out" / "nominal.png").is_file()


def test_a_controller_that_does_not_apply_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], scratch_registry: None
) -> None:
    from shipgym_baselines.classical.reference import ZeroRudder
    from shipgym_baselines.registry import register_controller

    register_controller("nomoto2_only", lambda: ZeroRudder(), applies_to=("nomoto2",))
    out = tmp_path / "out"
    assert main(["run", "mariner_track", "nomoto2_only", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err == (
        "shipgym run: error: controller 'nomoto2_only' does not apply to the mariner ship of "
        "scenario 'mariner_track'\n"
    )
    assert not out.exists()


@pytest.mark.parametrize(
    ("argv", "named"),
    [(["nosuch", "pid_los"], "unknown scenario 'nosuch'"), (["nominal", "nosuch"], "'nosuch'")],
)
def test_unknown_names_are_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], named: str
) -> None:
    assert main(["run", *argv, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and named in err


def test_a_learned_agent_replays_the_leaderboards_episode_of_a_training_seed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--training-seed K`` runs the policy the leaderboard runs as training seed K (its
    ``Job``), named in the output; without it the first training seed runs."""
    from shipgym_baselines.leaderboard.jobs import Job, run_batch

    argv = ("heldout:0", "ppo", "--seed", "10001", "--suite", "smoke")
    first = run_json(capsys, *argv, "--out", str(tmp_path / "a"))
    assert (first["training_seed"], first["training_seeds"]) == (0, [0, 1, 2])
    doc = run_json(capsys, *argv, "--training-seed", "1", "--out", str(tmp_path / "b"))
    assert list(doc)[:6] == [
        "scenario",
        "controller",
        "kind",
        "seed",
        "training_seed",
        "training_seeds",
    ]
    assert doc["training_seed"] == 1 and doc["cost"] != first["cost"]
    randomize = load_suite("smoke").randomize.model_dump(mode="json")
    (board,) = run_batch(Job("ppo", "heldout:0", (10001,), 1, randomize))
    assert board.training_seed == 1
    assert doc["cost"] == board.metrics["cost"] and doc["ace"] == board.metrics["ace"]
    assert main(["run", *argv, "--training-seed", "1", "--out", str(tmp_path / "c")]) == 0
    captured = capsys.readouterr()
    assert "training_seed            1" in captured.out.splitlines()
    assert captured.err.endswith(
        "(the trial of seed 10001 in suite 'smoke'; training seed 1 of 3 (0, 1, 2))\n"
    )


@pytest.mark.parametrize(
    ("controller", "says"),
    [("ppo", "has the training seeds 0, 1, 2"), ("pid_los", "has no training seeds")],
)
def test_a_training_seed_it_lacks_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], controller: str, says: str
) -> None:
    out = tmp_path / "out"
    argv = ["run", "nominal", controller, "--training-seed", "7", "--out", str(out)]
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        f"shipgym run: error: --training-seed 7: controller {controller!r} {says}\n"
    )
    assert not out.exists()


def test_an_untrained_controller_records_no_training_seed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    doc = run_json(capsys, "nominal", "zero_rudder", "--out", str(tmp_path / "out"))
    assert (doc["training_seed"], doc["training_seeds"]) == (None, [])


def test_force_keeps_a_users_file_and_folder_and_deletes_only_what_a_run_wrote(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``run --force`` follows the leaderboard's manifest rule: beside a user's file and
    folder it is refused before the episode (naming them) and deletes nothing; without
    them it replaces what the earlier run listed in ``manifest.txt``."""
    out = tmp_path / "r"
    argv = ["rudder_aging", "pid_los", "--suite", "smoke", "--out", str(out)]
    run_json(capsys, *argv)
    assert (out / "manifest.txt").read_text().split() == ["metrics.json", "rudder_aging.png"]
    (out / "holiday.png").write_text("x\n")
    (out / "my_plots.png").mkdir()
    (out / "my_plots.png" / "a.png").write_text("mine")
    assert main(["run", *argv, "--force"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "--force: " in err and "holds files no run wrote: holiday.png, my_plots.png, " in err
    assert (out / "holiday.png").read_text() == "x\n"
    assert (out / "my_plots.png" / "a.png").read_text() == "mine"
    (out / "holiday.png").unlink()
    (out / "my_plots.png" / "a.png").unlink()
    (out / "my_plots.png").rmdir()
    (out / "nominal.png").write_text("an earlier run's figure")  # as if listed by a run
    with open(out / "manifest.txt", "a") as manifest:
        manifest.write("nominal.png\n")
    run_json(capsys, *argv, "--force")
    assert sorted(p.name for p in out.iterdir()) == [
        "manifest.txt",
        "metrics.json",
        "rudder_aging.png",
    ]


#: a controller whose second act is too slow for a tiny --act-timeout
SLOW_PLUGIN = """
import time

import numpy as np


class Slow:
    name = "slow"
    kind = "classical"

    def reset(self, context, seed=None):
        self.calls = 0

    def act(self, obs, info):
        self.calls += 1
        if self.calls == 2:
            end = time.process_time() + 0.2  # computes: CPU time over the limit
            while time.process_time() < end:
                pass
        return np.zeros(1)
"""


def test_a_controller_too_slow_for_act_timeout_ends_the_episode(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plugin = tmp_path / "slow.py"
    plugin.write_text(SLOW_PLUGIN)
    out = tmp_path / "out"
    argv = ["rudder_aging", f"{plugin}:Slow", "--act-timeout", "0.05", "--out", str(out)]
    doc = run_json(capsys, *argv)
    assert (doc["termination_reason"], doc["steps"]) == ("controller_timeout", 2)
    assert doc["error"].startswith("the call ran ")
    assert json.loads((out / "metrics.json").read_text()) == doc


def test_a_truncated_compiled_library_is_rebuilt_and_named(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The nomoto2 plant's library in the per-user cache cut to 3,000 bytes (loading it
    kills the process with SIGBUS): the next episode compiles it again, says so in one line
    naming the file, and runs (in child processes: this one never maps the library)."""
    cache = tmp_path / "cache"
    monkeypatch.setenv("SHIPGYM_CACHE_DIR", str(cache))
    monkeypatch.delenv("SHIPGYM_CACHE", raising=False)
    monkeypatch.delenv("SHIPGYM_NO_COMPILE", raising=False)
    monkeypatch.delenv("SHIPGYM_QUIET", raising=False)

    def episode(out: str) -> subprocess.CompletedProcess[str]:
        command = [sys.executable, "-m", "shipgym_baselines.cli", "run", "current_shift"]
        command += ["pid_los", "--out", str(tmp_path / out), "--json"]
        return subprocess.run(command, capture_output=True, text=True, timeout=300)

    assert episode("first").returncode == 0
    (library,) = cache.glob("nomoto2_period_50_*.so")
    size = library.stat().st_size
    os.truncate(library, 3000)
    again = episode("second")
    assert again.returncode == 0, again.stderr
    line = (
        f"shipgym: the cached library {library} is 3000 bytes, {size} recorded: compiling it again"
    )
    assert line in again.stderr.splitlines()
    assert json.loads((tmp_path / "second" / "metrics.json").read_text()) == json.loads(
        again.stdout
    )
    assert library.stat().st_size == size
