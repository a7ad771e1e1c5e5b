"""Fixtures shared by the tests of ``baselines``."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest

from shipgym_baselines import registry


@pytest.fixture
def scratch_registry() -> Iterator[None]:
    """Controllers registered (or resolved) inside a test are gone after it (the built-ins
    loaded first, by reading CONTROLLERS, so that they are kept)."""
    records, resolved = dict(registry.CONTROLLERS), dict(registry._RESOLVED)
    yield
    registry._RECORDS.clear()
    registry._RECORDS.update(records)
    registry._RESOLVED.clear()
    registry._RESOLVED.update(resolved)


#: the smoke suite's controllers a quick run keeps (one classical, one reference)
SMOKE_CONTROLLERS = ["pid_los", "zero_rudder"]


@pytest.fixture(scope="session")
def smoke_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The smoke suite run once (one seed, :data:`SMOKE_CONTROLLERS`), complete: copy it
    (:func:`copy_folder`) before changing it."""
    from shipgym_baselines.leaderboard.run import run_leaderboard

    out = tmp_path_factory.mktemp("smoke") / "out"
    run_leaderboard(
        "smoke", seeds=1, out_dir=out, controllers=SMOKE_CONTROLLERS, workers=1, show_progress=False
    )
    return out


def copy_folder(source: Path, target: Path) -> Path:
    """A copy of a run folder, every file of it (its manifest included)."""
    shutil.copytree(source, target)
    return target


@pytest.fixture
def truth_calls(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Spies on every way to the truth: the training-time teacher channel, the evaluation
    loop's privileged reset and the env's ``plant_truth``.  The list holds the name of each
    call made while the test runs (the originals still answer)."""
    from shipgym.envs.path_follow import ShipPathFollowEnv
    from shipgym_baselines import evaluation, privileged

    calls: list[str] = []

    def spy(name: str, original: object) -> object:
        def recorded(*args: object, **kwargs: object) -> object:
            calls.append(name)
            return original(*args, **kwargs)  # type: ignore[operator]

        return recorded

    monkeypatch.setattr(privileged, "teacher_truth", spy("teacher_truth", privileged.teacher_truth))
    for module in (privileged, evaluation):
        monkeypatch.setattr(
            module, "reset_with_truth", spy("reset_with_truth", privileged.reset_with_truth)
        )
    monkeypatch.setattr(
        ShipPathFollowEnv, "plant_truth", spy("plant_truth", ShipPathFollowEnv.plant_truth)
    )
    return calls


def error_line(capsys: pytest.CaptureFixture[str], command: str) -> str:
    """The one stderr line of a bad input to ``shipgym command`` (checked for its shape:
    one line, no traceback, the command's prefix), without its prefix."""
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    prefix = f"shipgym {command}: error: "
    assert err.startswith(prefix), err
    return err.removeprefix(prefix).rstrip("\n")
