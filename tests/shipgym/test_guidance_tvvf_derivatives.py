"""Derivatives in ye of the TVVF law (guidance.tvvf_heading_derivatives)."""

from __future__ import annotations

import pytest

from shipgym.guidance import tvvf_heading, tvvf_heading_derivatives

DELTA = 1.9  # [m]


@pytest.mark.parametrize("unit", [1.0, 0.2923])
@pytest.mark.parametrize("ye", [-7.3, -0.4, 0.05, 0.9, 3.0, 25.0])
def test_tvvf_heading_derivatives_match_finite_differences(ye: float, unit: float) -> None:
    def psi_d(e: float) -> float:
        return tvvf_heading(e, 0.3, DELTA, error_unit=unit)

    d1, d2 = tvvf_heading_derivatives(ye, DELTA, error_unit=unit)
    step = 1e-4 * max(1.0, abs(ye))
    fd1 = (psi_d(ye + step) - psi_d(ye - step)) / (2 * step)
    fd2 = (psi_d(ye + step) - 2 * psi_d(ye) + psi_d(ye - step)) / step**2
    assert d1 == pytest.approx(fd1, rel=1e-5, abs=1e-9)
    assert d2 == pytest.approx(fd2, rel=1e-3, abs=1e-5)


@pytest.mark.parametrize("ye", [-3.0, -0.5, 0.5, 2.0])
def test_constant_theta_one_gives_the_lookahead_los_derivatives(ye: float) -> None:
    """θ ≡ 1 (slope 0): ψd = γp − atan(ye/Δ), so ψd' = −Δ/(Δ² + ye²) and
    ψd'' = 2·Δ·ye/(Δ² + ye²)²."""
    d1, d2 = tvvf_heading_derivatives(ye, DELTA, theta_slope=0.0, theta_offset=1.0)
    assert d1 == pytest.approx(-DELTA / (DELTA**2 + ye**2), rel=1e-12)
    assert d2 == pytest.approx(2 * DELTA * ye / (DELTA**2 + ye**2) ** 2, rel=1e-12)


def test_far_from_the_path_the_law_is_flat() -> None:
    """|ye|^θ/Δ > 1e12: ψd is saturated at γp ∓ π/2 and both derivatives are 0."""
    assert tvvf_heading_derivatives(200.0, DELTA) == (0.0, 0.0)


def test_bad_arguments_are_refused() -> None:
    with pytest.raises(ValueError, match="delta"):
        tvvf_heading_derivatives(1.0, 0.0)
    with pytest.raises(ValueError, match="error_unit"):
        tvvf_heading_derivatives(1.0, DELTA, error_unit=0.0)
