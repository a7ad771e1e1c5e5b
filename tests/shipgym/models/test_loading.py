"""The loading change: each ship's model declares its hull and the parameters a new draught
moves (shipgym.models.hull, shipgym.models.loading)."""

from __future__ import annotations

import math

import pytest

from shipgym.models import MODELS
from shipgym.models.base import ShipModel
from shipgym.models.hull import Hull, clarke_derivatives, draught_factors
from shipgym.models.loading import HULLS, loading_change


def test_the_hulls_are_the_models_own() -> None:
    assert HULLS == {name: m.hull for name, m in MODELS.items() if m.hull is not None}
    assert set(HULLS) == {"esso_osaka", "mariner", "blanke", "kvlcc2"}  # not nomoto2


def test_the_draught_factors_are_one_at_the_reference_draught() -> None:
    for hull in HULLS.values():
        assert all(math.isclose(v, 1.0) for v in draught_factors(hull, 1.0).values())


def test_clarke_s_sway_damping_grows_with_the_draught_squared_and_more() -> None:
    """Y'_v = −π(T/L)²(1 + 0.40 C_B B/T): at twice the draught, four times S and a smaller
    bracket (B/T halves)."""
    hull = Hull(L=100.0, B=15.0, T=5.0, C_B=0.7)
    f = draught_factors(hull, 2.0)
    expected = 4.0 * (1.0 + 0.40 * 0.7 * 1.5) / (1.0 + 0.40 * 0.7 * 3.0)
    assert f["Yv"] == pytest.approx(expected)
    assert clarke_derivatives(100.0, 15.0, 5.0, 0.7)["Yv"] < 0.0


@pytest.mark.parametrize("ship", sorted(HULLS))
def test_a_ship_at_its_own_draught_is_unchanged(ship: str) -> None:
    params = MODELS[ship].params_type()
    changed = loading_change(ship, params, 1.0)
    assert changed
    for name, value in changed.items():
        assert value == pytest.approx(getattr(params, name), rel=1e-12)


def test_a_ship_without_a_hull_or_a_wrong_record_is_named() -> None:
    with pytest.raises(ValueError, match="nomoto2"):
        loading_change("nomoto2", MODELS["nomoto2"].params_type(), 0.5)
    with pytest.raises(TypeError, match="MarinerParams"):
        loading_change("mariner", MODELS["blanke"].params_type(), 0.5)
    assert ShipModel.hull is None
