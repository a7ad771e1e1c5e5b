"""A run of chosen controllers is ranked against the references added to it
(shipgym_baselines.scoring.comparison): a plug-in gets a cost ratio and a rank,
``--no-references`` none (and the message names how to get one), the oracle alone has
nothing to rank."""

from __future__ import annotations

import io
import json
import math
import sys
from pathlib import Path

import pytest
import yaml

from shipgym_baselines.cli import main
from shipgym_baselines.records.episodes import read_episodes
from shipgym_baselines.records.runrecord import read_run
from shipgym_baselines.scoring.comparison import (
    REFERENCES,
    comparison_note,
    references_record,
    suite_folder,
    with_references,
)
from shipgym_baselines.scoring.ranking import NO_RANKING, NOTHING_TO_RANK
from shipgym_baselines.suite import load_suite

#: a user's controller, as docs/plugins.md enters one
POLICY_FILE = """
import numpy as np


class Steer:
    name = "steer"
    kind = "classical"

    def reset(self, context, seed=None):
        pass

    def act(self, obs, info):
        rudder = -2.0 * (obs[0] + obs[1]) - 4.0 * obs[3]
        return np.clip(np.array([rudder], dtype=np.float32), -1.0, 1.0)
"""


@pytest.fixture(scope="module")
def steer(tmp_path_factory: pytest.TempPathFactory) -> str:
    file = tmp_path_factory.mktemp("user") / "steer.py"
    file.write_text(POLICY_FILE)
    return f"{file}:Steer"


@pytest.fixture(scope="module")
def one_scenario(tmp_path_factory: pytest.TempPathFactory) -> str:
    """The smoke suite's trials of one scenario (the oracle's in the shipped table)."""
    smoke = load_suite("smoke")
    file = tmp_path_factory.mktemp("suite") / "one.yaml"
    suite = {
        "name": "one",
        "scenarios": ["rudder_aging"],
        "controllers": ["pid_los", "zero_rudder", "oracle"],
        "seeds": 2,
        "randomize": smoke.randomize.model_dump(mode="json"),
    }
    file.write_text(yaml.safe_dump(suite))
    return str(file)


def _run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[str, str]:
    assert main([*argv, "--no-progress", "--workers", "1"]) == 0
    captured = capsys.readouterr()
    return captured.out, captured.err


@pytest.fixture(scope="module")
def evaluated(steer: str, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str, str]:
    """``shipgym evaluate steer.py:Steer --suite smoke``: (its folder, stdout, stderr), with
    the progress bar."""
    out = tmp_path_factory.mktemp("evaluated") / "steer"
    with pytest.MonkeyPatch.context() as mp:
        stdout, stderr = io.StringIO(), io.StringIO()
        mp.setattr(sys, "stdout", stdout)
        mp.setattr(sys, "stderr", stderr)
        mp.delenv("SHIPGYM_QUIET", raising=False)  # with the notice lines
        argv = ["evaluate", steer, "--suite", "smoke", "--out", str(out)]
        assert main([*argv, "--workers", "1"]) == 0  # with its progress bar
    return out, stdout.getvalue(), stderr.getvalue()


def test_a_plugin_evaluated_on_smoke_gets_a_cost_ratio_and_a_rank(
    evaluated: tuple[Path, str, str],
) -> None:
    out, stdout, _ = evaluated
    suite = read_run(out)["suite"]
    assert [c["name"] for c in suite["controllers"]] == ["steer", *REFERENCES]
    assert suite["references"]["added"] == list(REFERENCES)
    board = json.loads((out / "aggregate.json").read_text())
    assert {r["controller"] for r in board} == {"steer"}  # the references are not ranked
    for row in board:
        assert math.isfinite(row["cost_ratio_iqm"]) and row["cost_ratio_iqm"] > 0
    assert "| 1 | steer | classical |" in stdout
    head = (out / "leaderboard.md").read_text().split("## Cost ratio per scenario")[0]
    assert "| 1 | steer | classical |" in head
    assert "P(improvement over" not in head + stdout  # no pid_los in the run
    for text in (stdout, head):
        assert (
            "Ranked against the references only "
            "(`oracle`, `oracle_frozen`, `zero_rudder`, `random`)" in text
        )
        # the command that compares with the suite's other controllers
        assert (
            "shipgym leaderboard --suite smoke --controllers nmpc_lambda_lssvm pid_los ppo" in text
        )
        assert f"shipgym report results/smoke {out}" in text
    page = (out / "leaderboard.html").read_text()
    assert 'id="ranked-against"' in page
    assert "Ranked against the references only (oracle, oracle_frozen, zero_rudder, random)" in page
    episodes = read_episodes(out)
    assert {e["controller"] for e in episodes} == {"steer", *REFERENCES}


