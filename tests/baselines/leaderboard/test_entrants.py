"""What an entrant can do to a leaderboard run: report figures, fail to be made, fail in
``episode_stats``, hang, end its process, ignore the timeout.  None of it changes another
controller's score, the references are never judged as entrants, and the run always ends
with its record complete."""

from __future__ import annotations

import io
import json
import shutil
import sys
from pathlib import Path

import pytest

from shipgym_baselines import isolation
from shipgym_baselines.records.episodes import read_episodes
from shipgym_baselines.records.runrecord import read_run

#: the plug-ins: twins of one PID (an unregistered name: the same default tuning), one
#: claiming a cost; one whose figures are a list; one that cannot be made; one that hangs
PLUGINS = """
import os

import numpy as np

from shipgym_baselines.classical.pid import PIDLOS


class Twin(PIDLOS):
    name = "twin"


class Claims(PIDLOS):
    name = "claims"

    def episode_stats(self):
        return {"cost": 0.001, "termination_reason": "goal"}


class Listing(PIDLOS):
    name = "listing"

    def episode_stats(self):
        return [1.0, 2.0]


class Unbuildable(PIDLOS):
    name = "unbuildable"

    def __init__(self, **settings):
        if not os.environ.get("FIXED"):
            raise SystemExit("no licence for the solver")
        super().__init__(**settings)


class Hangs(PIDLOS):
    name = "hangs"

    def reset(self, context, seed=None):
        super().reset(context, seed=seed)
        self.calls = 0

    def act(self, obs, info):
        self.calls += 1
        while self.calls == 3 and not os.environ.get("FIXED"):
            pass  # computes forever
        return super().act(obs, info)


class EndsItsProcess(Hangs):
    name = "ends_its_process"

    def act(self, obs, info):
        self.calls += 1
        if self.calls == 3 and not os.environ.get("FIXED"):
            os._exit(0)
        return PIDLOS.act(self, obs, info)


class IgnoresTheSignal(Hangs):
    name = "ignores_the_signal"

    def act(self, obs, info):
        import signal

        self.calls += 1
        if self.calls == 3 and not os.environ.get("FIXED"):
            signal.signal(signal.SIGUSR2, signal.SIG_IGN)
            while True:
                pass
        return PIDLOS.act(self, obs, info)


class SwallowsEverything(Hangs):
    name = "swallows_everything"

    def act(self, obs, info):
        self.calls += 1
        while self.calls == 3 and not os.environ.get("FIXED"):
            try:
                while True:
                    pass
            except BaseException:
                pass
        return PIDLOS.act(self, obs, info)
"""
CLASSES = (
    "Twin",
    "Claims",
    "Listing",
    "Unbuildable",
    "Hangs",
    "EndsItsProcess",
    "IgnoresTheSignal",
    "SwallowsEverything",
)
#: a tiny limit: the computed oracle's calls take far longer, the PIDs' far less
ACT_TIMEOUT = "0.002"


def _suite(root: Path) -> Path:
    """A suite of one own scenario (so the oracle is computed, not read from its table),
    the plug-ins and the oracle, one seed."""
    scenario = Path(__file__).resolve().parents[3] / "configs" / "scenarios" / "rudder_aging.yaml"
    text = scenario.read_text().replace("name: rudder_aging", "name: mine")
    (root / "mine.yaml").write_text(text.replace("time_limit: 90.0", "time_limit: 60.0"))
    (root / "plugins.py").write_text(PLUGINS)
    controllers = ", ".join(f"plugins.py:{c}" for c in CLASSES)
    suite = root / "suite.yaml"
    suite.write_text(f"name: mine\nscenarios: [mine.yaml]\ncontrollers: [{controllers}, oracle]\n")
    return suite


def _argv(suite: Path, out: Path, *extra: str) -> list[str]:
    return [
        "leaderboard",
        "--suite",
        str(suite),
        "--seeds",
        "1",
        "--act-timeout",
        ACT_TIMEOUT,
        "--out",
        str(out),
        "--workers",
        "1",
        "--no-progress",
        *extra,
    ]


def _main(argv: list[str], monkeypatch: pytest.MonkeyPatch) -> tuple[int, str]:
    from shipgym_baselines.cli import main

    monkeypatch.delenv("SHIPGYM_QUIET", raising=False)
    stderr = io.StringIO()
    monkeypatch.setattr(sys, "stderr", stderr)
    code = main(argv)
    monkeypatch.undo()
    return code, stderr.getvalue()


@pytest.fixture(scope="module")
def entrants_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, str]:
    """The suite run once: (the suite file, the run folder, what stderr said).  A call
    that does not end when asked is killed 0.5 s after ten times the limit (not 5 s)."""
    root = tmp_path_factory.mktemp("entrants")
    suite = _suite(root)
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv("FIXED", raising=False)
        mp.setattr(isolation, "GRACE_S", 0.5)
        code, stderr = _main(_argv(suite, root / "out"), mp)
    assert code == 0, stderr
    return suite, root / "out", stderr


def _episodes(out: Path) -> dict[str, dict]:
    """Each controller's episode of the suite's scenario (not of its no-change twin)."""
    scenarios = json.loads((out / "run.json").read_text())["suite"]["scenarios"]
    return {e["controller"]: e for e in read_episodes(out) if e["scenario"] in scenarios}


