"""A training run writes its agent folder as ``shipgym run`` writes its own: locked, every
file listed in the manifest, ``--force`` deleting only those, no link written through, and
``--resume`` unpickling only checkpoints this user's shipgym wrote."""

from __future__ import annotations

import os
import pickle
import re
from pathlib import Path

import pytest

from shipgym_baselines.cli import main
from shipgym_baselines.errors import RunError
from shipgym_baselines.learned.trust import trusting_pickle
from shipgym_baselines.records.manifest import check_listed, read_manifest
from shipgym_baselines.training.agents import load_agent_config
from shipgym_baselines.training.train import checkpoint_names, export_policy, train
from tests.baselines.records.test_locking import hold
from tests.baselines.training.test_train_curves import _tiny

pytest.importorskip("stable_baselines3")

#: the user's files of the probe, inside folders a training run writes
USER_FILES = ("eval/my_analysis.ipynb", "tb/my_runs/notes.txt")


@pytest.fixture(scope="module")
def trained(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A tiny PPO run (256 env steps, checkpoints at 128 and 256, TensorBoard logs); the
    records of its checkpoints in the per-user cache ``<its folder>/../cache``
    (:func:`same_user`)."""
    out = tmp_path_factory.mktemp("trained") / "run"
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("SHIPGYM_CACHE_DIR", str(out.parent / "cache"))
        train(_tiny(), out_dir=out, progress=False, tensorboard=True)
    return out


def same_user(trained: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The per-user cache of the process that trained ``trained``."""
    monkeypatch.setenv("SHIPGYM_CACHE_DIR", str(trained.parent / "cache"))


def _copy(source: Path, target: Path) -> Path:
    import shutil

    shutil.copytree(source, target, symlinks=True)
    return target


def test_every_file_a_run_writes_is_listed(trained: Path) -> None:
    """Checkpoints, evaluations and TensorBoard logs: all in the manifest, nothing else
    in the folder.  TensorBoard's events file ends in a random suffix (no link can wait
    for its name)."""
    listed = read_manifest(trained)
    assert {f"checkpoints/{name}" for name in checkpoint_names(128)[:1]} <= listed
    (events,) = [p for p in listed if p.startswith("tb/ppo_tiny_1/events.out.tfevents.")]
    assert re.fullmatch(r".*\.[0-9a-f]{16}", events), events
    assert check_listed(trained) <= listed


#: files SB3 writes during a run (checkpoints, the evaluations' history, the best model)
DURING_THE_RUN = (
    "checkpoints/ckpt_128_steps.zip",
    "checkpoints/ckpt_vecnormalize_128_steps.pkl",
    "eval/evaluations.npz",
    "best_model.zip",
)


@pytest.mark.parametrize("planted", DURING_THE_RUN)
def test_a_link_planted_during_a_run_is_not_written_through(
    planted: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A link that appears in the agent folder after the run checked it (planted as the
    run makes ``checkpoints/`` and ``eval/``), in place of a file SB3 writes: the run ends
    in one line naming it, and the file it points to is untouched."""
    from shipgym_baselines.training import train as train_module

    out, victim = tmp_path / "run", tmp_path / "victim.txt"
    victim.write_text("untouched")
    made = train_module.make_dir

    def planting(folder: Path) -> Path:
        path = made(folder)
        link = out / planted
        if Path(folder) in (link.parent, out / "eval") and not link.is_symlink():
            link.symlink_to(victim)
        return path

    monkeypatch.setattr(train_module, "make_dir", planting)
    with pytest.raises(RunError, match=f"{re.escape(planted)} is a symbolic link"):
        train(_tiny(n_timesteps=128), out_dir=out, progress=False, tensorboard=False)
    assert victim.read_text() == "untouched"


def test_a_resumed_run_logs_into_its_tensorboard_folder(trained: Path, tmp_path: Path) -> None:
    """A resumed run adds a second events file to ``tb/ppo_tiny_1`` (where SB3 would
    continue too), listed; the folder's other files are its own."""
    with trusting_pickle(True):
        out = _copy(trained, tmp_path / "run")
        train(_tiny(), out_dir=out, n_timesteps=384, resume=True, progress=False)
    events = sorted(p.name for p in (out / "tb" / "ppo_tiny_1").iterdir())
    assert len(events) == 2 and sorted(p.name for p in (out / "tb").iterdir()) == ["ppo_tiny_1"]
    assert {f"tb/ppo_tiny_1/{e}" for e in events} <= read_manifest(out)


def test_export_writes_through_no_link(trained: Path, tmp_path: Path) -> None:
    """A link in place of a policy folder's file: refused in one line before any file is
    written, what it points to untouched."""
    victim = tmp_path / "victim.txt"
    victim.write_text("untouched")
    dest = tmp_path / "policy"
    dest.mkdir()
    (dest / "meta.json").symlink_to(victim)
    with pytest.raises(RunError, match=r"meta\.json is a symbolic link"):
        export_policy(trained, dest)
    assert victim.read_text() == "untouched" and sorted(os.listdir(dest)) == ["meta.json"]


def test_force_keeps_the_users_files_and_refuses_in_one_line(trained: Path, tmp_path: Path) -> None:
    """The probe: a user's notebook in ``eval/`` and notes in ``tb/my_runs/``; ``--force``
    refuses before deleting anything, naming them.  Without them it starts afresh."""
    out = _copy(trained, tmp_path / "run")
    for rel in USER_FILES:
        (out / rel).parent.mkdir(parents=True, exist_ok=True)
        (out / rel).write_text("mine")
    before = sorted(p.relative_to(out).as_posix() for p in out.rglob("*"))
    with pytest.raises(RunError, match="holds files no run wrote") as refused:
        train(_tiny(), out_dir=out, progress=False, tensorboard=False, force=True)
    assert all(rel in str(refused.value) for rel in USER_FILES)
    assert "\n" not in str(refused.value)
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*")) == before
    for rel in USER_FILES:
        (out / rel).unlink()
        (out / rel).parent.rmdir() if rel.startswith("tb/my_runs") else None
    meta = train(_tiny(n_timesteps=128), out_dir=out, progress=False, tensorboard=False, force=True)
    assert meta["env_steps"] == 128
    assert not (out / "checkpoints" / checkpoint_names(256)[0]).exists()  # the old run's


def test_dagger_force_keeps_the_users_files(tmp_path: Path) -> None:
    """``train dagger --force`` on a folder holding a user's notebook: refused before any
    work, the file kept."""
    out = tmp_path / "run"
    (out / "eval").mkdir(parents=True)
    (out / USER_FILES[0]).write_text("mine")
    with pytest.raises(RunError, match=r"eval/my_analysis\.ipynb"):
        train(load_agent_config("dagger"), out_dir=out, progress=False, force=True)
    assert (out / USER_FILES[0]).read_text() == "mine"


def test_a_second_run_on_a_held_folder_is_refused(trained: Path, tmp_path: Path) -> None:
    out = _copy(trained, tmp_path / "run")
    holder = hold(out)
    try:
        with pytest.raises(RunError, match=f"is in use by another run \\(process {holder.pid}"):
            train(_tiny(), out_dir=out, n_timesteps=384, resume=True, progress=False)
    finally:
        holder.kill()
        holder.wait()


def test_resume_writes_through_no_planted_link(trained: Path, tmp_path: Path) -> None:
    out = _copy(trained, tmp_path / "run")
    victim = tmp_path / "victim.json"
    victim.write_text("untouched")
    (out / "learning_curve.json").unlink()
    (out / "learning_curve.json").symlink_to(victim)
    with pytest.raises(RunError, match=r"learning_curve\.json is a symbolic link"):
        train(_tiny(), out_dir=out, n_timesteps=384, resume=True, progress=False)
    assert victim.read_text() == "untouched"


class _Payload:
    """A pickle that makes a folder when it is unpickled (the probe's payload)."""

    def __init__(self, marker: Path) -> None:
        self.marker = str(marker)

    def __reduce__(self) -> tuple:
        return (os.mkdir, (self.marker,))


def test_resume_unpickles_no_planted_checkpoint_and_falls_back(
    trained: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A replay buffer planted beside the newest checkpoint is not unpickled (no record
    that a run of this user wrote it): one line names it, and the run resumes from the
    checkpoint before."""
    same_user(trained, monkeypatch)
    out = _copy(trained, tmp_path / "run")
    marker = tmp_path / "payload_ran"
    planted = out / "checkpoints" / checkpoint_names(256)[2]
    planted.write_bytes(pickle.dumps(_Payload(marker)))
    meta = train(_tiny(), out_dir=out, n_timesteps=384, resume=True, progress=False)
    assert not marker.exists() and meta["env_steps"] == 384
    err = capsys.readouterr().err.splitlines()
    assert any(str(planted) in line and "--trust-pickle" in line for line in err), err
    assert "train --resume: resuming from 128 env steps" in err


def test_a_corrupt_checkpoint_falls_back_in_one_line(
    trained: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Even trusted (``--trust-pickle``), a checkpoint cut to 3,000 bytes is named in one
    line and the run resumes from the one before, not a traceback."""
    out = _copy(trained, tmp_path / "run")
    newest = out / "checkpoints" / checkpoint_names(256)[0]
    os.truncate(newest, 3000)
    with trusting_pickle(True):
        meta = train(_tiny(), out_dir=out, n_timesteps=384, resume=True, progress=False)
    assert meta["env_steps"] == 384
    (line,) = [x for x in capsys.readouterr().err.splitlines() if "unreadable" in x]
    assert line.startswith(f"train --resume: the checkpoint {newest} is unreadable (")


def test_the_train_command_takes_trust_pickle(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["train", "--help"])
    assert "--trust-pickle" in capsys.readouterr().out


def test_another_users_checkpoints_need_trust_pickle(
    trained: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Checkpoints no run of this user wrote (a fresh per-user cache): refused, each named
    in one line, then one line saying how to go on; no traceback."""
    out = _copy(trained, tmp_path / "run")
    with pytest.raises(RunError, match=r"no checkpoint in .* can be read"):
        train(_tiny(), out_dir=out, n_timesteps=384, resume=True, progress=False)
    skipped = [x for x in capsys.readouterr().err.splitlines() if "skipped" in x]
    assert len(skipped) == 2 and all("--trust-pickle" in x for x in skipped)
    with trusting_pickle(True):
        meta = train(_tiny(), out_dir=out, n_timesteps=384, resume=True, progress=False)
    assert meta["env_steps"] == 384


@pytest.mark.parametrize(
    "damaged",
    [
        "meta.json",
        "checkpoints/state.json",
        "eval/best.json",
        "tuned_from.json",
        "eval/evaluations.npz",
    ],
)
def test_a_damaged_record_of_the_run_is_one_line(
    damaged: str, trained: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--resume`` on a folder whose record of the run (not a checkpoint) is damaged: one
    line naming the file and that ``--force`` trains it afresh, not a traceback."""
    same_user(trained, monkeypatch)
    out = _copy(trained, tmp_path / "run")
    (out / damaged).write_text("{not json")
    with pytest.raises(RunError) as refused:
        train(_tiny(), out_dir=out, n_timesteps=384, resume=True, progress=False)
    line = str(refused.value)
    assert line.startswith(str(out / damaged)) and "\n" not in line
    assert line.endswith("a damaged record of the run (--force trains it afresh)")
