"""Baselines, the evaluation loop and the leaderboard; the CLI: test_cli.py."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from shipgym.autopilot import HeadingPID, PIDGains
from shipgym_baselines.classical.pid import PIDLOS
from shipgym_baselines.evaluation import evaluate, run_episode
from shipgym_baselines.leaderboard.run import run_leaderboard


def test_pid_gains_place_closed_loop_poles() -> None:
    """Pole placement on T·ṙ + r = Kδ: the closed loop has a double pole at −ωn (ζ = 1)."""
    K, T, wn = 0.5, 1.5, 0.8
    g = PIDGains.from_nomoto(K, T, natural_frequency=wn, damping=1.0)
    # characteristic polynomial of T s² + (1 + K kd) s + K kp
    poles = np.roots([T, 1 + K * g.kd, K * g.kp])
    np.testing.assert_allclose(poles, [-wn, -wn], atol=1e-6)


def test_heading_pid_saturates_and_does_not_wind_up() -> None:
    pid = HeadingPID(PIDGains(kp=2.0, ki=1.0, kd=0.0), rudder_limit=0.5)
    for _ in range(100):
        assert pid.command(1.0, 0.0, 0.0, 0.5) == pytest.approx(0.5)
    assert pid.integral == 0.0  # conditional integration: no windup while saturated


def test_pid_los_follows_nominal_path_to_the_goal() -> None:
    (result,) = evaluate("pid_los", "nominal", seeds=[0])
    m = result.metrics
    assert m["success"] is True
    assert m["termination_reason"] == "goal"
    # the path is 37 m long at 0.8 m/s: the goal is reached in well under the time limit
    assert m["duration"] < 70.0
    # far better than doing nothing
    (zero,) = evaluate("zero_rudder", "nominal", seeds=[0])
    assert m["ace"] < 0.5 * zero.metrics["ace"]


@pytest.fixture(scope="module")
def smoke(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[dict]]:
    """The smoke suite's leaderboard, run once: (its folder, its rows)."""
    out = tmp_path_factory.mktemp("smoke")
    rows = run_leaderboard("smoke", seeds=2, out_dir=out, workers=2, show_progress=False)
    return out, rows


def test_leaderboard_writes_tables_with_contract_keys(smoke: tuple[Path, list[dict]]) -> None:
    tmp_path, rows = smoke
    for name in ("leaderboard.md", "leaderboard.csv", "leaderboard.json", "generalisation.json"):
        assert (tmp_path / name).is_file()
    on_disk = json.loads((tmp_path / "leaderboard.json").read_text())
    assert len(on_disk) == len(rows) == 3 * 6  # rudder_aging, mariner_track, heldout:0
    required = {
        "scenario",
        "controller",
        "kind",
        "ace",
        "ace_L",
        "t_c",
        "return",
        "success",
        "compute_ms",
        "ace_std",
        "t_c_std",
        "return_std",
        "compute_ms_std",
    }
    for row in on_disk:
        assert required <= set(row)
        assert row["kind"] in ("classical", "learned", "reference")
    assert {r["kind"] for r in on_disk} == {"classical", "learned", "reference"}
    pid = {r["scenario"]: r for r in on_disk if r["controller"] == "pid_los"}
    zero = {r["scenario"]: r for r in on_disk if r["controller"] == "zero_rudder"}
    for scenario in pid:
        assert pid[scenario]["ace"] < zero[scenario]["ace"]
    # the NMPC family runs on every ship: a row with numbers on the Mariner too
    nmpc = {r["scenario"]: r for r in on_disk if r["controller"] == "nmpc_lambda_lssvm"}
    assert all(row["applies"] is True for row in nmpc.values())
    assert nmpc["mariner_track"]["ace"] < zero["mariner_track"]["ace"]
    ppo = next(r for r in on_disk if r["controller"] == "ppo")
    assert ppo["kind"] == "learned" and ppo["train_env_steps"] > 0
    assert {r["split"] for r in on_disk} == {"catalogue", "heldout"}
    assert (tmp_path / "scenario_rudder_aging.png").is_file()
    assert_equals_golden(on_disk, GOLDEN / "smoke_leaderboard.json")


