"""The ``shipgym`` console script: subcommands, one-line errors, ``--json``."""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from shipgym.scenarios.loader import ScenarioError
from shipgym_baselines.cli import build_parser, main
from shipgym_baselines.errors import ControllerError
from tests.baselines.conftest import error_line


def _subcommands() -> list[str]:
    (action,) = (a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return list(action.choices)


def test_every_subcommand_is_listed() -> None:
    assert _subcommands() == [
        "leaderboard",
        "reproduce",
        "train",
        "tune",
        "evaluate",
        "run",
        "report",
        "summary",
        "manoeuvre",
        "scenarios",
        "bench",
        "references",
    ]


@pytest.mark.parametrize("command", _subcommands())
def test_help_of_every_subcommand(command: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main([command, "--help"])
    assert exit_info.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith(f"usage: shipgym {command}")
    assert "--json" in out


def test_choices_come_from_the_registries() -> None:
    from shipgym.models import MODELS
    from shipgym_baselines.cli.bench import BENCHES
    from shipgym_baselines.cli.manoeuvre import MANOEUVRES
    from shipgym_baselines.reproduce import PAPERS

    parser = build_parser()
    assert parser.parse_args(["reproduce", "xu2021"]).paper == "xu2021"
    for paper in PAPERS:
        assert parser.parse_args(["reproduce", paper]).paper == paper
    for target in BENCHES:
        assert parser.parse_args(["bench", target]).target == target
    for ship in MODELS:
        for kind in MANOEUVRES:
            args = parser.parse_args(["manoeuvre", ship, kind])
            assert (args.ship, args.kind) == (ship, kind)


def test_python_dash_m_runs_the_cli() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "shipgym_baselines.cli", "scenarios", "--json"],
        capture_output=True,
        text=True,
        check=True,
    )
    assert "rudder_aging" in json.loads(done.stdout)


def test_cli_scenarios_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["scenarios", "--json"]) == 0
    names = json.loads(capsys.readouterr().out)
    assert {"nominal", "rudder_aging", "current_shift", "maneuverability_change"} <= set(names)


def test_unknown_controller_is_one_line_and_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["evaluate", "nope", "--suite", "smoke", "--no-progress"]) == 2
    message = error_line(capsys, "evaluate")
    assert message.startswith("unknown controller 'nope'; valid:") and "pid_los" in message


def test_unknown_scenario_is_one_line_and_exit_2(
    tmp_path, capsys: pytest.CaptureFixture[str]
) -> None:
    smoke = yaml.safe_load(Path("configs/suites/smoke.yaml").read_text())
    smoke.update(scenarios=["no_such_scenario"], heldout_scenarios=0, controllers=["zero_rudder"])
    suite = tmp_path / "suite.yaml"
    suite.write_text(yaml.safe_dump(smoke))
    out = str(tmp_path / "out")  # an --out holding the suite file would be refused first
    code = main(["leaderboard", "--suite", str(suite), "--out", out, "--no-progress"])
    assert code == 2
    assert "no_such_scenario" in error_line(capsys, "leaderboard")


def test_cli_bad_suite_is_a_clear_error(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["leaderboard", "--suite", "nope", "--no-progress"]) == 2
    assert "valid: default" in error_line(capsys, "leaderboard")


