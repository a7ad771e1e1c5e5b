"""The box-constrained QP of a Gauss–Newton SQP step (CasADi's qrqp, buffers bound once), and
the other pieces every shooting SQP here shares: numpy buffers bound to a compiled CasADi
function (:func:`bind`), the backtracking line search (:func:`backtrack`) and the SQP loop
around them (:func:`sqp`).

    min_Δ  ½ Δᵀ H Δ + gᵀ Δ    s.t.  lb ≤ Δ ≤ ub

Used by every shooting NMPC here (:mod:`shipgym_baselines.classical.nmpc`, the oracle): H = JᵀWJ is
the (generalised) Gauss–Newton Hessian, g = Jᵀ∇φ.  The solver is built once per size; its
inputs and outputs are numpy buffers bound through CasADi's buffer interface, so a solve
allocates nothing.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import casadi as ca
import numpy as np


def bind(
    function: ca.Function, inputs: Sequence[np.ndarray], outputs: Sequence[np.ndarray]
) -> tuple[Any, Callable[[], None]]:
    """``function``'s buffer interface with numpy arrays as its inputs and outputs: calling
    the returned evaluator reads the inputs and writes the outputs in place (no allocation).
    Keep the returned buffer alive as long as the evaluator is used."""
    buffer, evaluate = function.buffer()
    for i, arg in enumerate(inputs):
        buffer.set_arg(i, memoryview(arg))
    for i, out in enumerate(outputs):
        buffer.set_res(i, memoryview(out))
    return buffer, evaluate


def backtrack(
    u: np.ndarray,
    step: np.ndarray,
    cost: float,
    lb: np.ndarray,
    ub: np.ndarray,
    evaluate: Callable[[np.ndarray], float],
) -> tuple[np.ndarray, float] | None:
    """Backtracking line search: the first of u + αΔ (α = 1, ½, ¼, … > 10⁻³, clipped to
    [lb, ub]) whose cost is not above ``cost``, with that cost; None if there is none."""
    alpha = 1.0
    while alpha > 1e-3:
        trial = u + alpha * step
        np.maximum(trial, lb, out=trial)  # np.clip(·, lb, ub), without its wrappers
        np.minimum(trial, ub, out=trial)
        trial_cost = evaluate(trial)
        if trial_cost <= cost:
            return trial, trial_cost
        alpha *= 0.5
    return None


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
        buffer, self._eval = bind(qp, [self._in[name] for name in qp.name_in()], self._out)
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

    def solve_gauss_newton(
        self, jac: np.ndarray, rho: np.ndarray, u: np.ndarray, lb: np.ndarray, ub: np.ndarray
    ) -> np.ndarray:
        """:meth:`solve` of the Gauss–Newton step of ‖ρ(u)‖² at u within lb ≤ u + Δ ≤ ub:
        H = JᵀJ, g = Jᵀρ, bounds lb − u, ub − u, computed straight into the QP's buffers
        (the same products as ``jac.T @ jac``, ``jac.T @ rho``, without temporaries)."""
        q, n = self._in, self.n
        np.matmul(jac.T, jac, out=q["h"].reshape(n, n))
        np.matmul(jac.T, rho, out=q["g"])
        np.subtract(lb, u, out=q["lbx"])
        np.subtract(ub, u, out=q["ubx"])
        self._eval()
        return self._out[0].copy()


def sqp(
    guess: np.ndarray,
    lb: np.ndarray,
    ub: np.ndarray,
    cost: Callable[[np.ndarray], float],
    direction: Callable[[np.ndarray], np.ndarray | None],
    max_iter: int,
    step_tolerance: float,
    cost_tolerance: float | None = None,
) -> tuple[np.ndarray, bool, int]:
    """The warm-started SQP of a shooting NMPC: from ``guess`` (clipped to [lb, ub]), at most
    ``max_iter`` times a step Δ = ``direction(u)`` (None: the linearisation is not finite)
    and a :func:`backtrack` on ``cost``; stopped when no descent is found, when the accepted
    step moves less than ``step_tolerance`` or (``cost_tolerance`` given) when it lowers the
    cost by less than that fraction.  Returns (plan, success, iterations)."""
    u = np.minimum(np.maximum(guess, lb), ub)  # np.clip(guess, lb, ub)
    value = cost(u)
    if not math.isfinite(value):
        return u, False, 0
    iterations = 0
    for iterations in range(1, max_iter + 1):
        step = direction(u)
        if step is None:
            return u, False, iterations
        found = backtrack(u, step, value, lb, ub, cost)
        if found is None:
            break  # no descent: converged as far as the (generalised) Gauss–Newton goes
        trial, trial_value = found
        moved = float(np.abs(trial - u).max())
        gain = value - trial_value
        u, value = trial, trial_value
        if moved < step_tolerance:
            break
        if cost_tolerance is not None and gain <= cost_tolerance * value:
            break
    return u, bool(np.isfinite(u).all() and math.isfinite(value)), iterations
