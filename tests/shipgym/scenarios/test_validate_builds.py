"""What validates must run: ``shipgym scenarios --validate`` builds
what construction builds — the nominal model's identification included — so every file it
accepts makes an env that steps, and construction errors name the scenario key."""

from __future__ import annotations

import copy
from pathlib import Path

import gymnasium as gym
import pytest
import yaml

import shipgym  # noqa: F401  (registers the envs)
from shipgym.scenarios.loader import ScenarioError, catalogue_dir, check_scenario_file
from shipgym_baselines.cli import main
from tests.shipgym.scenarios.fuzz import write_fuzzed

ENV_ID = "ShipPathFollow-v0"


def _steps(file: Path, mode: str) -> None:
    env = gym.make(ENV_ID, scenario=str(file), action_mode=mode, compile=False)
    env.reset(seed=0)
    env.action_space.seed(0)
    for _ in range(3):
        env.step(env.action_space.sample())
    env.close()


def test_finding9_every_file_validate_accepts_makes_an_env_and_steps(tmp_path: Path) -> None:
    """The property, on 200 fuzzed files (seeded: catalogue scenarios with 1–3 numbers
    changed, half of them the ship's own).  The seed is one whose 200 files reach both sides
    of the nominal-model check with the catalogue as it is (the scenario matrix added 20
    scenarios: seed 19 no longer did)."""
    accepted, nominal = 0, 0
    for file in write_fuzzed(tmp_path, 200, seed=22):
        problems = check_scenario_file(file)
        nominal += any("nominal model" in p.message for p in problems)
        if problems:
            continue
        accepted += 1
        for mode in ("rudder", "guidance"):
            _steps(file, mode)  # raises if construction refuses what validation accepted
    assert accepted >= 100 and nominal >= 1  # the fuzzer reaches both sides of the check


def _osaka(tmp_path: Path, **params: float) -> Path:
    data = yaml.safe_load(catalogue_dir().joinpath("osaka_curved.yaml").read_text())
    data = copy.deepcopy(data)
    data["ship"].setdefault("params", {}).update(params)
    file = tmp_path / "osaka.yaml"
    file.write_text(yaml.safe_dump(data))
    return file


def test_finding9_construction_errors_name_the_scenario_key(tmp_path: Path, capsys) -> None:
    """A rudder limit below the identifying zig-zag's 20° was a zig-zag rudder error."""
    file = _osaka(tmp_path, delta_max=0.1)
    with pytest.raises(ScenarioError, match=r"key 'ship\.params\.delta_max': the rudder limit"):
        gym.make(ENV_ID, scenario=str(file), action_mode="guidance", compile=False)
    assert main(["scenarios", "--validate", str(file)]) == 2
    out = capsys.readouterr().out
    assert "key 'ship.params.delta_max'" in out and "osaka.yaml:" in out
    diverging = _osaka(tmp_path, Xee=-0.224)  # ×100: the simulated zig-zag blows up
    (problem,) = check_scenario_file(diverging)
    assert problem.key == "ship.params" and "no nominal model" in problem.message
    with pytest.raises(ScenarioError, match=r"key 'ship\.params': no nominal model"):
        gym.make(ENV_ID, scenario=str(diverging), action_mode="guidance", compile=False)


def test_finding9_a_controller_meets_the_key_not_a_zigzag_error(tmp_path: Path, capsys) -> None:
    """Rudder mode builds no autopilot, but the controller context (what model-based
    controllers design on) names the key too: ``shipgym run`` says it in one line."""
    file = _osaka(tmp_path, delta_max=0.1)
    env = gym.make(ENV_ID, scenario=str(file), action_mode="rudder", compile=False)
    with pytest.raises(ScenarioError, match=r"key 'ship\.params\.delta_max'"):
        _ = env.unwrapped.controller_context
    code = main(["run", str(file), "pid_los", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "ship.params.delta_max" in err
