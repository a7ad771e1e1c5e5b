"""Fixtures shared by the tests of ``baselines``."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from shipgym_baselines import registry


@pytest.fixture
def scratch_registry() -> Iterator[None]:
    """Controllers registered (or resolved) inside a test are gone after it."""
    records, resolved = dict(registry._RECORDS), dict(registry._RESOLVED)
    yield
    registry._RECORDS.clear()
    registry._RECORDS.update(records)
    registry._RESOLVED.clear()
    registry._RESOLVED.update(resolved)