#: the smoke suite's run before the page was made lighter (main 195f895): leaderboard.html
#: and the folder's files [bytes]; the default suite's were 9.6 MB and 51 MB, the targets
#: 3 MB and 15 MB
SMOKE_PAGE_BEFORE, SMOKE_FOLDER_BEFORE = 1_072_283, 3_720_279
DEFAULT_PAGE_BEFORE, DEFAULT_FOLDER_BEFORE = 9.6e6, 51e6
PAGE_TARGET, FOLDER_TARGET = 3e6, 15e6


def test_the_page_and_the_run_folder_are_light(smoke: tuple[Path, list[dict]]) -> None:
    """The page and the folder shrink on the smoke suite as the targets ask of
    the default suite (page ≤ 3 / 9.6, folder ≤ 15 / 51 of their size before), the page
    still showing every figure (as a PNG) and table."""
    out, rows = smoke
    page = (out / "leaderboard.html").stat().st_size
    folder = sum(f.stat().st_size for f in out.rglob("*") if f.is_file())
    assert page <= SMOKE_PAGE_BEFORE * PAGE_TARGET / DEFAULT_PAGE_BEFORE, page
    assert folder <= SMOKE_FOLDER_BEFORE * FOLDER_TARGET / DEFAULT_FOLDER_BEFORE, folder
    html = (out / "leaderboard.html").read_text()
    for png in out.glob("*.png"):
        assert f"<code>{png.name}</code>" in html, png.name
    embedded = re.findall("data:image/(?:png|webp);base64,", html)  # lossless, the PNG's pixels
    linked = re.findall(r'src="(scenario_[^"]+\.png)"', html)  # the files beside the page
    # the ranking figures and the shipped ppo's learning curves embedded; the scenario
    # figures (rudder_aging, mariner_track, heldout:0) linked
    assert len(embedded) == 5
    assert sorted(linked) == sorted(p.name for p in out.glob("scenario_*.png"))
    assert len(embedded) + len(linked) == len(list(out.glob("*.png"))) == 8
    assert (out / "learning_curves.png").is_file()
    assert "data:image/svg" not in html
    assert all(row["controller"] in html for row in rows)


def test_the_smoke_leaderboard_opens_with_its_verdict(smoke: tuple[Path, list[dict]]) -> None:
    """leaderboard.md, the terminal summary and the page open with the run's two sentences:
    the catalogue leader of aggregate.json with its IQM, the learned agent's rank."""
    from shipgym_baselines.leaderboard.outputs import terminal_summary
    from shipgym_baselines.page.verdict import folder_verdict, plain_name

    out, _ = smoke
    board = [
        r for r in json.loads((out / "aggregate.json").read_text()) if r["split"] == "catalogue"
    ]
    lead = folder_verdict(out)
    assert lead is not None
    first, second = lead.split(". The ")[:2]
    assert first.startswith(
        f"`{board[0]['controller']}` leads the 2 catalogue scenarios at cost-ratio IQM "
        f"{board[0]['cost_ratio_iqm']:.3f}"
    )
    rank = 1 + [r["controller"] for r in board].index("ppo")
    assert second.startswith(f"best learned agent, `ppo`, ranks {rank}")
    assert "failure rate" in second
    assert f"`ppo` {board[rank - 1]['change_share_iqm']:.2f}" in lead  # its change share
    assert (out / "leaderboard.md").read_text().startswith(f"# Leaderboard\n\n{lead}\n\n")
    assert terminal_summary(out).startswith(f"{lead}\n\n## Ranking")
    html = (out / "leaderboard.html").read_text()
    plain = folder_verdict(out, plain_name)
    assert plain is not None and plain.replace("'", "&#x27;") in html
    assert html.index('id="verdict"') < html.index('id="ranking"')


def test_run_replays_the_leaderboards_trial(
    smoke: tuple[Path, list[dict]], tmp_path: Path, capsys
) -> None:
    """``shipgym run SCENARIO CONTROLLER --seed S --suite smoke`` is the smoke
    leaderboard's episode of that scenario and seed, its randomised trial included: ACE and
    cost equal bit for bit."""
    from shipgym_baselines.cli import main

    out, _ = smoke
    records = [json.loads(line) for line in (out / "episodes.jsonl").read_text().splitlines()]
    (board,) = [
        r
        for r in records
        if (r["scenario"], r["controller"], r["seed"]) == ("rudder_aging", "pid_los", 10_001)
    ]
    args = ["run", "rudder_aging", "pid_los", "--seed", "10001", "--json"]
    assert main([*args, "--suite", "smoke", "--out", str(tmp_path / "smoke")]) == 0
    replay = json.loads(capsys.readouterr().out)
    assert (replay["ace"], replay["cost"]) == (board["ace"], board["cost"])
    assert replay["steps"] == board["steps"]
    # a suite without randomize: the catalogue scenario itself, another episode
    plain = tmp_path / "plain.yaml"
    plain.write_text("name: plain\nscenarios: [rudder_aging]\ncontrollers: [pid_los]\n")
    assert main([*args, "--suite", str(plain), "--out", str(tmp_path / "plain")]) == 0
    assert json.loads(capsys.readouterr().out)["ace"] != board["ace"]


