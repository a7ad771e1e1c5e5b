"""shipgym_baselines.references: the shipped table covers the validation split; computed
references are kept once per user (shipped table → user cache → computed and stored), and
a computation is announced on stderr."""

from __future__ import annotations

import gzip
import json
import multiprocessing
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from shipgym.scenarios import Scenario, load_scenario
from shipgym_baselines import evaluation, leaderboard, references
from shipgym_baselines.errors import RunError
from shipgym_baselines.evaluation import EpisodeResult
from shipgym_baselines.leaderboard import Job, announce_references, reference_work, trials
from shipgym_baselines.references import (
    ORACLE_CPU_S_PER_STEP,
    ReferenceCache,
    ReferenceTable,
    entry_key,
    estimate_cpu_s,
    shipped_table,
    user_cache_path,
)
from shipgym_baselines.tuning.validation import oracle_costs, validation_trials

#: these tests read the notice lines, which the suite silences
pytestmark = pytest.mark.usefixtures("loud")


def test_the_shipped_table_holds_every_validation_trial() -> None:
    """``shipgym tune`` scores on these 32 trials: none is computed on first use."""
    table = shipped_table()
    held = [t.name for t in validation_trials() if table.lookup(t.scenario, t.seed) is not None]
    assert held == [t.name for t in validation_trials()] and len(held) == 32