def test_bad_option_values_are_one_line_errors(
    tmp_path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = ["--out", str(tmp_path)]
    assert main(["reproduce", "liu2019", "--seeds", "0", "--no-progress", *out]) == 2
    assert error_line(capsys, "reproduce") == "--seeds must be ≥ 1, got 0"
    assert main(["manoeuvre", "nomoto2", "zigzag", "--rudder", "-5", *out]) == 2
    assert "must be > 0" in error_line(capsys, "manoeuvre")
    assert main(["manoeuvre", "nomoto2", "zigzag", "--variant", "nope", *out]) == 2
    assert "unknown variant" in error_line(capsys, "manoeuvre")
    assert main(["train", "all", "--config", "x.yaml"]) == 2
    assert error_line(capsys, "train") == "train all: --config applies to one agent"


def test_a_project_error_from_deep_inside_is_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import shipgym.scenarios.loader

    def broken() -> list[str]:
        raise ScenarioError("configs/scenarios: unreadable")

    monkeypatch.setattr(shipgym.scenarios.loader, "list_scenarios", broken)
    assert main(["scenarios"]) == 2
    assert error_line(capsys, "scenarios") == "configs/scenarios: unreadable"


def test_a_bug_keeps_its_traceback(monkeypatch: pytest.MonkeyPatch) -> None:
    """Only project errors (bad input) become one line: anything else propagates."""
    import shipgym.scenarios.loader

    def buggy() -> list[str]:
        raise TypeError("a real bug")

    monkeypatch.setattr(shipgym.scenarios.loader, "list_scenarios", buggy)
    with pytest.raises(TypeError, match="a real bug"):
        main(["scenarios"])
    # a built-in KeyError that is not a ControllerError is a bug too
    monkeypatch.setattr(shipgym.scenarios.loader, "list_scenarios", lambda: {}["missing"])
    with pytest.raises(KeyError):
        main(["scenarios"])


def test_ctrl_c_is_one_line_and_exit_130(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import shipgym.scenarios.loader

    def interrupted() -> list[str]:
        raise KeyboardInterrupt

    monkeypatch.setattr(shipgym.scenarios.loader, "list_scenarios", interrupted)
    assert main(["scenarios"]) == 130
    assert capsys.readouterr().err == "shipgym scenarios: interrupted\n"


def test_controller_error_reads_as_its_message() -> None:
    """A KeyError's str() is the repr of its key; the controller error prints its message."""
    error = ControllerError("unknown controller 'x'")
    assert isinstance(error, KeyError) and str(error) == "unknown controller 'x'"


def test_cli_leaderboard_json_is_one_document(tmp_path, capsys) -> None:
    code = main(
        [
            "leaderboard",
            "--suite",
            "smoke",
            "--seeds",
            "1",
            "--out",
            str(tmp_path),
            "--json",
            "--no-progress",
        ]
    )
    assert code == 0
    rows = json.loads(capsys.readouterr().out)
    assert isinstance(rows, list) and rows
    ran = [r for r in rows if r["applies"]]
    assert all(isinstance(r["ace"], float) and math.isfinite(r["ace"]) for r in ran)


def test_cli_bench_env_json(capsys) -> None:
    assert main(["bench", "env", "--repeats", "1", "--json"]) == 0
    figures = json.loads(capsys.readouterr().out)
    assert figures["single_env_steps_per_s"] > 0
    assert figures["batched_env_steps_per_s"] > 0


def test_cli_bench_identification_json(capsys) -> None:
    """``--json``: one JSON object; per case and identifier, errors, convergence time and µs."""
    assert main(["bench", "identification", "--json"]) == 0
    figures = json.loads(capsys.readouterr().out)
    assert {"rudder_aging", "current_shift", "maneuverability_change"} <= set(figures)
    aging = figures["rudder_aging"]
    for name in ("lambda_lssvm", "weighted_lssvm"):
        assert aging[name]["update_us_median"] > 0
        assert aging[name]["final_relative_error"]["Tc"] < 0.05
    assert aging["lambda_lssvm"]["t_within_10pct"] <= aging["weighted_lssvm"]["t_within_10pct"]


def test_cli_bench_nmpc_json(capsys, monkeypatch) -> None:
    """The nomoto2 figures, and per ship each family member's (here two, 40 steps: CI time)."""
    from shipgym_baselines.studies import benchmarks

    monkeypatch.setattr(benchmarks, "NMPC_FAMILY", ("nmpc", "nmpc_lambda_lssvm_svf"))
    monkeypatch.setattr(benchmarks, "PER_SHIP_MAX_STEPS", 40)
    monkeypatch.setattr(benchmarks, "ORACLE_MAX_STEPS", 30)  # past the jumps (12 s)
    monkeypatch.setattr(benchmarks, "ESTIMATING", ("nmpc_ekf",))
    monkeypatch.setattr(
        benchmarks,
        "ESTIMATING_SCENARIOS",
        {"nomoto2": ("rudder_aging",), "kvlcc2": ("kvlcc2_nominal",)},
    )
    assert main(["bench", "nmpc", "--json"]) == 0
    figures = json.loads(capsys.readouterr().out)
    assert 0 < figures["nmpc_median_ms"] <= figures["nmpc_p99_ms"]
    assert figures["failures"] == 0 and figures["solves"] > 100
    assert set(figures["per_ship"]) == {"nomoto2", "esso_osaka", "mariner", "blanke"}
    for ship, entry in figures["per_ship"].items():
        for name in ("nmpc", "nmpc_lambda_lssvm_svf"):
            assert 0 < entry[f"{name}_median_ms"] <= entry[f"{name}_p99_ms"], ship
            assert 0 < entry[f"{name}_cpu_median_ms"] <= entry[f"{name}_cpu_p99_ms"], ship
        assert entry["nmpc_solves"] == (3 * 40 if ship == "nomoto2" else 40)
        assert entry["family_p99_ms"] == max(
            entry["nmpc_p99_ms"], entry["nmpc_lambda_lssvm_svf_p99_ms"]
        )
        # the privileged oracle, through its channel as in a run
        assert 0 < entry["oracle_median_ms"] <= entry["oracle_p99_ms"], ship
        assert entry["oracle_solves"] == (3 * 30 if ship == "nomoto2" else 30)
    # the estimating controllers' whole steps (estimate and solve), KVLCC2 included
    assert set(figures["estimating_per_ship"]) == {"nomoto2", "kvlcc2"}
    for entry in figures["estimating_per_ship"].values():
        assert 0 < entry["nmpc_ekf_step_cpu_median_ms"] <= entry["nmpc_ekf_step_cpu_p99_ms"]
        assert entry["nmpc_ekf_steps"] == 30


def test_cli_reproduce_liu2019_json(tmp_path, capsys) -> None:
    """The rows' shape: case, controller, metric, ours, paper; all three cases and controllers."""
    assert main(["reproduce", "liu2019", "--out", str(tmp_path), "--json", "--no-progress"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert {"case", "controller", "metric", "ours", "paper"} <= set(rows[0])
    assert {r["case"] for r in rows} == {"rudder_aging", "current_shift", "maneuverability_change"}
    literal = [r for r in rows if "front_end" not in r]  # beside the SVF extension's *_svf rows
    assert {r["controller"] for r in literal} == {"nmpc", "nmpc_wlssvm", "nmpc_lambda_lssvm"}
    assert {r["metric"] for r in literal} == {"ace", "t_c"}
    assert {r["controller"] for r in rows if r.get("front_end") == "svf"} == {
        "nmpc_lambda_lssvm_svf",
        "nmpc_wlssvm_svf",
    }
    assert (tmp_path / "liu2019.md").is_file() and (tmp_path / "rudder_aging_si.png").is_file()


def test_finding11_a_bad_suite_is_named_before_the_state_of_out(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Run where a run of the smoke suite was made before (``results/smoke`` holds it): a
    misspelt --suite is reported as such, not as "--out is not empty"; each suite has its
    own default folder."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "results" / "smoke").mkdir(parents=True)
    (tmp_path / "results" / "smoke" / "run.json").write_text("{}")
    for command in (["leaderboard"], ["evaluate", "pid_los"]):
        out = ["--out", "results/smoke"]
        assert main([*command, "--suite", "smok", *out, "--no-progress"]) == 2
        message = error_line(capsys, command[0])
        assert "smok" in message and "valid: default" in message and "not empty" not in message
    assert main(["leaderboard", "--suite", "smoke", "--no-progress"]) == 2  # then the folder
    message = error_line(capsys, "leaderboard")
    assert "--out results/smoke is not empty" in message
    assert "(the leaderboard's folder for --suite smoke; give --out for another)" in message


def test_no_help_text_points_to_the_unshipped_spec(capsys) -> None:
    """Help texts cite no section of the design spec (it is not shipped)."""
    from shipgym_baselines.cli import SUBCOMMANDS, build_parser

    parser = build_parser()
    texts = [parser.format_help()]
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    texts += [p.format_help() for p in sub.choices.values()]
    assert len(texts) == len(SUBCOMMANDS) + 1  # the top level and each subcommand
    assert not [t for t in texts if "SPEC" in t]


def test_bench_training_compares_equal_widths() -> None:
    """Each path's rate and CPU, and the ratios at the config's width and at the wide one
    (tiny runs: the figures' shape, not their speed)."""
    from shipgym_baselines.studies.benchmarks import bench_training

    figures = bench_training(n_envs=4, timesteps=64, kinds=("batched", "dummy"), wide_envs=8)
    for label in ("batched", "dummy", "batched_wide", "dummy_wide"):
        assert figures[f"ppo_{label}_env_steps_per_s"] > 0 and figures[f"ppo_{label}_cpu_s"] > 0
    for ratio in ("batched_over_dummy", "batched_wide_over_dummy", "batched_wide_over_dummy_wide"):
        assert figures[ratio] == pytest.approx(
            figures[f"ppo_{ratio.split('_over_')[0]}_env_steps_per_s"]
            / figures[f"ppo_{ratio.split('_over_')[1]}_env_steps_per_s"]
        )
    assert figures["wide_envs"] == 8 and figures["n_envs"] == 4
    for label in ("batched", "dummy", "batched_wide", "dummy_wide"):  # env + agent = the whole
        env, agent = figures[f"ppo_{label}_env_cpu_s"], figures[f"ppo_{label}_agent_cpu_s"]
        assert env > 0 and agent > 0
        assert env + agent == pytest.approx(figures[f"ppo_{label}_cpu_s"])
    bound = figures["ppo_dummy_wide_cpu_s"] / figures["ppo_batched_wide_agent_cpu_s"]
    assert figures["batched_wide_over_dummy_wide_cpu_bound"] == pytest.approx(bound)
    assert (
        figures["batched_wide_over_dummy_wide_cpu_bound"]
        > figures["batched_wide_over_dummy_wide_cpu"]
    )  # the batched env's own CPU is not zero


def test_env_clock_counts_the_env_cpu_and_nothing_else() -> None:
    """The bench's env clock adds up the CPU spent inside the wrapped VecEnv's reset and
    step (a stub env burning known CPU), not the caller's CPU between the calls."""
    import time

    import gymnasium as gym
    import numpy as np
    from stable_baselines3.common.vec_env import VecEnv

    from shipgym_baselines.studies.benchmarks import _env_clock

    def burn(seconds: float) -> None:
        end = time.process_time() + seconds
        while time.process_time() < end:
            pass

    class Burner(VecEnv):
        def __init__(self) -> None:
            box = gym.spaces.Box(-1.0, 1.0, (1,), np.float32)
            super().__init__(1, box, box)

        def reset(self):  # type: ignore[override]
            burn(0.02)
            return np.zeros((1, 1), np.float32)

        def step_async(self, actions):  # type: ignore[override]
            burn(0.01)

        def step_wait(self):  # type: ignore[override]
            burn(0.03)
            return np.zeros((1, 1), np.float32), np.zeros(1), np.zeros(1, bool), [{}]

        def get_attr(self, name, indices=None):  # type: ignore[override]
            return [None]  # render_mode, which VecEnv.__init__ asks for

        def close(self) -> None: ...
        def set_attr(self, name, value, indices=None): ...  # type: ignore[override]
        def env_method(self, name, *args, indices=None, **kwargs): ...  # type: ignore[override]
        def env_is_wrapped(self, wrapper_class, indices=None): ...  # type: ignore[override]

    clock = _env_clock(Burner())
    clock.reset()
    for _ in range(3):
        burn(0.05)  # the agent's CPU, outside the env
        clock.step(np.zeros((1, 1), np.float32))
    expected = 0.02 + 3 * (0.01 + 0.03)  # 0.14 s inside the env, 0.15 s outside
    assert expected <= clock.cpu_s < expected + 0.03


#: a number in the manoeuvre's text output (not a digit inside a name: t_90, U0, 20_20)
NUMBER = r"(?<![\w.])-?\d+(?:\.\d+)?(?:e[+-]?\d+)?"
#: what must follow it: one of the units the output uses
UNIT = r"\s*(?:m/s|deg/s|deg|kn|m|L|s|%)(?![\w/])"


@pytest.mark.parametrize(
    ("ship", "kind", "options"),
    [("mariner", "turning", []), ("nomoto2", "zigzag", ["--rudder", "10"])],
)
def test_every_number_of_the_manoeuvre_output_has_its_unit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], ship: str, kind: str, options: list[str]
) -> None:
    """Each figure and criterion line names a unit after every number (a distance in m and
    in ship lengths L); ``--json`` keeps the figures' names and adds their units."""
    import re

    out = ["--out", str(tmp_path)]
    assert main(["manoeuvre", ship, kind, *options, *out]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[-1] == f"plot: {tmp_path / f'{ship}_{kind}.png'}"
    for line in lines[:-1]:
        numbers = re.findall(NUMBER, line)
        assert numbers and len(re.findall(NUMBER + UNIT, line)) == len(numbers), line
    figures = {line.split()[0]: line for line in lines[1:-1]}
    if kind == "turning":
        assert re.fullmatch(r"advance +[\d.]+ m = [\d.]+ L", figures["advance"])
        assert re.search(r"ship length L = 172 m, approach speed U0 = 7.857 m/s", lines[0])
    else:
        assert re.fullmatch(r"overshoot_1 +[\d.]+ deg", figures["overshoot_1"])
    assert main(["manoeuvre", ship, kind, *options, *out, "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    named = {k for k in document if k not in ("units", "imo_criteria")}
    assert set(document["units"]) == named and named
    if kind == "turning":
        assert document["units"]["advance"] == "m" and document["advance"] > 600.0
    else:
        assert document["units"]["overshoot_1"] == "deg"


def test_manoeuvre_kvlcc2_gives_its_imo_criteria_rows(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``shipgym manoeuvre kvlcc2 turning|zigzag`` runs and judges the IMO criteria (the
    docs/imo_criteria.md row: 3.08 L, 3.12 L, 5.04°, 13.72°, 10.61°, every one a pass)."""
    out = ["--out", str(tmp_path), "--json"]
    rows = {}
    for kind, options in (("turning", []), ("zigzag", ["--rudder", "10"]), ("zigzag", [])):
        assert main(["manoeuvre", "kvlcc2", kind, *options, *out]) == 0
        rows |= {c["criterion"]: c for c in json.loads(capsys.readouterr().out)["imo_criteria"]}
    expected = {
        "advance": 3.08,
        "tactical_diameter": 3.12,
        "first_overshoot_10_10": 5.04,
        "second_overshoot_10_10": 13.72,
        "first_overshoot_20_20": 10.61,
    }
    assert set(rows) == set(expected)
    for name, value in expected.items():
        assert rows[name]["value"] == pytest.approx(value, abs=0.006) and rows[name]["passed"]


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--act-timeout", "0"], "--act-timeout must be a positive time in s, got 0.0"),
        (["--act-timeout", "nan"], "--act-timeout must be a positive time in s, got nan"),
        (
            ["--retry-failed"],
            "--retry-failed runs the failed episodes of a resumed run: add --resume",
        ),
    ],
)
@pytest.mark.parametrize("command", [["leaderboard"], ["evaluate", "pid_los"]])
def test_failure_options_that_cannot_work_are_one_line_before_any_work(
    command: list[str], extra: list[str], message: str, tmp_path: Path, capsys
) -> None:
    out = tmp_path / "out"
    assert main([*command, "--suite", "smoke", "--out", str(out), *extra]) == 2
    assert error_line(capsys, command[0]) == message
    assert not out.exists()
