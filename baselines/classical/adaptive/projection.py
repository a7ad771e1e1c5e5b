"""Smooth projection operator for adaptation laws — Xu, Oliveira & Guedes Soares (2021)
eqs. (24)–(25).

The paper writes θ̂' = γ·Proj(θ̂, y) without defining Proj; this is the smooth operator of
Pomet & Praly (1992) in the form of Lavretsky & Wise (2013, *Robust and Adaptive Control*,
§11.4), for a scalar estimate bounded to [lo, hi]: the convex function

    f(θ) = ((θ − c)² − w0²)/(ε·w0²),  c = (lo + hi)/2,  w0 = (hi − lo)/(2√(1 + ε)),

is 0 on the inner interval [c ± w0] and 1 on the outer one [lo, hi], and

    Proj(θ, y) = y·(1 − f(θ))  if f(θ) > 0 and y points outwards,  else y.

It is Lipschitz in θ, keeps [lo, hi] invariant (θ̂' = 0 at the bounds when y points out)
and never increases a Lyapunov function with the term (θ̂ − θ)²/(2γ) for a true θ in the
inner interval: (θ̂ − θ)·(Proj(θ̂, y) − y) ≤ 0.
"""

from __future__ import annotations


def projection(theta: float, y: float, lower: float, upper: float, epsilon: float = 0.1) -> float:
    """Proj(θ, y) keeping θ in [lower, upper] (module doc); ε > 0 the boundary-layer width.

    Returns y·(1 − f) if f(θ) > 0 and y·(θ − c) > 0 (pointing outwards in the boundary
    layer), else y; f reaches 1 exactly at lower and upper.
    """
    centre = 0.5 * (lower + upper)
    w0_sq = (0.5 * (upper - lower)) ** 2 / (1.0 + epsilon)
    offset = theta - centre
    f = (offset * offset - w0_sq) / (epsilon * w0_sq)
    if f > 0.0 and y * offset > 0.0:
        return y * (1.0 - f)
    return y
