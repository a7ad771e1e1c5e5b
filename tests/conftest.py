"""Fixtures of the whole test suite."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from shipgym import codegen

#: folders of the working directory that commands write into by default (``results/…``)
DEFAULT_OUTPUTS = ("results",)


def working_directory_listing(root: Path) -> set[str]:
    """What a test could leave in the working directory: its entries (hidden ones, tool
    caches such as ``.pytest_cache``, aside) and, two levels deep, what the commands'
    default output folders hold."""
    found = {p.name for p in root.iterdir() if not p.name.startswith(".")}
    for name in DEFAULT_OUTPUTS:
        folder = root / name
        if folder.is_dir():
            found |= {p.relative_to(root).as_posix() for p in folder.glob("*")}
            found |= {p.relative_to(root).as_posix() for p in folder.glob("*/*")}
    return found


@pytest.fixture(autouse=True)
def leaves_no_trace(request: pytest.FixtureRequest) -> Iterator[None]:
    """Every test writes only into temporary folders: the working
    directory (the checkout, where ``shipgym leaderboard`` writes ``results/``) is as it
    was before the test."""
    root = Path.cwd()
    before = working_directory_listing(root)
    yield
    new = sorted(working_directory_listing(root) - before)
    assert not new, f"{request.node.nodeid} wrote into the working directory {root}: {new}"


@pytest.fixture(autouse=True)
def user_cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> Path:
    """The per-user cache (``$SHIPGYM_CACHE_DIR``) in a fresh temporary folder, so that no
    test reads or writes the real one; compiled C libraries stay in the machine's cache
    (``$SHIPGYM_CACHE`` pinned to it), so that tests do not compile again."""
    monkeypatch.setenv("SHIPGYM_CACHE", str(codegen.cache_dir()))
    # no notice lines (a cold compile cache would add them to the stderr tests compare);
    # the tests of the notices unset it
    monkeypatch.setenv("SHIPGYM_QUIET", "1")
    folder = tmp_path_factory.mktemp("user_cache")
    monkeypatch.setenv(codegen.CACHE_DIR_ENV, str(folder))
    return folder


@pytest.fixture
def loud(monkeypatch: pytest.MonkeyPatch) -> None:
    """The notice lines on (the suite silences them: :func:`user_cache`)."""
    monkeypatch.delenv("SHIPGYM_QUIET", raising=False)
