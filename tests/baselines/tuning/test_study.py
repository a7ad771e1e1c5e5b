"""shipgym tune: the study machinery (toy optimum, resume, refusal), its report's shape,
the chosen settings reaching the registry's default construction, and the trial source."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

import optuna
import pytest
import yaml

from shipgym.scenarios.sampling import ScenarioDistribution
from shipgym_baselines.classical.pid import PIDLOS
from shipgym_baselines.cli import main
from shipgym_baselines.errors import RunError
from shipgym_baselines.records import chosen as chosen_reader
from shipgym_baselines.records.manifest import read_manifest
from shipgym_baselines.scoring.intervals import geometric_mean
from shipgym_baselines.tuning import chosen
from shipgym_baselines.tuning import study as study_module
from shipgym_baselines.tuning.objective import controller_ratios
from shipgym_baselines.tuning.space import ParamSpec, TuningConfig, load_tuning
from shipgym_baselines.tuning.study import default_storage, open_study, plan_studies, run_study
from shipgym_baselines.tuning.validation import (
    check_validation_split,
    oracle_costs,
    validation_trials,
)
from tests.baselines.records.conftest import file_held_elsewhere
from tests.baselines.records.test_locking import hold

#: the packaged distributions' folder
DISTRIBUTIONS = Path(__file__).resolve().parents[3] / "configs" / "distributions"
#: a tiny per-ship pid_los study: nomoto2's first validation trial, 3 trials
TINY = {
    "name": "pid_los_tiny",
    "controller": "pid_los",
    "per_ship": True,
    "ships": ["nomoto2"],
    "budget": 3,
    "validation": {"distribution": "validation", "per_ship": 1},
    "chunk": 1,
    "startup_trials": 2,
    "fixed": {"preset": "paper", "tuning": "pole_placement"},
    "default": {"preset": "paper"},
    "params": {
        "natural_frequency_T": {"low": 0.5, "high": 4.0, "log": True},
        "los_radius_L": {"low": 1.5, "high": 6.0},
    },
}

#: what the learned studies share: not per ship, one trial scored on nomoto2's first
#: validation trial
LEARNED = {
    "kind": "learned",
    "per_ship": False,
    "ships": ["nomoto2"],
    "budget": 1,
    "validation": {"distribution": "validation", "per_ship": 1},
    "startup_trials": 1,
}


@pytest.fixture(scope="module")
def tiny(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The tiny config as a YAML file (its out folder shares one oracle cache)."""
    folder = tmp_path_factory.mktemp("tiny")
    file = folder / "pid_los_tiny.yaml"
    file.write_text(yaml.safe_dump(TINY))
    return file


def test_a_seeded_tpe_study_finds_a_toy_optimum(tmp_path: Path) -> None:
    """The sampler and pruner of every study (open_study) on f(x, y) = (log x − log 2)² +
    (y − 3)², optimum x = 2, y = 3, with the config's parameter specs."""
    config = TuningConfig.model_validate({**TINY, "budget": 60, "startup_trials": 10})
    from shipgym_baselines.tuning.study import StudyPlan

    plan = StudyPlan("toy", config, None, tmp_path, f"sqlite:///{tmp_path}/toy.db", "toy")
    study = open_study(plan, resume=False)
    x_spec = ParamSpec(low=0.1, high=20.0, log=True)
    y_spec = ParamSpec(low=-5.0, high=5.0)

    def objective(trial: Any) -> float:
        x, y = x_spec.suggest(trial, "x"), y_spec.suggest(trial, "y")
        return (math.log(x) - math.log(2.0)) ** 2 + (y - 3.0) ** 2

    study.optimize(objective, n_trials=60)
    assert study.best_params["x"] == pytest.approx(2.0, rel=0.15)
    assert study.best_params["y"] == pytest.approx(3.0, abs=0.3)
    again = open_study(plan, resume=True)  # the same study, from its SQLite storage
    assert len(again.trials) == 60 and again.best_value == study.best_value


