"""Whether files that need unpickling may be read (``--trust-pickle``).

A stable-baselines3 zip keeps cloudpickled values beside its JSON, and a
``vecnormalize.pkl`` is a pickle: unpickling either runs any code its author put in it.
Scoring third-party agents is this product's purpose, so a model is read as data only
(:mod:`shipgym_baselines.learned.loading`, :mod:`shipgym_baselines.learned.normalizer`)
and a file that
needs unpickling is an :class:`~shipgym_baselines.errors.UnsafeFileError` unless the user trusts
it: ``--trust-pickle`` on ``evaluate``, ``run`` and ``leaderboard``.

The choice travels in the environment variable :data:`TRUST_PICKLE_ENV`, so the worker
processes of a run (forked, spawned or a local Ray instance) see what the command said.

A training checkpoint (an SB3 zip, its replay buffer and reward statistics, pickles all)
is read by ``train --resume`` under the same rule, with one exception: a file this user's
shipgym wrote itself.  Each checkpoint file's SHA-256 is recorded when it is written
(:func:`remember_written`) in the per-user cache, outside the agent folder, so whoever made
a folder cannot forge the record; a file whose bytes match a record (:func:`written_here`)
is unpickled without ``--trust-pickle``, any other file only with it.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path

from shipgym_baselines.errors import UnsafeFileError

#: set to "1" while a command runs with ``--trust-pickle``
TRUST_PICKLE_ENV = "SHIPGYM_TRUST_PICKLE"
#: the command-line option that allows unpickling
TRUST_PICKLE_OPTION = "--trust-pickle"


def pickle_trusted() -> bool:
    """True while the running command was given ``--trust-pickle``."""
    return os.environ.get(TRUST_PICKLE_ENV) == "1"


@contextlib.contextmanager
def trusting_pickle(trusted: bool) -> Iterator[None]:
    """Within the block, files that need unpickling are read (``trusted``) or refused;
    the previous setting is restored afterwards."""
    before = os.environ.get(TRUST_PICKLE_ENV)
    os.environ[TRUST_PICKLE_ENV] = "1" if trusted else "0"
    try:
        yield
    finally:
        if before is None:
            os.environ.pop(TRUST_PICKLE_ENV, None)
        else:
            os.environ[TRUST_PICKLE_ENV] = before


def refuse_unpickling(file: Path, why: str) -> UnsafeFileError:
    """The error for ``file``, which only unpickling can read (``why``: what in it)."""
    return UnsafeFileError(
        f"{file}: {why}; reading it means unpickling, which runs any code the file holds: "
        f"refused (pass {TRUST_PICKLE_OPTION} if you trust whoever made it)"
    )


#: the per-user cache's folder of SHA-256 records of the checkpoint files shipgym wrote
WRITTEN_DIR = "written"


def _record(file: Path) -> Path:
    """The record of ``file``'s bytes as they are now (named by their SHA-256)."""
    from shipgym.codegen import file_sha256, user_cache_dir

    return user_cache_dir() / WRITTEN_DIR / file_sha256(file)


def remember_written(file: Path) -> None:
    """Record that this user's shipgym wrote ``file`` as it is now (its SHA-256: an empty
    file of that name in the per-user cache)."""
    record = _record(file)
    record.parent.mkdir(parents=True, exist_ok=True)
    record.touch()


def written_here(file: Path) -> bool:
    """True when ``file``'s bytes are those of a file this user's shipgym wrote
    (:func:`remember_written`)."""
    return _record(file).is_file()