def test_the_leaderboard_announces_its_time_before_the_first_episode(
    evaluated: tuple[Path, str, str],
) -> None:
    out, _, stderr = evaluated
    # the first line but a cold cache's compilations (each announced on its own line)
    first = next(x for x in stderr.splitlines() if not x.startswith("shipgym: compiling"))
    # smoke: 3 scenarios × 2 seeds × 5 controllers (the references' read from their tables),
    # and the no-change twins of its 2 changing scenarios × 2 seeds × steer and the oracle
    suite = read_run(out)["suite"]
    assert list(suite["twin_scenarios"]) == ["twin:rudder_aging", "twin:heldout:0"]
    assert suite["twin_players"] == ["steer", "oracle"]
    episodes = 3 * 2 * 5 + 2 * 2 * 2
    assert first.startswith(f"leaderboard: {episodes} episodes on 1 worker, about ")
    assert len(read_episodes(out)) == episodes
    assert first.endswith(
        " (recorded costs; one-off C compilations on a new machine come on top, each announced)"
    )
    # after the episodes, the tables' wait is announced too
    assert "shipgym: writing the tables, ranking and figures of 3 scenarios (about " in stderr


def test_no_references_gives_no_ranking_and_says_how_to_get_one(
    steer: str, one_scenario: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "mine"
    argv = ["evaluate", steer, "--suite", one_scenario, "--out", str(out), "--no-references"]
    stdout, _ = _run(argv, capsys)
    assert [c["name"] for c in read_run(out)["suite"]["controllers"]] == ["steer"]
    assert "references" not in read_run(out)["suite"]
    assert json.loads((out / "aggregate.json").read_text()) == []
    for text in (stdout, (out / "leaderboard.md").read_text()):
        assert NO_RANKING in text
        assert "without `--no-references`" in text and "`--controllers`" in text
        assert "Ranked against" not in text
    page = (out / "leaderboard.html").read_text()
    assert "No ranking" in page and "--no-references" in page


def test_the_oracle_alone_has_nothing_to_rank(
    one_scenario: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "oracle"
    argv = ["leaderboard", "--suite", one_scenario, "--controllers", "oracle", "--out", str(out)]
    stdout, _ = _run([*argv, "--no-references"], capsys)
    assert json.loads((out / "scenario_scores.json").read_text())  # its episodes are there
    for text in (stdout, (out / "leaderboard.md").read_text()):
        assert NOTHING_TO_RANK in text
        assert "has none" not in text and "no episodes of" not in text
    assert "Nothing to rank" in (out / "leaderboard.html").read_text()


def test_evaluate_runs_merge_into_one_ranking_reading_the_references_once(
    steer: str, one_scenario: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Two ``evaluate`` runs hold the same reference episodes: ``report`` reads them once."""
    folders = []
    for policy in (steer, "pid_los"):
        folders.append(tmp_path / policy.rpartition(":")[2].lower())
        _run(["evaluate", policy, "--suite", one_scenario, "--out", str(folders[-1])], capsys)
    note = (folders[1] / "leaderboard.md").read_text()
    # pid_los is the suite's one competitor: nothing of the suite is left out
    assert (
        "References added for the cost ratio: `oracle`, `oracle_frozen`, `zero_rudder`, `random`"
        in note
    )
    assert "Ranked against" not in note
    assert main(["report", *map(str, folders), "--out", str(tmp_path / "both")]) == 0
    capsys.readouterr()
    board = json.loads((tmp_path / "both" / "aggregate.json").read_text())
    assert sorted(r["controller"] for r in board) == ["pid_los", "steer"]
    assert "P(improvement over pid_los)" in (tmp_path / "both" / "leaderboard.md").read_text()
    assert "Ranked against" not in (tmp_path / "both" / "leaderboard.md").read_text()


def test_with_references_adds_those_missing_in_order() -> None:
    assert with_references(["pid_los"]) == (["pid_los", *REFERENCES], list(REFERENCES))
    names, added = with_references(["random", "pid_los", "oracle"])
    assert names == ["random", "pid_los", "oracle", "oracle_frozen", "zero_rudder"]
    assert added == ["oracle_frozen", "zero_rudder"]
    assert with_references(list(REFERENCES)) == (list(REFERENCES), [])


def _suite(record: dict, competitors: list[str]) -> dict:
    kinds = [(c, "classical") for c in competitors] + [(r, "reference") for r in REFERENCES]
    return {"controllers": [{"name": c, "kind": k} for c, k in kinds], "references": record}


def test_the_note_says_what_the_run_is_ranked_against() -> None:
    quick = ["pid_los", "lqr", "oracle", "zero_rudder", "random"]
    mine = references_record("quick", quick, ["mine.py:Ctrl"], list(REFERENCES))
    note = comparison_note(_suite(mine, ["Ctrl"]), "results/evaluate/quick/Ctrl")
    assert note.startswith(
        "Ranked against the references only (`oracle`, `oracle_frozen`, `zero_rudder`, "
    )
    assert "not against the suite's other controllers (2)" in note
    assert "`shipgym leaderboard --suite quick --controllers pid_los lqr mine.py:Ctrl`" in note
    assert (
        "`shipgym report results/quick results/evaluate/quick/Ctrl --out "
        "results/quick_with_Ctrl`" in note
    )
    two = references_record("quick", quick, ["pid_los", "mine.py:Ctrl"], list(REFERENCES))
    note = comparison_note(_suite(two, ["pid_los", "Ctrl"]))
    assert note.startswith("Ranked among this run's 2 controllers and against the references")
    assert "--controllers lqr pid_los mine.py:Ctrl`." in note and "report" not in note
    # the suite's own controllers: the references it lacks are named, nothing is left out
    whole = references_record("my.yaml", ["pid_los"], None, list(REFERENCES))
    assert comparison_note(_suite(whole, ["pid_los"])) == (
        "References added for the cost ratio: `oracle`, `oracle_frozen`, `zero_rudder`, `random` "
        "(`--no-references`: none)."
    )
    assert comparison_note(_suite(references_record("quick", quick, None, []), ["x"])) == ""
    assert comparison_note({"controllers": []}) == ""  # a report's merged suite, old records


def test_each_suite_has_its_own_default_folder() -> None:
    assert suite_folder("quick") == Path("results/quick")
    assert suite_folder("suites/my_suite.yaml") == Path("results/my_suite")


def test_a_run_started_without_the_references_resumes_without_them(
    one_scenario: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A run of an earlier version (or ``--no-references``) is finished as it was started."""
    from shipgym_baselines.leaderboard.run import run_leaderboard

    out, given = tmp_path / "before", ["pid_los", "zero_rudder", "oracle"]
    run_leaderboard(one_scenario, 1, out, workers=1, show_progress=False, controllers=given)
    before = read_run(out)["suite"]
    argv = ["leaderboard", "--suite", one_scenario, "--seeds", "1", "--out", str(out)]
    _run([*argv, "--controllers", *given, "--resume"], capsys)
    assert read_run(out)["suite"] == before and "references" not in before
    assert {e["controller"] for e in read_episodes(out)} == set(given)  # no random


def test_a_suite_of_your_own_without_the_oracle_gets_it_and_a_ranking(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A suite file that lists no reference: the run adds them (the oracle from its table) and
    ranks the suite's controller, saying so; --no-references runs the suite as listed."""
    smoke = load_suite("smoke")
    file = tmp_path / "mine.yaml"
    suite = {
        "name": "mine",
        "scenarios": ["rudder_aging"],
        "controllers": ["pid_los"],
        "seeds": 1,
        "randomize": smoke.randomize.model_dump(mode="json"),
    }
    file.write_text(yaml.safe_dump(suite))
    out, _ = _run(["leaderboard", "--suite", str(file), "--out", str(tmp_path / "a")], capsys)
    assert "| 1 | pid_los | classical |" in out
    assert (
        "References added for the cost ratio: `oracle`, `oracle_frozen`, `zero_rudder`, `random`"
        in out
    )
    assert read_run(tmp_path / "a")["suite"]["references"]["added"] == list(REFERENCES)
    argv = ["leaderboard", "--suite", str(file), "--out", str(tmp_path / "b")]
    out, _ = _run([*argv, "--no-references"], capsys)
    assert "No ranking" in out
    assert {e["controller"] for e in read_episodes(tmp_path / "b")} == {"pid_los"}


def test_chosen_controllers_get_a_folder_of_their_own() -> None:
    """--controllers never writes into the suite's folder: one folder per set of controllers."""
    from shipgym_baselines.cli.leaderboard import FOLDER_NAME_MAX, evaluate_folder

    assert evaluate_folder(["pid_los", "lqr"], "smoke") == Path(
        "results/evaluate/smoke/pid_los+lqr"
    )
    assert evaluate_folder("pid_los", "suites/my.yaml") == Path("results/evaluate/my/pid_los")
    many = ["pid_los", "pid_vf", "pid_tvvf", "pid_lookahead_los", "lqr", "adaptive_lqr"]
    many += ["l1_backstepping", "adaptive_backstepping", "nmpc", "nmpc_lambda_lssvm"]
    name = evaluate_folder(many, "quick").name
    assert len(name) == FOLDER_NAME_MAX and name != evaluate_folder(many[:-1], "quick").name
