"""Bad input on the command line: exit code 2, one stderr line naming the bad thing, no
traceback, and nothing run or written before the check."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from shipgym_baselines.cli import main
from tests.baselines.conftest import error_line

#: a scenario file's text with one ``{line}`` to fill in (nomoto2, 30 s)
SCENARIO = """\
name: bad_input
ship: {{model: nomoto2, params: {{{params}}}}}
initial_state: {{heading_deg: {heading}}}
path: {{waypoints: [[1, 1], [15, 1], [15, 10]]}}
disturbances: {{current: {{speed: 0.05, direction_deg: {direction}}}}}
events: [{{time: {event}, params: {{Tc: 1.0}}}}]
time_limit: {limit}
"""
GOOD = {"params": "Tc: 0.1", "heading": 0.0, "direction": 90.0, "event": 5.0, "limit": 30.0}


def assert_refused(
    capsys: pytest.CaptureFixture[str], argv: list[str], named: list[str], out: Path
) -> None:
    """``shipgym argv`` exits 2 with one error line naming each of ``named``, before it
    makes ``out``."""
    assert main(argv) == 2
    message = error_line(capsys, argv[0])
    for text in named:
        assert text in message
    assert not out.exists()


def scenario_file(tmp_path: Path, **bad: object) -> str:
    file = tmp_path / "scenario.yaml"
    file.write_text(SCENARIO.format(**{**GOOD, **bad}))
    return str(file)


def test_the_good_scenario_file_runs(tmp_path: Path) -> None:
    """The template is valid: each test below breaks exactly one thing."""
    out = tmp_path / "out"
    assert main(["run", scenario_file(tmp_path), "zero_rudder", "--out", str(out)]) == 0
    assert (out / "metrics.json").is_file()


@pytest.mark.parametrize(
    ("bad", "named"),
    [
        ({"event": 31.0}, ["events.0.time", "31.0 s", "time_limit: 30.0 s"]),
        ({"params": "K: -0.5"}, ["ship.params", "K must be > 0", "-0.5"]),
        ({"params": "K: 0"}, ["ship.params", "K must be > 0"]),
        ({"params": "T1: 0"}, ["ship.params", "T1 must be > 0"]),
        ({"limit": ".inf"}, ["time_limit", "finite"]),
        ({"limit": ".nan"}, ["time_limit", "finite"]),
        ({"direction": ".inf"}, ["direction_deg", "finite"]),
        ({"heading": ".nan"}, ["initial_state.heading_deg", "finite"]),
    ],
    ids=[
        "late_event",
        "K<0",
        "K=0",
        "T1=0",
        "inf_limit",
        "nan_limit",
        "inf_current",
        "nan_heading",
    ],
)
def test_a_bad_scenario_number_is_named_before_the_episode(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], bad: dict, named: list[str]
) -> None:
    file = scenario_file(tmp_path, **bad)
    out = tmp_path / "out"
    assert_refused(capsys, ["run", file, "pid_los", "--out", str(out)], [file, *named], out)


def test_scenarios_validate_names_every_problem_and_exits_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = scenario_file(tmp_path, heading=".nan", limit=".inf", params="K: -1")
    assert main(["scenarios", "--validate", bad, "rudder_aging"]) == 2
    captured = capsys.readouterr()
    lines = captured.out.splitlines()
    assert f"{bad}:2: key 'ship.params': Nomoto2Params.K must be > 0 (physical), got -1.0" in lines
    assert f"{bad}:3: key 'initial_state.heading_deg': Input should be a finite number" in lines
    assert f"{bad}:7: key 'time_limit': Input should be a finite number" in lines
    assert "ok rudder_aging" in lines and len(lines) == 4
    assert "Traceback" not in captured.err


def test_scenarios_validate_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import json

    bad = scenario_file(tmp_path, event=40.0)
    assert main(["scenarios", "--validate", "nominal", bad, "--json"]) == 2
    results = json.loads(capsys.readouterr().out)
    assert [(r["file"], r["ok"]) for r in results] == [("nominal", True), (bad, False)]
    assert results[0]["problems"] == []
    (problem,) = results[1]["problems"]
    assert problem.startswith("line 6: key 'events.0.time': event at 40.0 s")
    assert main(["scenarios", "--validate", "nominal", "--json"]) == 0


def test_scenarios_validate_reports_two_problems_of_a_scenario_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = scenario_file(tmp_path, heading=".nan", direction=".inf")
    assert main(["scenarios", "--validate", bad]) == 2
    assert capsys.readouterr().out.splitlines() == [
        f"{bad}:3: key 'initial_state.heading_deg': Input should be a finite number",
        f"{bad}:5: key 'disturbances.current.constant.direction_deg': Input should be a "
        "finite number",
    ]


def bad_suite(tmp_path: Path) -> str:
    """A suite with a bad controller, a bad scenario name and a scenario file with two
    problems (the schema itself passes)."""
    scenario_file(tmp_path, heading=".nan", params="K: -1")
    file = tmp_path / "suite.yaml"
    file.write_text(
        "name: mine\n"
        "scenarios:\n  - nominal\n  - no_such_scenario\n  - scenario.yaml\n"
        "controllers:\n  - pid_los\n  - no_such_controller\n"
        "seeds: 2\n"
    )
    return str(file)


def test_scenarios_validate_checks_a_suite_and_reports_every_problem(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    suite = bad_suite(tmp_path)
    assert main(["scenarios", "--validate", suite, "smoke"]) == 2
    captured = capsys.readouterr()
    lines = captured.out.splitlines()
    scenario = tmp_path / "scenario.yaml"
    assert lines[0].startswith(f"{suite}:4: key 'scenarios.1': unknown scenario 'no_such_scenario'")
    assert lines[1].startswith(f"{suite}:5: key 'scenarios.2': {scenario}:2: key 'ship.params':")
    assert lines[2].startswith(
        f"{suite}:5: key 'scenarios.2': {scenario}:3: key 'initial_state.heading_deg':"
    )
    assert lines[3].startswith(
        f"{suite}:8: key 'controllers.1': unknown controller 'no_such_controller'"
    )
    assert lines[4:] == ["ok smoke"]
    assert captured.err == "shipgym scenarios: 1 of 2 files have problems\n"


def test_scenarios_validate_json_says_which_kind_of_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import json

    smoke = Path(__file__).resolve().parents[2] / "configs/suites/smoke.yaml"
    copy = tmp_path / "smoke_copy.yaml"
    copy.write_text(smoke.read_text())
    assert main(["scenarios", "--validate", str(copy), "nominal", "--json"]) == 0
    results = json.loads(capsys.readouterr().out)
    assert [(r["kind"], r["ok"], r["problems"]) for r in results] == [
        ("suite", True, []),
        ("scenario", True, []),
    ]
    assert main(["scenarios", "--validate", bad_suite(tmp_path), "--json"]) == 2
    (result,) = json.loads(capsys.readouterr().out)
    assert result["kind"] == "suite" and not result["ok"] and len(result["problems"]) == 4
    assert result["problems"][0].startswith("line 4: key 'scenarios.1': unknown scenario")


def test_a_manoeuvre_rudder_beyond_the_limit_is_an_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = ["--out", str(tmp_path / "m")]
    assert main(["manoeuvre", "nomoto2", "turning", "--rudder", "35", *out]) == 2
    assert error_line(capsys, "manoeuvre") == "rudder 35.0° is beyond the nomoto2 rudder limit ±30°"
    assert main(["manoeuvre", "mariner", "zigzag", "--rudder", "-40", *out]) == 2
    assert "beyond the mariner rudder limit ±34.38°" in error_line(capsys, "manoeuvre")
    assert not (tmp_path / "m").exists()


@pytest.mark.parametrize(
    ("argv", "command", "message"),
    [
        (["reproduce", "liu2019", "--seeds", "0"], "reproduce", "--seeds must be ≥ 1, got 0"),
        (["bench", "env", "--repeats", "0"], "bench", "--repeats must be ≥ 1, got 0"),
        (["bench", "training", "--repeats", "-1"], "bench", "--repeats must be ≥ 1, got -1"),
        (["train", "ppo", "--timesteps", "0"], "train", "--timesteps must be ≥ 1, got 0"),
    ],
)
def test_counts_below_one_are_refused(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    argv: list[str],
    command: str,
    message: str,
) -> None:
    out = ["--out", str(tmp_path / "out")] if command != "bench" else []
    assert main([*argv, *out, *(["--no-progress"] if command == "reproduce" else [])]) == 2
    assert error_line(capsys, command) == message
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    "argv",
    [
        ["run", "rudder_aging", "pid_los"],
        ["reproduce", "liu2019", "--no-progress"],
        ["manoeuvre", "nomoto2", "turning"],
    ],
    ids=lambda argv: argv[0],
)
def test_an_unusable_out_is_refused_first(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str]
) -> None:
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    assert main([*argv, "--out", str(blocker)]) == 2
    assert error_line(capsys, argv[0]) == f"--out {blocker} is a file, not a folder"
    assert main([*argv, "--out", str(blocker / "below")]) == 2
    assert f"{blocker} is a file" in error_line(capsys, argv[0])


def test_run_refuses_a_folder_that_is_not_empty(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    assert main(["run", "rudder_aging", "zero_rudder", "--out", str(out)]) == 2
    assert f"--out {out} is not empty" in error_line(capsys, "run")
    assert main(["run", "rudder_aging", "zero_rudder", "--out", str(out), "--force"]) == 2
    assert "notes.txt" in error_line(capsys, "run")  # --force removes only a run's files
    assert (out / "notes.txt").read_text() == "mine"


def test_a_misspelt_hyperparameter_is_named_with_the_valid_ones(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    config = yaml.safe_load(Path("configs/agents/ppo.yaml").read_text())
    config["hyperparams"]["n_step"] = config["hyperparams"].pop("n_steps")
    file = tmp_path / "agent.yaml"
    file.write_text(yaml.safe_dump(config))
    out = tmp_path / "out"
    assert main(["train", "ppo", "--config", str(file), "--out", str(out)]) == 2
    message = error_line(capsys, "train")
    assert f"{file}: key 'hyperparams': unknown hyperparameter 'n_step' of ppo" in message
    assert "(did you mean 'n_steps'?)" in message
    valid = message.split("valid for ppo: ")[1].split(", ")
    assert {"n_steps", "batch_size", "gae_lambda", "clip_range"} <= set(valid)
    assert "seed" not in valid  # set by the trainer
    assert not out.exists()


def test_a_hyperparameter_the_trainer_sets_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    config = yaml.safe_load(Path("configs/agents/sac.yaml").read_text())
    config["hyperparams"]["seed"] = 3
    file = tmp_path / "agent.yaml"
    file.write_text(yaml.safe_dump(config))
    assert main(["train", "sac", "--config", str(file), "--out", str(tmp_path / "o")]) == 2
    assert "'seed' is set by the trainer" in error_line(capsys, "train")


@pytest.mark.parametrize(
    ("text", "named"),
    [
        ("name: s\nscenarios: [rudder_aging\ncontrollers: [pid_los]\n", ["line 3", "malformed"]),
        ("name: s\nscenarios: [rudder_aging]\ncontrollers: [pid_los]\nseedz: 3\n", ["'seedz'"]),
        ("name: s\nscenarios: [rudder_aging]\n", ["'controllers'", "required"]),
        ("name: s\nscenarios: [rudder_aging]\ncontrollers: []\n", ["'controllers'", "at least 1"]),
    ],
    ids=["malformed", "unknown_key", "no_controllers", "empty_controllers"],
)
def test_a_bad_suite_is_named_with_file_and_key(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, named: list[str]
) -> None:
    suite = tmp_path / "suite.yaml"
    suite.write_text(text)
    out = tmp_path / "out"
    command = ["leaderboard", "--suite", str(suite), "--out", str(out), "--no-progress"]
    assert_refused(capsys, command, [str(suite), *named], out)


def test_scenarios_validate_suggests_the_key_an_unknown_one_is_close_to(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An unknown key names the close field of its own model (top level and nested) in a
    scenario file; a key close to none gets no suggestion."""
    file = tmp_path / "typos.yaml"
    file.write_text(
        SCENARIO.format(**GOOD).replace("[15, 10]]}", "[15, 10]], acceptance_radius_l: 2}")
        + "time_limt: 5\nwhatever: 1\n"
    )
    assert main(["scenarios", "--validate", str(file)]) == 2
    assert capsys.readouterr().out.splitlines() == [
        f"{file}:4: key 'path.acceptance_radius_l': Extra inputs are not permitted; did you "
        "mean 'acceptance_radius_L'?",
        f"{file}:8: key 'time_limt': Extra inputs are not permitted; did you mean 'time_limit'?",
        f"{file}:9: key 'whatever': Extra inputs are not permitted",
    ]


def test_a_suites_problems_are_in_line_order_with_suggestions(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The schema's problem (found first) at the end of the file is printed last."""
    file = tmp_path / "suite.yaml"
    file.write_text(
        "name: mine\nscenarios:\n  - nominal\n  - no_such_scenario\ncontrollers: [pid_los]\n"
        "randomise:\n  start_offset_L: 0.1\n"
    )
    assert main(["scenarios", "--validate", str(file)]) == 2
    lines = capsys.readouterr().out.splitlines()
    assert [line.split(": key")[0] for line in lines] == [f"{file}:4", f"{file}:6"]
    assert lines[1] == (
        f"{file}:6: key 'randomise': Extra inputs are not permitted; did you mean 'randomize'?"
    )
