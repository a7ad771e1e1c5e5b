"""The law (35) linearised on its design model (Xu, Oliveira & Guedes Soares 2021)."""

from __future__ import annotations

import numpy as np
import pytest

from shipgym.models import MODELS
from shipgym_baselines.classical.adaptive.backstepping import backstepping_rudder
from shipgym_baselines.classical.adaptive.design_model import NonlinearNomoto, nominal_design_model
from shipgym_baselines.classical.adaptive.loop_analysis import (
    linearised_closed_loop_poles,
    linearised_pd_gains,
)
from shipgym_baselines.classical.adaptive.settings import Gains, L1BacksteppingSettings


def _paper_design() -> tuple[NonlinearNomoto, Gains]:
    model = nominal_design_model(MODELS["esso_osaka"]())
    gains = Gains.transfer(L1BacksteppingSettings(gain_transfer="literal"), 3.25, 0.41, "m")
    return model, gains


def test_pd_gains_are_the_law_linearised_at_a_constant_reference() -> None:
    """a2 = 0, exact estimates, ψd constant: δ(ψ, r) = −(Kp·z1 + Kd·r) exactly."""
    model = NonlinearNomoto(K=0.189, T=7.37, a2=0.0)
    _, gains = _paper_design()
    kp, kd = linearised_pd_gains(model, gains)
    for psi, r in ((0.1, 0.0), (0.0, 0.02), (-0.3, 0.05)):
        delta, z1, _ = backstepping_rudder(model, gains, psi, r, (0.0, 0.0, 0.0), (1, 1, 0))
        assert delta == pytest.approx(-(kp * z1 + kd * r), rel=1e-12)


def test_without_the_filter_the_poles_are_the_designed_error_system() -> None:
    model, gains = _paper_design()
    poles = np.sort_complex(linearised_closed_loop_poles(model, gains))
    error_system = np.array([[-gains.K1, 1.0], [-gains.z1_weight / model.T, -gains.K2 / model.T]])
    np.testing.assert_allclose(poles, np.sort_complex(np.linalg.eigvals(error_system)))
    assert poles.real.max() < 0


def test_printed_design_is_linearly_unstable_with_the_filter_on_the_paper_ship() -> None:
    """Why ``l1_backstepping`` limit-cycles: on the Esso Osaka's identified design model
    (K = 0.189 1/s, T = 7.37 s) the printed gains with C(s) on the whole command (eq. (39),
    ω = 0.25 rad/s) give an unstable loop: the saturated rudder then bounds an
    oscillation."""
    model, gains = _paper_design()
    with_filter = linearised_closed_loop_poles(model, gains, 0.25, 1.0)
    assert len(with_filter) == 4
    assert with_filter.real.max() > 0.05  # measured 0.070 1/s
