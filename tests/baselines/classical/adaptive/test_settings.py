"""§5.2 settings and the gain transfer (Xu, Oliveira & Guedes Soares 2021)."""

from __future__ import annotations

import pytest

from shipgym_baselines.classical.adaptive.settings import Gains, L1BacksteppingSettings


def test_similarity_transfer_keeps_the_printed_gains_on_the_paper_ship() -> None:
    settings = L1BacksteppingSettings()
    paper = Gains.transfer(settings, 3.25, 0.41, "m")
    assert (paper.K1, paper.gamma1, paper.filter_frequency, paper.error_unit) == (
        0.02,
        100.0,
        0.25,
        1.0,
    )
    mariner = Gains.transfer(settings, 172.0, 7.7, "m")
    tau = (172.0 / 7.7) / (3.25 / 0.41)
    assert mariner.time_scale == pytest.approx(tau)
    assert mariner.K1 * tau == pytest.approx(0.02)
    assert mariner.gamma_rho / tau == pytest.approx(20.0)
    assert mariner.K2 == 15.0
    assert mariner.error_unit == pytest.approx(172.0 / 3.25)
    assert Gains.transfer(settings, 172.0, 7.7, "L").error_unit == 172.0


def test_literal_transfer_uses_the_printed_numbers_on_any_ship() -> None:
    gains = Gains.transfer(L1BacksteppingSettings(gain_transfer="literal"), 172.0, 7.7, "m")
    assert (gains.K1, gains.gamma_rho, gains.filter_frequency, gains.error_unit) == (
        0.02,
        20.0,
        0.25,
        1.0,
    )


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (dict(gain_transfer="froude"), "gain_transfer"),
        (dict(error_unit="ft"), "error_unit"),
        (dict(K2=0.0), "K1, K2"),
        (dict(z1_weight=-1.0), "z1_weight"),
        (dict(filter_placement="output"), "filter_placement"),
        (dict(paper_ship_speed=0.0), "paper_ship_length"),
    ],
)
def test_bad_settings_are_refused(change: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        L1BacksteppingSettings(**change)
