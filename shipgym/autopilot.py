"""PID heading autopilots designed on Nomoto models: pole placement and Vyshnegradsky.

Used inside the env in ``guidance`` action mode and by the ``pid_*`` baselines (one
definition for both).

Pole placement (:meth:`PIDGains.from_nomoto`).  With T·ṙ + r = K·δ and
δ = Kp·ψ̃ − Kd·r + Ki∫ψ̃ (ψ̃ = ψd − ψ), the closed loop without Ki is
T·ψ̈ + (1 + K·Kd)·ψ̇ + K·Kp·ψ = K·Kp·ψd, so a natural frequency ωn and damping ζ give
(Xu, Oliveira & Guedes Soares 2021 §5.2, after Fossen 2011 §12.2.7):

    Kp = ωn²·T/K,   Kd = (2ζωn·T − 1)/K,   Ki = ωn³·T/(10K) = Kp·ωn/10.

With Ki the characteristic polynomial is s³ + 2ζωn·s² + ωn²·s + ωn³/10 (times T): the PD
poles are exactly −ζωn ± ωn√(ζ² − 1); the integral adds a slow pole and shifts them
slightly.  For nomoto2 the first-order model is K and T = T1 + T2 − T3 (Nomoto's
approximation).

Vyshnegradsky diagram (:func:`vyshnegradsky_gains`), Xu & Guedes Soares (2020) §5.1.  The
PD law δ = Kp(ψd − ψ) − Kd·ψ̇ (eq. (17)) on the 2nd-order Nomoto model
T1T2·r̈ + (T1 + T2)·ṙ + r = K(δ + T3·δ̇) (eq. (16)) closes to the cubic (eq. (18))

    T1T2·s³ + (T1 + T2 + K·T3·Kd)·s² + (1 + K·Kd + K·T3·Kp)·s + K·Kp,

and s = ω0·q with ω0 = (K·Kp/(T1T2))^(1/3) normalises it to q³ + A·q² + B·q + 1 (eqs.
(19)–(20); the paper's eq. (20) prints s for q), stable iff A, B > 0 and AB > 1.  Eq. (21)
gives A and B in terms of Kp and Kd; with x = (K·Kp)^(1/3) and P = T1T2, S = T1 + T2 it
reduces to one polynomial in x,

    T3²·x³ − B·T3·P^(1/3)·x² + A·P^(2/3)·x + (T3 − S) = 0,

then Kp = x³/K and K·Kd = B·P^(1/3)·x² − 1 − T3·x³; Ki = Kp/100 (§5.2).

Reading of the paper's numbers (checked in tests/test_pid.py).  §5.2 prints, for the
identified Esso Osaka model K = 0.185 1/s, T1 = 7.8569 s, T2 = 0.3815 s, T3 = 0.5297 s,
"the control parameters … are 212.6 and 547.8, respectively".  Read as (Kp, Kd) these do
not satisfy eq. (21) with the stated A = B = 4 (they give A = 8.76, B = 7.39); eq. (21) with
A = B = 4 has the single real solution Kp = 2167.5, Kd = 541.7.  With A = B = 3 — "the ideal
value" the paper names just before choosing (4, 4) — eq. (21) gives Kp = 547.85,
Kd = 212.66: the printed numbers truncated to one decimal (212.66 → 212.6), listed Kd
first.  So the printed gains are the (3, 3) design.  Default here: the stated design A = B = 4
(:data:`VYSHNEGRADSKY_AB_STATED`); :data:`VYSHNEGRADSKY_AB_PRINTED` = (3, 3) reproduces
the printed gains.  The angle unit does not matter (Kp is rad/rad = deg/deg, Kd in s).

Choices where the paper is silent: when the cubic has several positive roots with Kp, Kd
> 0 (it can for larger A, B; for (3, 3) and (4, 4) on every model we use it has one), the
smallest-gain one is taken (:func:`vyshnegradsky_solutions` lists all).  The design, like
the paper's, ignores the rudder servo and saturation.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from shipgym.angles import wrap_angle
from shipgym.numerics import SCALAR


@dataclasses.dataclass(frozen=True)
class PIDGains:
    kp: float  # [rad rudder / rad heading error]
    ki: float  # [1/s]
    kd: float  # [s]

    @classmethod
    def from_nomoto(
        cls, K: float, T: float, natural_frequency: float = 1.0, damping: float = 1.0
    ) -> PIDGains:
        """Pole placement on T·ṙ + r = K·δ; K [1/s], T [s], ωn [rad/s] (module doc).

        Xu, Oliveira & Guedes Soares (2021) §5.2: Kp = ωn²T/K, Kd = (2ζωnT − 1)/K,
        Ki = ωn³T/(10K); Kd is clipped at 0 when 2ζωnT < 1.
        """
        if K <= 0 or T <= 0 or natural_frequency <= 0:
            raise ValueError(f"need K, T, natural_frequency > 0, got {K}, {T}, {natural_frequency}")
        kp = T * natural_frequency**2 / K
        kd = max(0.0, (2.0 * damping * natural_frequency * T - 1.0) / K)
        return cls(kp=kp, ki=kp * natural_frequency / 10.0, kd=kd)


def pid_step(
    gains: PIDGains,
    integral: Any,
    desired_heading: Any,
    heading: Any,
    yaw_rate: Any,
    dt: float,
    limit: float,
    xp: Any = SCALAR,
) -> tuple[Any, Any]:
    """One period of the discrete PID heading autopilot, for one ship or N (``xp``).

    δc = Kp·ψ̃ − Kd·r + Ki·∫ψ̃ clipped to ±limit [rad], ψ̃ = wrap(ψd − ψ) [rad], r [rad/s];
    the integral [rad·s] accumulates ψ̃·dt only while the command would not saturate
    (conditional integration, anti-windup).  Returns (δc, new integral).
    """
    error = wrap_angle(desired_heading - heading)
    trial = gains.kp * error - gains.kd * yaw_rate + gains.ki * (integral + error * dt)
    integral = xp.where((-limit < trial) & (trial < limit), integral + error * dt, integral)
    raw = gains.kp * error - gains.kd * yaw_rate + gains.ki * integral
    return xp.minimum(limit, xp.maximum(-limit, raw)), integral


class HeadingPID:
    """Discrete PID heading autopilot with rudder saturation and anti-windup (:func:`pid_step`).

    ``command`` is called once per control period dt [s]; returns δc [rad] in ±limit.
    """

    def __init__(self, gains: PIDGains, rudder_limit: float) -> None:
        self.gains = gains
        self.rudder_limit = rudder_limit
        self.integral = 0.0

    def reset(self) -> None:
        self.integral = 0.0

    def command(self, desired_heading: float, heading: float, yaw_rate: float, dt: float) -> float:
        delta_c, self.integral = pid_step(
            self.gains, self.integral, desired_heading, heading, yaw_rate, dt, self.rudder_limit
        )
        return delta_c


# --------------------------------------------------------------------------------------------
# Vyshnegradsky diagram — Xu & Guedes Soares (2020) §5.1, eqs. (16)–(21)
# --------------------------------------------------------------------------------------------
#: (A, B) the paper states it uses (§5.1: "(A = 4, B = 4) will be used")
VYSHNEGRADSKY_AB_STATED: tuple[float, float] = (4.0, 4.0)
#: (A, B) that reproduce the gains the paper prints (§5.2: 212.6 and 547.8; module doc)
VYSHNEGRADSKY_AB_PRINTED: tuple[float, float] = (3.0, 3.0)


def nomoto2_pd_characteristic(
    K: float, T1: float, T2: float, T3: float, kp: float, kd: float
) -> np.ndarray:
    """Coefficients (highest power first) of the PD closed loop — Xu & Guedes Soares (2020)
    eq. (18): T1T2·s³ + (T1 + T2 + K·T3·Kd)·s² + (1 + K·Kd + K·T3·Kp)·s + K·Kp."""
    return np.array(
        [T1 * T2, T1 + T2 + K * T3 * kd, 1.0 + K * kd + K * T3 * kp, K * kp], dtype=np.float64
    )


def vyshnegradsky_parameters(coefficients: np.ndarray) -> tuple[float, float]:
    """Vyshnegradsky parameters (A, B) of a cubic a0·s³ + a1·s² + a2·s + a3.

    s = ω0·q with ω0 = (a3/a0)^(1/3) gives q³ + A·q² + B·q + 1: A = a1/(a0·ω0),
    B = a2/(a0·ω0²) (Xu & Guedes Soares 2020 eqs. (19)–(21)).  Needs a0, a3 > 0.
    """
    a0, a1, a2, a3 = (float(c) for c in coefficients)
    if not (a0 > 0.0 and a3 > 0.0):
        raise ValueError(f"need a0 > 0 and a3 > 0 for the normalisation, got {a0}, {a3}")
    w0 = (a3 / a0) ** (1.0 / 3.0)
    return a1 / (a0 * w0), a2 / (a0 * w0 * w0)


def vyshnegradsky_solutions(
    K: float, T1: float, T2: float, T3: float, A: float = 4.0, B: float = 4.0
) -> list[tuple[float, float]]:
    """All (Kp, Kd) with Kp, Kd > 0 solving eq. (21) for the given (A, B), smallest Kp first.

    K [1/s], T1, T2 [s] > 0, T3 [s] (any sign); Kp [rad/rad], Kd [s].  Raises ValueError
    for bad model parameters or an (A, B) outside the stable region A, B > 0, AB > 1.
    """
    for name, value in (("K", K), ("T1", T1), ("T2", T2)):
        if not (math.isfinite(value) and value > 0.0):
            raise ValueError(f"Vyshnegradsky design needs {name} > 0, got {value}")
    if not math.isfinite(T3):
        raise ValueError(f"Vyshnegradsky design needs a finite T3, got {T3}")
    if not (A > 0.0 and B > 0.0 and A * B > 1.0):
        raise ValueError(
            f"Vyshnegradsky parameters must satisfy A > 0, B > 0, AB > 1 "
            f"(Xu & Guedes Soares 2020 eq. (20)), got A = {A}, B = {B}"
        )
    p3 = (T1 * T2) ** (1.0 / 3.0)  # P^(1/3)
    s = T1 + T2
    # eq. (21) in x = (K·Kp)^(1/3); np.roots drops the leading zeros when T3 = 0
    roots = np.roots([T3 * T3, -B * T3 * p3, A * p3 * p3, T3 - s])
    out = []
    for x in roots:
        if abs(x.imag) > 1e-9 * max(1.0, abs(x)) or x.real <= 0.0:
            continue
        xr = float(x.real)
        kp = xr**3 / K
        kd = (B * p3 * xr * xr - 1.0 - T3 * xr**3) / K  # B equation of eq. (21)
        if kp > 0.0 and kd > 0.0:
            out.append((kp, kd))
    return sorted(out)


def vyshnegradsky_gains(
    K: float,
    T1: float,
    T2: float,
    T3: float,
    A: float = 4.0,
    B: float = 4.0,
    ki_ratio: float = 0.01,
) -> PIDGains:
    """PID gains from the Vyshnegradsky diagram — Xu & Guedes Soares (2020) §5.1–5.2.

    Solves eq. (21) for Kp, Kd so that the PD closed loop on the 2nd-order Nomoto model has
    Vyshnegradsky parameters (A, B) (default (4, 4), the paper's stated choice; (3, 3)
    reproduces its printed gains, see the module doc), and sets Ki = ki_ratio·Kp
    (Kp/100 in the paper; ki_ratio in 1/s).  The smallest-gain solution is returned when
    there are several.  K [1/s], T1, T2, T3 [s].
    """
    if not (math.isfinite(ki_ratio) and ki_ratio >= 0.0):
        raise ValueError(f"ki_ratio must be ≥ 0, got {ki_ratio}")
    solutions = vyshnegradsky_solutions(K, T1, T2, T3, A, B)
    if not solutions:
        raise ValueError(
            f"no Kp, Kd > 0 give Vyshnegradsky parameters A = {A}, B = {B} for the Nomoto "
            f"model K = {K}, T1 = {T1}, T2 = {T2}, T3 = {T3}"
        )
    kp, kd = solutions[0]
    return PIDGains(kp=kp, ki=ki_ratio * kp, kd=kd)
