"""The box-constrained QP of a Gauss–Newton SQP step (CasADi's qrqp, buffers bound once).

    min_Δ  ½ Δᵀ H Δ + gᵀ Δ    s.t.  lb ≤ Δ ≤ ub

Used by every shooting NMPC here (:mod:`baselines.classical.nmpc`, the oracle): H = JᵀWJ is
the (generalised) Gauss–Newton Hessian, g = Jᵀ∇φ.  The solver is built once per size; its
inputs and outputs are numpy buffers bound through CasADi's buffer interface, so a solve
allocates nothing.
"""

from __future__ import annotations

import casadi as ca
import numpy as np


class BoxQP:
    """A dense n-variable QP with simple bounds only, solved by qrqp."""

    def __init__(self, n: int) -> None:
        qp = ca.conic(
            "gn_qp",
            "qrqp",
            {"h": ca.Sparsity.dense(n, n), "a": ca.Sparsity(0, n)},
            {
                "print_iter": False,
                "print_header": False,
                "print_info": False,
                "error_on_fail": False,
            },
        )
        self.n = n
        self._in = {name: np.zeros(qp.sparsity_in(i).nnz()) for i, name in enumerate(qp.name_in())}
        self._out = [np.zeros(qp.sparsity_out(i).nnz()) for i in range(qp.n_out())]
        buffer, self._eval = qp.buffer()
        for i, name in enumerate(qp.name_in()):
            buffer.set_arg(i, memoryview(self._in[name]))
        for i, out in enumerate(self._out):
            buffer.set_res(i, memoryview(out))
        self._keep = (qp, buffer)  # the buffers' owners stay alive

    def solve(self, h: np.ndarray, g: np.ndarray, lb: np.ndarray, ub: np.ndarray) -> np.ndarray:
        """Δ minimising ½ΔᵀHΔ + gᵀΔ within [lb, ub] (H symmetric positive semidefinite)."""
        q = self._in
        q["h"][:] = np.asarray(h).ravel()
        q["g"][:] = g
        q["lbx"][:] = lb
        q["ubx"][:] = ub
        self._eval()
        return self._out[0].copy()
