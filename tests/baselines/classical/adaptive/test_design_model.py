"""Design model T·ṙ + H(r)·r = K·δ + b (Xu, Oliveira & Guedes Soares 2021 eq. (15))."""

from __future__ import annotations

import pytest

from shipgym.identification.cubic_damping import ship_cubic_damping
from shipgym.identification.nominal import first_order_nomoto
from shipgym.models import MODELS
from shipgym.models.nomoto2 import Nomoto2, Nomoto2Params
from shipgym_baselines.classical.adaptive.design_model import NonlinearNomoto, nominal_design_model


def test_nomoto2_design_model_is_the_first_order_reduction_with_beta() -> None:
    m = nominal_design_model(Nomoto2())
    p = Nomoto2Params()
    assert (m.K, m.T, m.a2) == pytest.approx((p.K, p.T1 + p.T2 - p.T3, p.beta))


def test_other_ships_get_the_pipeline_k_t_and_the_zigzag_a2() -> None:
    ship = MODELS["esso_osaka"]()
    m = nominal_design_model(ship)
    K, T = first_order_nomoto(ship)
    assert (m.K, m.T) == (K, T)
    assert m.a2 == ship_cubic_damping(ship, K, T) >= 0.0


def test_damping_is_one_plus_a2_r_squared() -> None:
    assert NonlinearNomoto(K=0.5, T=2.0, a2=3.0).damping(0.2) == pytest.approx(1.12)


@pytest.mark.parametrize("bad", [dict(T=0.0), dict(K=0.0), dict(a2=-1.0)])
def test_a_design_model_without_positive_damping_is_refused(bad: dict) -> None:
    with pytest.raises(ValueError, match="need T > 0"):
        NonlinearNomoto(**{"K": 0.5, "T": 2.0, "a2": 0.1, **bad})
