"""A ship's nominal Nomoto models for controller design: closed form or zig-zag fit."""

from __future__ import annotations

import pytest

from shipgym.identification.nominal import first_order_nomoto, second_order_nomoto
from shipgym.identification.zigzag import ship_nomoto
from shipgym.models import MODELS
from shipgym.models.base import ParameterError
from shipgym.models.nomoto2 import Nomoto2


def test_nomoto2_nominal_model_is_its_own_closed_form() -> None:
    """nomoto2 is a 2nd-order Nomoto model: K, T1, T2, T3 are its parameters, and the
    first-order model is Nomoto's approximation T = T1 + T2 − T3 (no zig-zag run)."""
    ship = Nomoto2()
    p = ship.params
    assert second_order_nomoto(ship) == (p.K, p.T1, p.T2, p.T3)
    assert first_order_nomoto(ship) == (p.K, p.T1 + p.T2 - p.T3)
    slower = p.replace(T1=2.0, T3=0.5)
    assert first_order_nomoto(ship, slower) == (p.K, 2.0 + p.T2 - 0.5)


def test_non_positive_first_order_time_constant_is_a_parameter_error() -> None:
    ship = Nomoto2()
    with pytest.raises(ParameterError, match="not positive"):
        first_order_nomoto(ship, ship.params.replace(T3=5.0))


def test_nominal_models_come_from_the_ships_own_zigzag() -> None:
    """first_order_nomoto of a ship without a closed form is the zig-zag fit (no typed
    numbers), cached per model, and follows the nominal parameters it is given."""
    mariner = MODELS["mariner"]()
    assert mariner.closed_form_nomoto() is None
    K, T = first_order_nomoto(mariner)
    fit, servo = ship_nomoto(mariner)
    assert (K, T) == fit.first_order()
    assert second_order_nomoto(mariner) == (fit.K, fit.T1, fit.T2, fit.T3)
    # the de Wit-Oppe linear part: K = a3/a1 = 0.056 1/s, T = 1/a1 = 55.6 s; the 20/20
    # fit also sees the cubic damping a2·r³, which lowers both
    assert 0.03 < K < 0.056 and 30.0 < T < 55.6
    assert servo > 1.0  # the 0.066 rad/s rate limit makes the effective servo slow
    faster = mariner.params.replace(a3=2 * mariner.params.a3)
    K2, T2 = first_order_nomoto(mariner, faster)
    # twice the rudder effectiveness: a larger gain, less than doubled because the
    # stronger turns meet more cubic damping
    assert 1.3 * K < K2 < 2 * K
    assert (K2, T2) == ship_nomoto(mariner.with_params(faster))[0].first_order()