def _ratios(out: Path) -> dict[str, float]:
    board = json.loads((out / "aggregate.json").read_text())
    return {row["controller"]: row["cost_ratio_iqm"] for row in board}


def test_a_plugin_that_claims_a_cost_ranks_as_its_twin(entrants_run: tuple) -> None:
    _, out, _ = entrants_run
    episodes = _episodes(out)
    assert episodes["claims"]["controller_stats"] == {"cost": 0.001, "termination_reason": "goal"}
    assert episodes["claims"]["cost"] == episodes["twin"]["cost"] > 1.0
    ratios = _ratios(out)
    assert ratios["claims"] == ratios["twin"] > 1.0


def test_the_oracle_is_never_timed_out_as_an_entrant(entrants_run: tuple) -> None:
    """Computed afresh under a 2 ms limit (its solver's calls take longer), the oracle's
    episode is its own, so the ratios are against its true cost."""
    _, out, _ = entrants_run
    episodes = _episodes(out)
    assert episodes["oracle"]["termination_reason"] == "goal"
    assert _ratios(out)["twin"] == pytest.approx(
        episodes["twin"]["cost"] / episodes["oracle"]["cost"]
    )


def test_figures_that_are_a_list_are_left_out_and_the_run_completes(entrants_run: tuple) -> None:
    _, out, stderr = entrants_run
    listing = _episodes(out)["listing"]
    assert listing["termination_reason"] == "goal" and "controller_stats" not in listing
    assert listing["stats_error"] == "episode_stats() is a list, not a mapping of names to numbers"
    assert "shipgym: listing's episode_stats() is a list" in stderr
    assert read_run(out)["status"] == "complete"


def test_a_plugin_that_cannot_be_made_fails_every_trial(entrants_run: tuple) -> None:
    _, out, stderr = entrants_run
    unbuildable = _episodes(out)["unbuildable"]
    assert unbuildable["termination_reason"] == "controller_error"
    assert unbuildable["error"] == (
        "the controller could not be made: SystemExit: no licence for the solver"
    )
    assert "shipgym: unbuildable failed on mine seed 10000" in stderr


def test_a_hanging_act_ends_its_episode_and_the_run_finishes(entrants_run: tuple) -> None:
    _, out, _ = entrants_run
    hangs = _episodes(out)["hangs"]
    assert (hangs["termination_reason"], hangs["steps"]) == ("controller_timeout", 3)
    assert hangs["error"].startswith("the call ran ")
    record = read_run(out)
    assert record["status"] == "complete" and record["act_timeout"] == float(ACT_TIMEOUT)


def test_a_plugin_that_ends_its_process_fails_its_episodes_and_the_run_finishes(
    entrants_run: tuple,
) -> None:
    """``os._exit(0)`` inside ``act``: the plug-in plays in a process of its own, so only
    its episodes fail, named; the run and the other controllers go on."""
    _, out, stderr = entrants_run
    ended = _episodes(out)["ends_its_process"]
    assert ended["termination_reason"] == "controller_error" and ended["steps"] == 1
    assert ended["error"] == "the controller's process ended with exit code 0"
    assert "shipgym: ends_its_process failed on mine seed 10000" in stderr
    assert read_run(out)["status"] == "complete"
    assert _episodes(out)["twin"]["termination_reason"] == "goal"


@pytest.mark.parametrize("name", ["ignores_the_signal", "swallows_everything"])
def test_a_call_that_will_not_end_has_its_process_killed(entrants_run: tuple, name: str) -> None:
    """A call that ignores the watchdog's signal, or catches the timeout and goes on: its
    process is killed once it outlives ten times the limit (and a grace), its episodes
    fail as controller_timeout, and the run finishes."""
    _, out, _ = entrants_run
    episode = _episodes(out)[name]
    assert episode["termination_reason"] == "controller_timeout"
    assert episode["error"] == (
        "the call had not returned after 0.52 s, 10 times the limit of 0.002 s and 0.5 s "
        "more, nor ended when asked: its process was killed"
    )
    assert read_run(out)["status"] == "complete"


def test_resume_after_the_fix_runs_the_failed_entrants_again(
    entrants_run: tuple, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    suite, source, _ = entrants_run
    out = tmp_path / "out"
    shutil.copytree(source, out)
    monkeypatch.setenv("FIXED", "1")
    code, _ = _main(_argv(suite, out, "--resume", "--retry-failed"), monkeypatch)
    assert code == 0 and read_run(out)["status"] == "complete"
    episodes = _episodes(out)
    for name in ("unbuildable", "hangs", "ends_its_process", "ignores_the_signal"):
        assert episodes[name]["termination_reason"] == "goal", name


def test_resume_under_another_limit_is_refused_in_one_line(
    entrants_run: tuple, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys
) -> None:
    from shipgym_baselines.cli import main

    suite, source, _ = entrants_run
    out = tmp_path / "out"
    shutil.copytree(source, out)
    argv = _argv(suite, out, "--resume")
    argv[argv.index(ACT_TIMEOUT)] = "0.5"
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        f"shipgym leaderboard: error: --resume: {out / 'run.json'} judged its controllers "
        f"with --act-timeout {ACT_TIMEOUT} s, not 0.5 s: resume with --act-timeout "
        f"{ACT_TIMEOUT}, or use --force to start afresh"
    )
    assert read_run(out)["status"] == "complete"
