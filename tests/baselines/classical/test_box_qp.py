"""The Gauss–Newton QP written into qrqp's buffers is the QP of the explicit products."""

from __future__ import annotations

import numpy as np

from shipgym_baselines.classical.box_qp import BoxQP


def test_solve_gauss_newton_equals_solve_of_the_products_bit_for_bit() -> None:
    """J as the NMPC holds it (a transposed column-major buffer), random scales and bounds,
    some active: the step Δ is the same array as ``solve(JᵀJ, Jᵀρ, lb − u, ub − u)``."""
    rng = np.random.default_rng(3)
    for n in (1, 3, 8, 12):
        qp = BoxQP(n)
        for _ in range(40):
            residuals = int(rng.integers(n, 80))
            jac = (rng.standard_normal((n, residuals)) * 10.0 ** rng.integers(-3, 3)).T
            rho = rng.standard_normal(residuals)
            u = rng.uniform(-0.5, 0.5, n)
            lb, ub = np.full(n, -0.52), np.full(n, 0.52)
            want = qp.solve(jac.T @ jac, jac.T @ rho, lb - u, ub - u)
            got = qp.solve_gauss_newton(jac, rho, u, lb, ub)
            assert got.tobytes() == want.tobytes()
            assert np.all(u + got >= lb - 1e-12) and np.all(u + got <= ub + 1e-12)