GOLDEN = Path(__file__).resolve().parents[1] / "golden"
#: the floats of rows computed through BLAS or torch agree to this across machines
#: (tests/golden/README.md); every other row is compared exactly
GOLDEN_REL = 1e-4


def _through_blas_or_torch(row: dict) -> bool:
    """A learned agent (torch) or an LS-SVM identifier (BLAS solves): the CPU's kernels
    round these differently from machine to machine."""
    return row.get("kind") == "learned" or "lssvm" in row["controller"]


def assert_equals_golden(rows: list[dict], golden: Path) -> None:
    """Every number equal to the recorded golden (tests/golden/README.md), wall-clock
    controller timings aside, the floats of BLAS / torch rows to ``GOLDEN_REL``: a
    restructure must not move them."""
    want = json.loads(golden.read_text())
    assert len(rows) == len(want)
    for got, ref in zip(rows, want, strict=True):
        keys = {k for k in ref if not k.startswith("compute_ms")}
        assert {k for k in got if not k.startswith("compute_ms")} == keys
        loose = _through_blas_or_torch(ref)
        for key in keys:
            where = (ref["scenario"], ref["controller"], key, got[key], ref[key])
            assert _close(got[key], ref[key]) if loose else got[key] == ref[key], where


def _close(got: object, ref: object) -> bool:
    """Equal, floats to ``GOLDEN_REL`` relative (lists element by element; an infinite or
    NaN float only equals itself)."""
    if isinstance(ref, list):
        return isinstance(got, list) and len(got) == len(ref) and all(map(_close, got, ref))
    if isinstance(ref, float) and isinstance(got, float):
        return got == ref or math.isclose(got, ref, rel_tol=GOLDEN_REL, abs_tol=0.0)
    return got == ref


def test_default_suite_has_every_controller_and_learned_agent() -> None:
    """Every controller on main and every shipped policy is on the default board, but three
    of Liu et al.'s identifier rows, which play in the quick suite (the default run's
    time: docs/leaderboard.md, "The default run's size")."""
    from shipgym.scenarios.loader import list_scenarios
    from shipgym_baselines.learned.policy import shipped_policies
    from shipgym_baselines.registry import CONTROLLERS
    from shipgym_baselines.suite import load_suite

    suite, quick = load_suite("default"), load_suite("quick")
    every = set(CONTROLLERS) | set(shipped_policies())
    assert every - set(suite.controllers) == {"nmpc_wlssvm", "nmpc_wlssvm_svf", "nmpc_lambda_lssvm"}
    assert every <= set(quick.controllers)
    assert set(suite.scenarios) <= set(list_scenarios())
    assert suite.heldout_scenarios >= 1


def test_guidance_mode_with_zero_action_is_pid_los() -> None:
    """The env's autopilot (guidance mode, a = 0) is the pid_los baseline's paper design,
    step for step."""
    import gymnasium as gym

    pid = run_episode(PIDLOS(preset="paper"), "rudder_aging", seed=3)
    env = gym.make(
        "ShipPathFollow-v0", scenario="rudder_aging", action_mode="guidance", randomize=False
    )
    env.reset(seed=3)
    commands = []
    while True:
        _, _, terminated, truncated, info = env.step(np.zeros(2, dtype=np.float32))
        commands.append(info["rudder_command"])
        if terminated or truncated:
            break
    # pid_los passes δc/δmax through a float32 action: equal to float32 resolution
    assert len(commands) == len(pid.trajectory["rudder_command"]) - 1
    np.testing.assert_allclose(commands, pid.trajectory["rudder_command"][1:], atol=1e-6)
