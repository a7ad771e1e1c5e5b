"""Every ship against the published values of its hull (shipgym.validation, rendered in
docs/validation.md): each value with a tolerance is within it, every value names its source,
and one not asserted says why."""

from __future__ import annotations

import math

import pytest

from shipgym.models import MODELS
from shipgym.models.ship import Published
from shipgym.validation import (
    FIGURES,
    PUBLISHED,
    TURNING,
    measure_ship,
    relative_error,
)

#: (ship, published value) of every ship's record
REFS = [(ship, ref) for ship, refs in PUBLISHED.items() for ref in refs]


@pytest.fixture(scope="module")
def ours() -> dict[str, dict[str, float]]:
    """Every ship's figures (all five ships' manoeuvres take about a second)."""
    return {ship: measure_ship(ship) for ship in MODELS}


def test_every_ship_has_every_figure(ours: dict[str, dict[str, float]]) -> None:
    for ship, figures in ours.items():
        for key in FIGURES:
            assert math.isfinite(figures[key]), (ship, key)
        for key in TURNING:
            assert math.isfinite(figures[key + "_port"] + figures[key + "_mean"]), (ship, key)


@pytest.mark.parametrize(
    ("ship", "ref"),
    [(ship, ref) for ship, ref in REFS if ref.tolerance is not None],
    ids=[f"{ship}-{ref.figure}" for ship, ref in REFS if ref.tolerance is not None],
)
def test_published_values_within_their_tolerance(
    ship: str, ref: Published, ours: dict[str, dict[str, float]]
) -> None:
    err = relative_error(ours[ship][ref.figure], ref.value)
    assert abs(err) <= ref.tolerance, f"{ship} {ref.figure}: {err:+.1%} ({ref.source})"


def test_every_published_value_names_its_source_and_an_unasserted_one_why() -> None:
    for ship, ref in REFS:
        assert ship in MODELS
        base = ref.figure.removesuffix("_port").removesuffix("_mean")
        assert base in FIGURES, ref.figure
        assert ref.source and ref.value != 0.0
        assert ref.note, f"{ship} {ref.figure}: say why this tolerance, or why none"


def test_kvlcc2_10_10_zigzag_is_outside_the_tests_as_the_page_says(
    ours: dict[str, dict[str, float]],
) -> None:
    """The page reports our 10/10 overshoots as under the MARIN tests (not loosened): if a
    model change brings them within 25 %, give them a tolerance in shipgym.validation."""
    for ref in PUBLISHED["kvlcc2"]:
        if ref.figure.startswith("overshoot_10"):
            assert relative_error(ours["kvlcc2"][ref.figure], ref.value) < -0.25
