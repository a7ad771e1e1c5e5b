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

from shipgym.scenarios.loader import Scenario, load_scenario
from shipgym_baselines import evaluation, references
from shipgym_baselines.errors import RunError
from shipgym_baselines.leaderboard.jobs import (
    Job,
    announce_references,
    reference_work,
    trials,
    work,
)
from shipgym_baselines.records.episodes import EpisodeLabel, EpisodeResult
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
from tests.baselines.records.conftest import file_held_elsewhere

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

    def __call__(
        self,
        controller: Any,
        scenario: Scenario,
        seeds: list[int],
        label: EpisodeLabel | None = None,
        **_: Any,
    ) -> list:
        (seed,) = seeds
        self.runs.append((scenario.name, seed))
        t = np.arange(3.0)
        return [
            EpisodeResult(
                controller="oracle" if label is None else label.controller,
                kind="reference",
                scenario=scenario.name if label is None else label.scenario,
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


@pytest.mark.parametrize("damage", ["truncated", "not gzip", "no table"])
def test_an_unreadable_cache_is_set_aside_and_named(
    oracle: CountingOracle, capsys: pytest.CaptureFixture[str], damage: str
) -> None:
    """A cache cut short, not gzip, or gzip of no table: moved to ``<file>.bad``
    with one line naming it, and the cache starts afresh (the reference computed again)."""
    cached = user_cache_path()
    (trial,) = validation_trials(ship="nomoto2", per_ship=1)
    scenario = load_scenario("nominal")
    cache = ReferenceCache(cached)
    for seed in range(3):
        cache.store(scenario, CountingOracle()(None, scenario, [seed])[0])
    if damage == "truncated":
        cached.write_bytes(cached.read_bytes()[: cached.stat().st_size // 2])
    else:
        cached.write_bytes(gzip.compress(b"[]") if damage == "no table" else b"not gzip")
    damaged = cached.read_bytes()
    capsys.readouterr()
    assert oracle_costs([trial]) == [1 + trial.seed / 1e5] and len(oracle.runs) == 1
    bad = references.set_aside_path(cached)
    (line,) = [x for x in capsys.readouterr().err.splitlines() if "unreadable" in x]
    assert line.startswith(f"shipgym: the reference cache {cached} is unreadable (")
    assert line.endswith(f"): set aside as {bad}; its references are computed again when needed")
    assert bad.read_bytes() == damaged
    assert set(ReferenceTable.load(cached).entries) == {entry_key(trial.scenario, trial.seed)}


def test_a_link_in_place_of_the_cache_is_not_written_through(
    oracle: CountingOracle, tmp_path: Path
) -> None:
    """A store replaces no file that a link in the cache's place points to: refused."""
    cached = user_cache_path()
    cached.parent.mkdir(parents=True)
    victim = tmp_path / "victim.json.gz"
    ReferenceTable({}).save(victim)
    before = victim.read_bytes()
    cached.symlink_to(victim)
    with pytest.raises(RunError, match=f"{cached} is a symbolic link"):
        oracle_costs(validation_trials(ship="nomoto2", per_ship=1))
    assert victim.read_bytes() == before and cached.is_symlink()


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
    (result,) = work(jobs[0])  # run, neither read from nor stored in the cache
    assert result.metrics["cost"] == 1 + 5 / 1e5 and len(oracle.runs) == 1
    assert not user_cache_path().exists()


def test_the_estimate_is_steps_times_the_ships_measured_rate() -> None:
    """The ships' rates are measured (positive); a trial at its full length."""
    assert set(ORACLE_CPU_S_PER_STEP) == {"nomoto2", "esso_osaka", "mariner", "blanke"}
    assert all(rate > 0 for rate in ORACLE_CPU_S_PER_STEP.values())
    (trial,) = trials(Job("oracle", "mariner_track", (0,)))
    steps = trial.config.time_limit / trial.control_period
    assert estimate_cpu_s([trial]) == pytest.approx(steps * ORACLE_CPU_S_PER_STEP["mariner"])


# --- shipgym references: where it writes, and never over a table of another revision -------


def _tiny_suite(folder: Path) -> Path:
    """A suite of one trial: ``nominal`` on one seed."""
    import yaml

    suite = folder / "tiny.yaml"
    suite.write_text(
        yaml.safe_dump(
            {"name": "tiny", "scenarios": ["nominal"], "controllers": ["oracle"], "seeds": 1}
        )
    )
    return suite


def _foreign_table(file: Path, entries: int) -> bytes:
    """A table of ``entries`` entries under env revision -1 at ``file``; returns its bytes."""
    scenario = load_scenario("nominal")
    table = ReferenceTable(
        {entry_key(scenario, s): {"metrics": {"cost": 9.0}} for s in range(entries)}
    )
    table.save(file)
    with gzip.open(file, "rt") as f:
        data = json.load(f)
    data["env_revision"] = -1
    with gzip.open(file, "wt") as f:
        json.dump(data, f)
    return file.read_bytes()


def test_a_table_of_another_revision_is_refused_unless_replace(
    oracle: CountingOracle, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Refused in one line naming the file and what differs, the file byte-identical and no
    ``.bak``; ``--replace`` keeps the old bytes as ``FILE.bak`` and fills the file afresh; a
    second ``--replace`` on the now current table touches no ``.bak``; an existing ``.bak``
    of other bytes is never overwritten."""
    from shipgym.envs.core import ENV_REVISION
    from shipgym_baselines.cli import main

    table = tmp_path / "mine.json.gz"
    old = _foreign_table(table, 5)
    argv = ["references", "--suite", str(_tiny_suite(tmp_path)), "--table", str(table)]
    argv += ["--workers", "1"]
    assert main(argv) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert str(table) in line and f"env_revision -1, not {ENV_REVISION}" in line
    assert "--replace" in line
    assert table.read_bytes() == old and not references.backup_path(table).exists()
    assert oracle.runs == []  # refused before any work
    assert main([*argv, "--replace"]) == 0
    assert references.backup_path(table) == tmp_path / "mine.json.gz.bak"
    assert references.backup_path(table).read_bytes() == old
    assert references.foreign(table) is None
    assert list(ReferenceTable.load(table).entries) == [entry_key(load_scenario("nominal"), 10000)]
    assert main([*argv, "--replace"]) == 0 and len(oracle.runs) == 1  # held now
    assert references.backup_path(table).read_bytes() == old
    other = tmp_path / "other.json.gz"
    old = _foreign_table(other, 2)
    references.backup_path(other).write_bytes(b"an older backup")
    argv[argv.index(str(table))] = str(other)
    capsys.readouterr()
    assert main([*argv, "--replace"]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert f"{other}.bak, which exists" in line
    assert other.read_bytes() == old
    assert references.backup_path(other).read_bytes() == b"an older backup"


def test_a_file_that_is_no_table_is_refused_naming_it(tmp_path: Path) -> None:
    """Not gzip, or a table of the other reference: refused unless replaced."""
    notes = tmp_path / "notes.json.gz"
    notes.write_text("my notes")
    assert (references.foreign(notes) or "").startswith("no reference table (")
    with pytest.raises(RunError, match=r"notes\.json\.gz holds no reference table \("):
        references.fill_tables({"oracle": notes})
    assert notes.read_text() == "my notes"
    frozen = tmp_path / "frozen.json.gz"
    ReferenceTable({}, frozen, "oracle_frozen").save()
    assert "reference oracle_frozen, not oracle" in (references.foreign(frozen) or "")
    assert references.foreign(tmp_path / "absent.json.gz") is None


def _digest(file: Path) -> str:
    import hashlib

    return hashlib.sha256(file.read_bytes()).hexdigest()


def test_the_references_command_writes_the_packaged_tables_only_with_packaged(
    oracle: CountingOracle,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """By default the episodes go to the per-user cache (which the leaderboard reads) and the
    shipped tables stay byte-identical; ``--packaged`` writes the shipped table (here moved
    to a temporary file); ``--packaged`` and ``--table`` exclude each other."""
    from shipgym_baselines.cli import main

    shipped = {ref: references.table_path(ref) for ref in references.REFERENCES}
    before = {ref: _digest(file) for ref, file in shipped.items()}
    argv = ["references", "--suite", str(_tiny_suite(tmp_path)), "--reference", "oracle"]
    argv += ["--workers", "1", "--json"]
    assert main(argv) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["tables"] == {"oracle": str(user_cache_path())} and summary["computed"] == 1
    assert list(ReferenceTable.load(user_cache_path()).entries) == [
        entry_key(load_scenario("nominal"), 10000)
    ]
    assert {ref: _digest(file) for ref, file in shipped.items()} == before
    packaged = tmp_path / "packaged" / "oracle.json.gz"
    monkeypatch.setattr(references, "table_path", lambda reference="oracle": packaged)
    assert main([*argv, "--packaged"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["tables"] == {"oracle": str(packaged)} and summary["computed"] == 1
    assert len(ReferenceTable.load(packaged).entries) == 1
    with pytest.raises(SystemExit) as exit_:  # argparse: mutually exclusive
        main([*argv, "--packaged", "--table", str(tmp_path / "t.json.gz")])
    assert exit_.value.code == 2 and "--table" in capsys.readouterr().err


def test_the_default_counts_what_the_shipped_table_holds(
    capsys: pytest.CaptureFixture[str], user_cache: Path
) -> None:
    """The validation split is in the shipped table: nothing computed, no cache written."""
    from shipgym_baselines.cli import main

    assert main(["references", "--validation", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert (summary["computed"], summary["held"]) == (0, 32)
    assert summary["table"] == str(user_cache_path()) and not user_cache_path().exists()


def test_a_second_fill_of_one_table_is_refused_naming_the_first(
    oracle: CountingOracle, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Two ``shipgym references --table FILE`` at once would each replace the file with
    its own entries: the second is refused in one line naming the first, before any work,
    and the file is filled once the first has ended."""
    from shipgym_baselines.cli import main

    table = tmp_path / "t.json.gz"
    argv = ["references", "--suite", str(_tiny_suite(tmp_path)), "--table", str(table)]
    argv += ["--workers", "1"]
    with file_held_elsewhere(table, "--table") as holder:
        assert main(argv) == 2
        (line,) = capsys.readouterr().err.strip().splitlines()
        assert f"--table {table} is being written by another process (process {holder.pid}" in line
        assert oracle.runs == [] and not table.exists()
    # a lock file left by a killed process is free: the kernel released it with the process
    assert (tmp_path / "t.json.gz.lock").is_file()
    assert main(argv) == 0 and len(ReferenceTable.load(table).entries) == 1
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith("t.")) == [
        "t.json.gz"  # no lock file left
    ]


@pytest.mark.parametrize("planted", ["t.json.gz", "t.json.gz.lock"])
def test_a_table_fill_writes_through_no_link(
    planted: str, oracle: CountingOracle, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A link in place of the table or of its lock file: refused in one line naming it,
    what it points to untouched."""
    from shipgym_baselines.cli import main

    victim = tmp_path / "victim.txt"
    victim.write_text("untouched")
    (tmp_path / planted).symlink_to(victim)
    argv = ["references", "--suite", str(_tiny_suite(tmp_path))]
    argv += ["--table", str(tmp_path / "t.json.gz"), "--workers", "1"]
    assert main(argv) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert f"{tmp_path / planted} is " in line
    assert victim.read_text() == "untouched" and (tmp_path / planted).is_symlink()