def test_tuning_reads_only_validation_trials(
    tiny: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A spy on the trial sources: a study draws test scenarios only from the validation
    split and never loads a catalogue scenario file."""
    import shipgym.scenarios.loader as loader

    drawn: list[str] = []
    files: list[str] = []
    real_test, real_file = ScenarioDistribution.test_scenario, loader.load_scenario_file

    def spy_test(self: ScenarioDistribution, index: int) -> Any:
        drawn.append(f"{self.name}:{index}")
        return real_test(self, index)

    def spy_file(path: Any) -> Any:
        files.append(str(path))
        return real_file(path)

    monkeypatch.setattr(ScenarioDistribution, "test_scenario", spy_test)
    monkeypatch.setattr(loader, "load_scenario_file", spy_file)
    (plan,) = plan_studies(str(tiny), out=tiny.parent / "out_spy", chosen_dir=tmp_path)
    run_study(plan, n_trials=2)
    assert drawn and {name.split(":")[0] for name in drawn} == {"validation"}
    assert files == []
    for bad in ("heldout", "inrange", "train"):
        with pytest.raises(RunError, match="validation split"):
            check_validation_split(bad)


def test_tuning_cannot_name_the_leaderboards_test_splits(tmp_path: Path) -> None:
    """The held-out and in-range splits (test_only) are refused by every path to a study's
    trials, also as a copy of their file under another name."""
    for split in ("heldout", "inrange"):
        with pytest.raises(RunError, match="test_only"):
            validation_trials(split)
    copy = tmp_path / "my_split.yaml"
    copy.write_text((DISTRIBUTIONS / "inrange.yaml").read_text().replace("inrange", "my_split"))
    with pytest.raises(RunError, match="test_only"):
        validation_trials(str(copy))
    assert len(validation_trials()) == 32  # the validation split itself: every trial


def test_a_study_reports_resumes_and_refuses_to_overwrite(tiny: Path, tmp_path: Path) -> None:
    out = tiny.parent / "out_main"
    (plan,) = plan_studies(str(tiny), out=out, chosen_dir=tmp_path)
    report = run_study(plan, n_trials=2)
    on_disk = json.loads((out / "nomoto2" / "tuning_report.json").read_text())
    assert on_disk["best_value"] == report["best_value"]
    for key in ("trials", "best_params", "best_value", "best_vs_default", "default_value"):
        assert key in on_disk, key
    assert len(on_disk["trials"]) == 2
    assert {"number", "params", "value", "state"} <= set(on_disk["trials"][0])
    assert set(on_disk["best_params"]) == {"natural_frequency_T", "los_radius_L"}
    block = on_disk["best_vs_default"]
    for side in ("best", "default"):
        low, high = block[side]["ci95"]
        assert low <= block[side]["cost_ratio_gmean"] <= high
    assert block["best"]["cost_ratio_gmean"] == pytest.approx(on_disk["best_value"])
    assert on_disk["validation"]["trials"] == ["validation:0"]
    with pytest.raises(RunError, match="--resume"):
        run_study(plan, n_trials=3)
    resumed = run_study(plan, n_trials=3, resume=True)
    assert len(resumed["trials"]) == 3
    assert resumed["trials"][:2] == on_disk["trials"]  # the same study, continued
    written = chosen.read_chosen("pid_los", tmp_path)
    assert written["studies"]["nomoto2"]["study"] == "pid_los_tiny:nomoto2"
    if not resumed["chosen"]["kept_default"]:
        assert written["ships"]["nomoto2"]["los_radius_L"] == resumed["best_params"]["los_radius_L"]
    # the best value is the objective of its settings, re-scored through the evaluation loop
    trials = validation_trials("validation", "nomoto2", 1)
    oracle = oracle_costs(trials)  # the per-user cache (shipped: the validation split)
    settings = {**TINY["fixed"], **resumed["best_params"]}
    ratios = controller_ratios("pid_los", settings, trials, oracle)
    assert geometric_mean(ratios) == pytest.approx(resumed["best_value"], rel=1e-12)
    with pytest.raises(RunError, match="no study"):
        (other,) = plan_studies(str(tiny), out=tmp_path / "none", chosen_dir=tmp_path)
        run_study(other, resume=True)


def test_chosen_settings_reach_the_default_construction(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """PIDLOS() and L1Backstepping() read the ship's chosen section at reset (explicit
    settings win); preset='paper' ignores it; a ship without a section keeps the paper's
    design."""
    from shipgym.envs.context import ControllerContext
    from shipgym.scenarios.loader import load_scenario

    chosen.write_chosen("pid_los", "nomoto2", {"natural_frequency_T": 2.9}, {}, tmp_path)
    monkeypatch.setattr(chosen_reader, "chosen_dir", lambda: tmp_path)  # the reader's folder
    chosen.packaged_chosen.cache_clear()
    try:
        ctx = ControllerContext.of(load_scenario("nominal"), "rudder")
        tuned, paper = PIDLOS(), PIDLOS(preset="paper")
        tuned.reset(ctx)
        paper.reset(ctx)
        from shipgym.identification.nominal import first_order_nomoto

        _, T = first_order_nomoto(ctx.nominal_model)
        assert tuned.gains.kp == pytest.approx(paper.gains.kp * (2.9 / T) ** 2)
        explicit = PIDLOS(natural_frequency_T=T)  # explicit settings win over chosen ones
        explicit.reset(ctx)
        assert explicit.gains.kp == pytest.approx(paper.gains.kp)
        other = PIDLOS()
        other.reset(ControllerContext.of(load_scenario("blanke_nominal"), "rudder"))
        assert other.natural_frequency_T is None  # no blanke section: the paper's ωn
        from shipgym_baselines.classical.l1_backstepping import L1Backstepping

        chosen.write_chosen("l1_backstepping", "nomoto2", {"K2": 30.0, "K1": 0.05}, {}, tmp_path)
        chosen.packaged_chosen.cache_clear()
        l1, l1_paper, l1_given = (
            L1Backstepping(),
            L1Backstepping(preset="paper"),
            L1Backstepping(K1=0.01),
        )
        for policy in (l1, l1_paper, l1_given):
            policy.reset(ctx)
        assert (l1.settings.K1, l1.settings.K2) == (0.05, 30.0)
        assert (l1_paper.settings.K1, l1_paper.settings.K2) == (0.02, 15.0)
        assert (l1_given.settings.K1, l1_given.settings.K2) == (0.01, 30.0)
        from shipgym_baselines.classical.lqr import (
            LQR,
            PAPER_LAMBDA_DELTA,
            PAPER_LAMBDA_PSI,
            AdaptiveLQR,
            length_scaled_lambda_y,
        )

        weights = {"lambda_y": 0.3, "lambda_psi": 4.0, "lambda_delta": 2.0}
        chosen.write_chosen("lqr", "nomoto2", weights, {}, tmp_path)
        chosen.packaged_chosen.cache_clear()
        lqr, lqr_paper, lqr_given, adaptive = (
            LQR(),
            LQR(preset="paper"),
            LQR(lambda_psi=9.0),
            AdaptiveLQR(),  # its own study's section (none): the paper's weights
        )
        for policy in (lqr, lqr_paper, lqr_given, adaptive):
            policy.reset(ctx)
        paper = (length_scaled_lambda_y(ctx.ship_length), PAPER_LAMBDA_PSI, PAPER_LAMBDA_DELTA)
        as_tuple = lambda w: (w.lambda_y, w.lambda_psi, w.lambda_delta)  # noqa: E731
        assert as_tuple(lqr.weights) == (0.3, 4.0, 2.0)
        assert as_tuple(lqr_paper.weights) == paper == as_tuple(adaptive.weights)
        assert as_tuple(lqr_given.weights) == (0.3, 9.0, 2.0)
    finally:
        chosen.packaged_chosen.cache_clear()


def test_bad_tuning_configs_name_the_key(tmp_path: Path) -> None:
    from shipgym.config import ConfigError

    for edit, match in [
        ({"params": {"x": {"low": 2.0, "high": 1.0}}}, "low < high"),
        ({"kind": "learned"}, "training"),
        (
            {
                "fixed": {"los_radius_L": 3.0},
                "params": TINY["params"] | {"los_radius_L": {"low": 1.0, "high": 2.0}},
            },
            "tuned",
        ),
        (  # a learned default that would train in another env than the trials
            {
                "kind": "learned",
                "per_ship": False,
                "training": {"agent": "ppo", "n_timesteps": 256},
                "fixed": {"env.n_envs": 64, "hyperparams.n_steps": 32},
                "default": {"env.n_envs": 64},
            },
            r"default: .*\['hyperparams.n_steps'\]",
        ),
    ]:
        file = tmp_path / "bad.yaml"
        file.write_text(yaml.safe_dump({**TINY, **edit}))
        with pytest.raises(ConfigError, match=match):
            load_tuning(str(file))


def test_the_cli_runs_a_study_and_refuses_to_rerun_it(
    tiny: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tiny.parent / "out_cli"
    argv = ["tune", str(tiny), "--out", str(out), "--chosen-dir", str(tmp_path), "--trials", "1"]
    assert main([*argv, "--json"]) == 0
    (report,) = json.loads(capsys.readouterr().out)
    assert report["study"] == "pid_los_tiny:nomoto2" and len(report["trials"]) == 1
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--resume" in err[0]


def test_a_learned_study_trains_scores_and_prunes_through_the_same_command(
    tmp_path: Path,
) -> None:
    """``shipgym tune`` on a learned config: each trial trains a tiny PPO in two parts and
    reports the validation cost ratio after each (the pruner's intermediate values)."""
    config = {
        **LEARNED,
        "name": "ppo_tiny",
        "controller": "ppo",
        "training": {"agent": "ppo", "n_timesteps": 256, "evaluations": 2},
        "fixed": {"env.n_envs": 1, "hyperparams.n_steps": 64, "hyperparams.batch_size": 64},
        "default": {"env.n_envs": 1, "hyperparams.n_steps": 64, "hyperparams.batch_size": 64},
        "params": {"hyperparams.learning_rate": {"low": 1e-4, "high": 1e-3, "log": True}},
    }
    file = tmp_path / "ppo_tiny.yaml"
    file.write_text(yaml.safe_dump(config))
    (plan,) = plan_studies(str(file), out=tmp_path / "out", chosen_dir=tmp_path / "chosen")
    report = run_study(plan)
    (trial,) = report["trials"]
    assert trial["state"] == "COMPLETE" and list(trial["intermediate"]) == ["128", "256"]
    assert report["validation"]["trials"] == ["validation:0"]
    assert report["best_value"] == pytest.approx(trial["value"])
    assert report["chosen"]["section"] == "all"
    # the winner's settings as it was scored: the best trial under the fixed settings, or
    # the default (which trains as every trial does)
    winner = (
        config["default"]
        if report["chosen"]["kept_default"]
        else {**config["fixed"], **report["best_params"]}
    )
    assert report["chosen"]["settings"] == winner


def test_a_dagger_study_trains_its_rounds_in_parts(tmp_path: Path) -> None:
    """A learned study of an ``algo: dagger`` agent: each part continues the DAgger run
    until its labels are reached (parts of 50 labels, a round of one rollout ≈ 85: one round
    a part), reports the labels so far, and the value is the newest student's cost ratio."""
    agent = {
        "name": "dagger_tiny",
        "algo": "dagger",
        "n_timesteps": 100_000,
        "env": {"distribution": None, "scenario": "rudder_aging", "history_steps": 2},
        "hyperparams": {"rounds": 5, "episodes_per_round": 1, "epochs": 1, "batch_size": 64},
        "policy_kwargs": {"net_arch": [8]},
        "eval": {"distribution": "validation", "n_episodes": 1, "select_on": "relative_cost"},
    }
    agent_file = tmp_path / "dagger_tiny.yaml"
    agent_file.write_text(yaml.safe_dump(agent))
    config = {
        **LEARNED,
        "name": "dagger_tiny",
        "controller": "dagger",
        "training": {"agent": str(agent_file), "n_timesteps": 100, "evaluations": 2},
        "params": {"env.history_steps": {"choices": [2, 4]}},
    }
    file = tmp_path / "dagger_tiny_study.yaml"
    file.write_text(yaml.safe_dump(config))
    (plan,) = plan_studies(str(file), out=tmp_path / "out", chosen_dir=tmp_path / "chosen")
    report = run_study(plan)
    (trial,) = report["trials"]
    run = tmp_path / "out" / "runs" / f"trial_{trial['number']}"
    rounds = json.loads((run / "dagger" / "rounds.json").read_text())
    assert [r["round"] for r in rounds] == [0, 1]
    assert list(trial["intermediate"]) == [str(r["labels_total"]) for r in rounds]
    meta = json.loads((run / "meta.json").read_text())
    assert meta["history_steps"] == trial["params"]["env.history_steps"]
    assert trial["value"] == pytest.approx(trial["intermediate"][str(rounds[-1]["labels_total"])])


def test_every_packaged_tuning_config_loads() -> None:
    from shipgym_baselines.tuning.space import list_tuning

    names = list_tuning()
    assert "pid_los" in names and "ppo" in names
    for name in names:
        load_tuning(name)
    assert optuna.__version__


def test_only_the_driver_fails_a_running_trial(tmp_path: Path) -> None:
    """A trial left RUNNING is failed when the driver resumes the study (a killed process's
    trial), but not when a Ray task opens it (another task's trial that is running now: the
    race that made a task's ``tell`` fail with "Cannot tell a FAIL trial")."""
    from shipgym_baselines.tuning.study import StudyPlan

    config = TuningConfig.model_validate(TINY)
    plan = StudyPlan("toy", config, None, tmp_path, f"sqlite:///{tmp_path}/toy.db", "toy")
    running = open_study(plan, resume=False).ask()
    open_study(plan, resume=True, create=False, driver=False)
    assert open_study(plan, resume=True).trials[running.number].state.name == "FAIL"
    plan2 = StudyPlan("toy2", config, None, tmp_path, f"sqlite:///{tmp_path}/toy2.db", "toy2")
    running = open_study(plan2, resume=False).ask()
    task_view = open_study(plan2, resume=True, create=False, driver=False)
    assert task_view.trials[running.number].state.name == "RUNNING"


@pytest.mark.slow
def test_ray_tasks_share_the_study_storage(tiny: Path, tmp_path: Path) -> None:
    """--backend ray: two Ray tasks run the trials of one study through its SQLite storage
    (Ray starts in ≈ 16 s on the 2-core machine)."""
    pytest.importorskip("ray")
    (plan,) = plan_studies(str(tiny), out=tmp_path / "ray", chosen_dir=tmp_path)
    report = run_study(plan, n_trials=3, backend="ray", workers=2)
    finished = [t for t in report["trials"] if t["state"] in ("COMPLETE", "PRUNED")]
    assert 3 <= len(finished) <= 4  # each task stops at the budget (one may overshoot by 1)
    assert report["best_value"] == min(t["value"] for t in finished if t["state"] == "COMPLETE")


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["tune", "no_such_space"], "unknown tuning space 'no_such_space'"),
        (["tune", "pid_los", "--ship", "titanic"], "--ship 'titanic'"),
        (["tune", "ppo", "--ship", "mariner"], "--ship"),
        (["tune", "pid_los", "--storage", "sqlite:///x.db"], "--storage"),
        (["tune", "pid_los", "--ship", "nomoto2", "--trials", "0"], "--trials 0"),
    ],
)
def test_bad_tune_input_is_one_line_naming_it(
    argv: list[str], match: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main([*argv, "--out", str(tmp_path / "out"), "--chosen-dir", str(tmp_path)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and match in err[0], err


def _digests(folder: Path) -> dict[str, str]:
    import hashlib

    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in folder.glob("*.yaml")}


def test_a_short_study_leaves_the_packaged_settings_byte_identical(
    tiny: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Without --promote a study writes its chosen settings into OUT/chosen only."""
    packaged = _digests(chosen_reader.chosen_dir())
    out = tmp_path / "out"
    assert main(["tune", str(tiny), "--out", str(out), "--trials", "1"]) == 0
    assert _digests(chosen_reader.chosen_dir()) == packaged
    written = chosen.read_chosen("pid_los", out / "chosen")
    assert written["studies"]["nomoto2"]["study"] == "pid_los_tiny:nomoto2"
    record = written["studies"]["nomoto2"]["validation"]
    assert record["trials"] == ["validation:0"] and len(record["ratios"]) == 1
    err = capsys.readouterr().err
    assert f"{out / 'chosen' / 'pid_los.yaml'} [nomoto2]" in err
    summary = written["studies"]["nomoto2"]
    kept = summary["best_value"] >= summary["default_value"]
    said = "chose the default settings (no trial beat them" if kept else "chose the best trial's"
    assert said in err


def test_promote_targets_the_packaged_folder_and_excludes_chosen_dir(
    tiny: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (plan,) = plan_studies(str(tiny), out=tmp_path / "out", promote=True)
    assert plan.chosen_dir == chosen_reader.chosen_dir()
    (plan,) = plan_studies(str(tiny), out=tmp_path / "out")
    assert plan.chosen_dir == tmp_path / "out" / "chosen"
    with pytest.raises(RunError, match="--promote"):
        plan_studies(str(tiny), out=tmp_path / "out", chosen_dir=tmp_path, promote=True)
    argv = ["tune", str(tiny), "--promote", "--chosen-dir", str(tmp_path)]
    with pytest.raises(SystemExit) as exit_:  # argparse: mutually exclusive
        main(argv)
    assert exit_.value.code == 2 and "--chosen-dir" in capsys.readouterr().err


def _incumbent_file(folder: Path, ratios: list[float] | None, settings: dict[str, Any]) -> None:
    """A chosen file whose nomoto2 section holds ``settings``, recorded on the tiny study's
    trial with ``ratios`` (None: no record)."""
    from shipgym_baselines.tuning.promotion import revisions

    summary: dict[str, Any] = {"study": "earlier"}
    if ratios is not None:
        summary["validation"] = {
            "trials": ["validation:0"],
            "seeds": [10000],
            "ratios": ratios,
            **revisions(),
        }
    chosen.write_chosen("pid_los", "nomoto2", settings, summary, folder)


def test_better_recorded_settings_are_kept_unless_force(
    tiny: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Settings recorded at a ratio no study can reach (0.5: half the oracle's cost) on the
    same trial are kept, the file byte-identical and exit 1; --force replaces them and says
    what it replaced."""
    folder = tmp_path / "chosen"
    incumbent = {"tuning": "pole_placement", "natural_frequency_T": 3.0}
    _incumbent_file(folder, [0.5], incumbent)
    before = _digests(folder)
    argv = ["tune", str(tiny), "--out", str(tmp_path / "a"), "--chosen-dir", str(folder)]
    assert main([*argv, "--trials", "1", "--json"]) == 1
    captured = capsys.readouterr()
    (report,) = json.loads(captured.out)
    assert _digests(folder) == before
    block = report["chosen"]
    assert block["written"] is False and "--force" in block["refused"]
    assert block["incumbent"]["source"] == "recorded"
    assert block["incumbent"]["comparison"]["incumbent_value"] == pytest.approx(0.5)
    assert block["incumbent"]["comparison"]["new_value"] > 0.5
    assert "not written" in captured.err and "0.5" in captured.err
    assert captured.err.count("kept ") == 1  # said once, at the end
    argv[3] = str(tmp_path / "b")
    assert main([*argv, "--trials", "1", "--force"]) == 0
    err = capsys.readouterr().err
    assert "replaced" in err and "natural_frequency_T': 3.0" in err
    assert chosen.read_chosen("pid_los", folder)["studies"]["nomoto2"]["study"] != "earlier"


def test_unrecorded_settings_are_scored_on_the_same_trials(tiny: Path, tmp_path: Path) -> None:
    """Settings without a record on the study's trials are scored there before the
    comparison: the incumbent's objective is the controller's ratio with those settings over
    the paper preset, through the same evaluation loop."""
    folder = tmp_path / "chosen"
    incumbent = {"tuning": "pole_placement", "natural_frequency_T": 0.9, "los_radius_L": 5.0}
    _incumbent_file(folder, None, incumbent)
    (plan,) = plan_studies(str(tiny), out=tmp_path / "out", chosen_dir=folder)
    report = run_study(plan, n_trials=1)
    block = report["chosen"]["incumbent"]
    assert block["source"] == "scored" and block["settings"] == incumbent
    trials = validation_trials("validation", "nomoto2", 1)
    ratios = controller_ratios(
        "pid_los", {"preset": "paper", **incumbent}, trials, report["validation"]["oracle_costs"]
    )
    assert block["comparison"]["incumbent_value"] == pytest.approx(ratios[0], rel=1e-12)
    expect_written = report["chosen"]["incumbent"]["comparison"]["new_value"] <= ratios[0]
    assert report["chosen"]["written"] is expect_written


def test_the_packaged_records_reproduce_their_ratios() -> None:
    """A packaged chosen section's recorded validation ratios are what its settings score
    now (pid_los on nomoto2; the denominators from its report's oracle costs, of the oracle
    revision the record names).  A record of another oracle revision is not used for a
    promotion (the incumbent is scored again)."""
    from shipgym_baselines.tuning.promotion import incumbent_settings, recorded_ratios, revisions

    settings, summary = chosen_reader.section_record("pid_los", "nomoto2")
    config = load_tuning("pid_los")
    v = config.validation
    trials = validation_trials(v.distribution, "nomoto2", v.per_ship, config.ships)
    record = summary["validation"]
    recorded = [float(r) for r in record["ratios"]]
    assert geometric_mean(recorded) == pytest.approx(summary["value"])
    assert record["trials"] == [t.name for t in trials]
    current = all(record.get(k) == value for k, value in revisions().items())
    assert (recorded_ratios(summary, trials) is not None) == current
    report = json.loads((Path(__file__).parents[3] / summary["report"]).read_text())
    oracle = report["validation"]["oracle_costs"]
    now = controller_ratios("pid_los", incumbent_settings(config, settings), trials, oracle)
    assert now == pytest.approx(recorded, rel=1e-9)


def test_a_missing_extra_is_one_line_naming_the_install(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name, *a: None if name == "optuna" else real(name, *a)
    )
    assert main(["tune", "pid_los", "--out", str(tmp_path / "out")]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert 'pip install -e ".[tune]"' in line and "optuna" in line


# --- a study is continued only under the record it started with ----------------------------


def test_a_resumed_study_with_an_edited_config_is_refused(
    tiny: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Another fixed block or narrower ranges: refused in one line naming the keys, the
    study, its report and its chosen settings untouched; another budget alone resumes."""
    out, folder = tmp_path / "out", tmp_path / "chosen"
    where = ["--out", str(out), "--chosen-dir", str(folder)]
    assert main(["tune", str(tiny), *where, "--trials", "1"]) == 0
    report = (out / "nomoto2" / "tuning_report.json").read_bytes()
    written = _digests(folder)
    capsys.readouterr()
    edited = tmp_path / "edited.yaml"
    narrower = {**TINY["params"], "los_radius_L": {"low": 2.0, "high": 3.0}}
    for edit, keys in [
        ({"fixed": {"preset": "paper", "tuning": "vyshnegradsky"}}, "fixed.tuning"),
        ({"params": narrower}, "params.los_radius_L"),
        ({"fixed": {"preset": "paper"}, "params": narrower}, "fixed.tuning, params.los_radius_L"),
    ]:
        edited.write_text(yaml.safe_dump({**TINY, **edit}))
        assert main(["tune", str(edited), *where, "--resume", "--trials", "2"]) == 2
        (line,) = capsys.readouterr().err.strip().splitlines()
        said = "the config differs from the one study 'pid_los_tiny:nomoto2' started with: "
        assert f"{said}{keys} (restore it, or start a new study" in line, line
    assert (out / "nomoto2" / "tuning_report.json").read_bytes() == report
    assert _digests(folder) == written
    (plan,) = plan_studies(str(tiny), out=out)
    assert len(optuna.load_study(study_name=plan.study_name, storage=plan.storage).trials) == 1
    edited.write_text(yaml.safe_dump({**TINY, "budget": 9, "description": "more trials"}))
    assert main(["tune", str(edited), *where, "--resume", "--trials", "1"]) == 0


def test_a_study_keeps_its_record_and_one_without_is_not_resumed(tmp_path: Path) -> None:
    """A new study holds its record and the record's digest; a study made without one (by
    an older shipgym) is refused with advice rather than continued unchecked."""
    from shipgym_baselines.tuning.study import StudyPlan, record_digest, study_record

    config = TuningConfig.model_validate(TINY)
    plan = StudyPlan("toy", config, "nomoto2", tmp_path, f"sqlite:///{tmp_path}/a.db", "a")
    attrs = open_study(plan, resume=False).user_attrs
    record = study_record(plan)
    assert attrs["record"] == record and attrs["record_sha256"] == record_digest(record)
    assert record["fixed"] == TINY["fixed"] and record["ship"] == "nomoto2"
    assert record["validation_trials"][0].startswith("validation:0:10000:")
    assert "budget" not in record and "name" not in record
    old = StudyPlan("toy", config, "nomoto2", tmp_path, f"sqlite:///{tmp_path}/b.db", "b")
    optuna.create_study(study_name="b", storage=old.storage)  # no record
    with pytest.raises(RunError, match=r"has no record of the config it started with.*--out"):
        open_study(old, resume=True)


def test_the_chosen_settings_score_what_their_record_says(tmp_path: Path) -> None:
    """A trial wins (the default is poor): the chosen section is the best trial's settings as
    stored with it, and exactly those settings (over the paper preset they were scored from)
    score the recorded objective now.  A plan whose fixed block differs from the study's
    still writes the trial's own settings, never a mix of the two."""
    import dataclasses

    from shipgym_baselines.tuning.promotion import incumbent_settings
    from shipgym_baselines.tuning.study import Scorer, write_report

    file = tmp_path / "pid_los_tiny.yaml"
    file.write_text(
        yaml.safe_dump({**TINY, "default": {"preset": "paper", "natural_frequency_T": 0.5}})
    )
    (plan,) = plan_studies(str(file), out=tmp_path / "out", chosen_dir=tmp_path / "chosen")
    report = run_study(plan, n_trials=2)
    assert report["chosen"]["kept_default"] is False and report["chosen"]["written"]
    settings, summary = chosen_reader.section_record("pid_los", "nomoto2", tmp_path / "chosen")
    assert settings == {"tuning": "pole_placement", **report["best_params"]}
    trials = validation_trials("validation", "nomoto2", 1)
    oracle = report["validation"]["oracle_costs"]
    ratios = controller_ratios("pid_los", incumbent_settings(plan.config, settings), trials, oracle)
    assert geometric_mean(ratios) == pytest.approx(summary["value"], rel=1e-12)
    assert summary["best_value"] == summary["value"] == report["best_value"]
    other = plan.config.model_copy(update={"fixed": {"preset": "paper", "tuning": "vyshnegradsky"}})
    edited = dataclasses.replace(plan, config=other, chosen_dir=tmp_path / "again")
    study = optuna.load_study(study_name=plan.study_name, storage=plan.storage)
    again = write_report(edited, study, Scorer(edited))
    assert again["chosen"]["settings"] == settings


def test_a_second_process_on_a_study_is_refused_in_one_line(
    tiny: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """While another process holds a study's folder, ``tune`` and ``tune --resume`` on it
    are refused in one line naming the holder; nothing is added to the study."""
    out = tmp_path / "out"
    argv = ["tune", str(tiny), "--out", str(out), "--chosen-dir", str(tmp_path), "--trials", "1"]
    assert main(argv) == 0
    folder = out / "nomoto2"
    study = optuna.load_study(study_name="pid_los_tiny:nomoto2", storage=default_storage(folder))
    assert len(study.trials) == 1
    assert read_manifest(folder) >= {"study.db", "tuning_report.json", "manifest.txt"}
    capsys.readouterr()
    holder = hold(folder)
    try:
        for extra in (["--resume", "--trials", "2"], []):
            assert main([*argv, *extra]) == 2
            (line,) = capsys.readouterr().err.strip().splitlines()
            assert f"--out {folder} is in use by another run (process {holder.pid}," in line
    finally:
        holder.kill()
        holder.wait()
    assert len(study.trials) == 1


def test_a_study_created_meanwhile_by_another_process_is_one_line(
    tiny: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Two fresh studies on one storage at once: the second creation is refused in one
    line (not Optuna's DuplicatedStudyError)."""
    storage = f"sqlite:///{tmp_path / 'shared.db'}"
    (plan,) = plan_studies(str(tiny), out=tmp_path / "a", storage=storage, ship="nomoto2")
    open_study(plan, resume=False)
    monkeypatch.setattr(study_module, "study_exists", lambda plan: False)  # the race
    with pytest.raises(RunError, match=r"was just created in .* by another process"):
        open_study(plan, resume=False)


def test_a_link_in_a_study_folder_is_refused(tiny: Path, tmp_path: Path) -> None:
    """A study writes through no link: one planted in its folder is refused, named."""
    (plan,) = plan_studies(str(tiny), out=tmp_path / "out", chosen_dir=tmp_path)
    plan.folder.mkdir(parents=True)
    (plan.folder / "tuning_report.json").symlink_to(tmp_path / "elsewhere.json")
    with pytest.raises(RunError, match=r"tuning_report\.json is a symbolic link"):
        run_study(plan, n_trials=1)
    assert not (tmp_path / "elsewhere.json").exists()


def test_a_second_process_on_a_shared_storage_is_refused_in_one_line(
    tiny: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Two ``tune --resume`` on one study through one SQLite ``--storage``, each with its
    own ``--out``: both would draw the same trials.  While one holds the storage, the other
    is refused in one line naming it, and adds nothing to the study."""
    db = tmp_path / "shared.db"
    storage = f"sqlite:///{db}"
    argv = ["tune", str(tiny), "--ship", "nomoto2", "--storage", storage]
    argv += ["--chosen-dir", str(tmp_path / "chosen"), "--trials", "1"]
    assert main([*argv, "--out", str(tmp_path / "a")]) == 0
    with file_held_elsewhere(db, "--storage") as holder:
        capsys.readouterr()
        assert main([*argv, "--out", str(tmp_path / "b"), "--resume", "--trials", "2"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        (line,) = [x for x in err if x.startswith("shipgym tune: error: ")]  # one line
        assert f"--storage {db} is being written by another process (process {holder.pid}" in line
    study = optuna.load_study(study_name="pid_los_tiny:nomoto2", storage=storage)
    assert len(study.trials) == 1
    assert main([*argv, "--out", str(tmp_path / "b"), "--resume", "--trials", "2"]) == 0
    assert not (tmp_path / "shared.db.lock").exists()


@pytest.mark.parametrize("planted", ["link", "not chosen settings"])
def test_chosen_settings_that_cannot_be_written_are_refused_before_any_trial(
    planted: str, tiny: Path, tmp_path: Path
) -> None:
    """A link in place of the chosen file, or a file that is no chosen settings: refused
    in one line before the study's first trial (not after its last), the file untouched."""
    chosen_dir = tmp_path / "chosen"
    chosen_dir.mkdir()
    victim = tmp_path / "victim.yaml"
    victim.write_text("untouched\n")
    target = chosen_dir / "pid_los.yaml"
    if planted == "link":
        target.symlink_to(victim)
    else:
        target.write_text("untouched\n")
    (plan,) = plan_studies(str(tiny), out=tmp_path / "out", chosen_dir=chosen_dir)
    with pytest.raises(RunError, match=re.escape(str(target))) as refused:
        run_study(plan, n_trials=1)
    assert "\n" not in str(refused.value)
    assert victim.read_text() == "untouched\n" and not (plan.folder / "study.db").exists()