def test_the_references_command_counts_the_validation_trials_as_held(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--validation`` alone: the validation split's trials only (no suite), all held by
    a copy of the shipped table, so nothing is computed and the file is unchanged."""
    from shipgym_baselines.cli import main

    table = tmp_path / "copy.json.gz"
    table.write_bytes(references.table_path().read_bytes())
    assert main(["references", "--validation", "--table", str(table), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert (summary["computed"], summary["held"], summary["table"]) == (0, 32, str(table))
    assert table.read_bytes() == references.table_path().read_bytes()


# --- the per-user cache ----------------------------------------------------------------------


def test_the_cache_lives_where_the_environment_says(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, user_cache: Path
) -> None:
    """``$SHIPGYM_CACHE_DIR`` (a temporary folder in every test), else
    ``$XDG_CACHE_HOME/shipgym``, else ``~/.cache/shipgym``."""
    assert user_cache_path() == user_cache / "references" / "oracle.json.gz"
    assert ReferenceCache().path == user_cache_path()
    monkeypatch.delenv("SHIPGYM_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert user_cache_path() == tmp_path / "shipgym" / "references" / "oracle.json.gz"


class CountingOracle:
    """A stand-in for :func:`~shipgym_baselines.evaluation.evaluate` that counts its runs;
    its cost is 1 + the seed / 10⁵."""

    def __init__(self) -> None:
        self.runs: list[tuple[str, int]] = []

    def __call__(self, controller: Any, scenario: Scenario, seeds: list[int], **_: Any) -> list:
        (seed,) = seeds
        self.runs.append((scenario.name, seed))
        t = np.arange(3.0)
        return [
            EpisodeResult(
                controller="oracle",
                kind="reference",
                scenario=scenario.name,
                seed=seed,
                metrics={"cost": 1 + seed / 1e5, "termination_reason": "goal"},
                trajectory={"t": t, "x": t, "y": t},
            )
        ]


@pytest.fixture
def oracle(monkeypatch: pytest.MonkeyPatch) -> CountingOracle:
    """No shipped references, and the oracle's runs counted instead of run."""
    counting = CountingOracle()
    monkeypatch.setattr(evaluation, "evaluate", counting)
    monkeypatch.setattr(
        references, "shipped_table", lambda reference="oracle": ReferenceTable({}, None, reference)
    )
    return counting


def test_a_second_study_reads_the_cache(
    oracle: CountingOracle, capsys: pytest.CaptureFixture[str], user_cache: Path
) -> None:
    """The first computes (announced: how many, ≈ CPU, where cached) and stores; a second
    study, of any --out, reads the user cache and says nothing."""
    chosen = validation_trials(ship="nomoto2", per_ship=2)
    first = oracle_costs(chosen)
    assert len(oracle.runs) == 2 and first == [1 + t.seed / 1e5 for t in chosen]
    out, err = capsys.readouterr()
    assert out == ""
    cached = user_cache / "references" / "oracle.json.gz"
    estimate = references.duration(estimate_cpu_s([t.scenario for t in chosen]))
    assert (
        f"shipgym: computing 2 oracle references (≈ {estimate} CPU; once: cached in {cached})\n"
        in err
    )
    assert oracle_costs(chosen) == first and len(oracle.runs) == 2
    assert capsys.readouterr().err == ""
    assert set(ReferenceTable.load(cached).entries) == {
        entry_key(t.scenario, t.seed) for t in chosen
    }


def test_a_cache_of_another_revision_is_ignored_and_replaced(
    oracle: CountingOracle, user_cache: Path
) -> None:
    (trial,) = validation_trials(ship="mariner", per_ship=1)
    cached = user_cache_path()
    stale = ReferenceTable({entry_key(trial.scenario, trial.seed): {"metrics": {"cost": 9.0}}})
    stale.save(cached)
    with gzip.open(cached, "rt") as f:
        data = json.load(f)
    data["oracle"]["revision"] = -1
    with gzip.open(cached, "wt") as f:
        json.dump(data, f)
    assert oracle_costs([trial]) == [1 + trial.seed / 1e5] and len(oracle.runs) == 1
    assert ReferenceTable.load(cached).lookup(trial.scenario, trial.seed) is not None


def test_an_unreadable_cache_is_named(oracle: CountingOracle) -> None:
    cached = user_cache_path()
    cached.parent.mkdir(parents=True)
    cached.write_bytes(b"not gzip")
    with pytest.raises(RunError, match=f"reference cache {cached} is unreadable.*delete it"):
        oracle_costs(validation_trials(ship="nomoto2", per_ship=1))


def _store(args: tuple[str, list[int]]) -> None:
    """Store one fake reference per seed in the cache at ``path`` (a worker)."""
    path, seeds = args
    scenario, cache = load_scenario("nominal"), ReferenceCache(path)
    for seed in seeds:
        cache.store(scenario, CountingOracle()(None, scenario, [seed])[0])


def test_concurrent_stores_keep_every_entry(tmp_path: Path) -> None:
    """Four processes storing at once: each store re-reads and merges under the lock, so
    no entry is lost.  Spawned, not forked: a fork of a test process that ran Ray or torch
    threads may inherit a held lock and hang."""
    path = str(tmp_path / "refs.json.gz")
    work = [(path, list(range(k, 40, 4))) for k in range(4)]
    with multiprocessing.get_context("spawn").Pool(4) as pool:
        pool.map_async(_store, work).get(timeout=300)
    scenario = load_scenario("nominal")
    table = ReferenceTable.load(path)
    assert set(table.entries) == {entry_key(scenario, seed) for seed in range(40)}


# --- the leaderboard -------------------------------------------------------------------------


def _oracle_jobs(references: str = "table") -> list[Job]:
    return [Job("oracle", "nominal", (seed,), references=references) for seed in (5, 6)]


def test_the_leaderboard_computes_a_missing_reference_once_per_user(
    oracle: CountingOracle, capsys: pytest.CaptureFixture[str]
) -> None:
    """A trial neither table holds is announced, computed, stored; the next run reads it."""
    jobs = _oracle_jobs()
    announce_references(jobs)
    assert "shipgym: computing 2 oracle references (≈ " in capsys.readouterr().err
    first = [r for job in jobs for r in reference_work(job)]
    assert len(oracle.runs) == 2
    announce_references(jobs)
    assert capsys.readouterr().err == ""
    again = [r for job in jobs for r in reference_work(job)]
    assert len(oracle.runs) == 2
    assert [r.metrics["cost"] for r in again] == [r.metrics["cost"] for r in first]
    assert {r.kind for r in again} == {"reference"}


def test_recomputed_references_are_all_announced(
    oracle: CountingOracle, capsys: pytest.CaptureFixture[str]
) -> None:
    jobs = [*_oracle_jobs("recompute"), Job("pid_los", "nominal", (5, 6))]
    announce_references(jobs)
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith("shipgym: computing 2 oracle references (≈ ")
    assert "--recompute-references" in line
    (result,) = leaderboard.work(jobs[0])  # run, neither read from nor stored in the cache
    assert result.metrics["cost"] == 1 + 5 / 1e5 and len(oracle.runs) == 1
    assert not user_cache_path().exists()


def test_the_estimate_is_steps_times_the_ships_measured_rate() -> None:
    """The ships' rates are measured (positive); a trial at its full length."""
    assert set(ORACLE_CPU_S_PER_STEP) == {"nomoto2", "esso_osaka", "mariner", "blanke"}
    assert all(rate > 0 for rate in ORACLE_CPU_S_PER_STEP.values())
    (trial,) = trials(Job("oracle", "mariner_track", (0,)))
    steps = trial.config.time_limit / trial.control_period
    assert estimate_cpu_s([trial]) == pytest.approx(steps * ORACLE_CPU_S_PER_STEP["mariner"])
