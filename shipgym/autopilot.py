"""PID heading autopilot, designed by pole placement on a first-order Nomoto model.

Used inside the env in ``guidance`` action mode and by the ``pid_los`` baseline (one
definition for both).  With T·ṙ + r = K·δ and δ = Kp·ψ̃ − Kd·r + Ki∫ψ̃ (ψ̃ = ψd − ψ), the
closed loop (ignoring Ki) is T·ψ̈ + (1 + K·Kd)·ψ̇ + K·Kp·ψ = K·Kp·ψd, so a natural frequency
ωn and damping ζ give (Fossen 2011, §12.2.7):

    Kp = T·ωn²/K,   Kd = (2ζωn·T − 1)/K,   Ki = Kp·ωn/10.

For nomoto2 the first-order model is K and T = T1 + T2 − T3 (Nomoto's approximation).
"""

from __future__ import annotations

import dataclasses
import math

from shipgym.paths import wrap_angle


@dataclasses.dataclass(frozen=True)
class PIDGains:
    kp: float  # [rad rudder / rad heading error]
    ki: float  # [1/s]
    kd: float  # [s]

    @classmethod
    def from_nomoto(
        cls, K: float, T: float, natural_frequency: float = 1.0, damping: float = 1.0
    ) -> PIDGains:
        """Pole placement on T·ṙ + r = K·δ; K [1/s], T [s], ωn [rad/s]."""
        if K <= 0 or T <= 0 or natural_frequency <= 0:
            raise ValueError(f"need K, T, natural_frequency > 0, got {K}, {T}, {natural_frequency}")
        kp = T * natural_frequency**2 / K
        kd = max(0.0, (2.0 * damping * natural_frequency * T - 1.0) / K)
        return cls(kp=kp, ki=kp * natural_frequency / 10.0, kd=kd)


class HeadingPID:
    """Discrete PID heading autopilot with rudder saturation and anti-windup.

    ``command`` is called once per control period dt [s]; returns δc [rad] in ±limit.
    The integral only accumulates while the command is not saturated (conditional
    integration).
    """

    def __init__(self, gains: PIDGains, rudder_limit: float) -> None:
        self.gains = gains
        self.rudder_limit = rudder_limit
        self.integral = 0.0

    def reset(self) -> None:
        self.integral = 0.0

    def command(self, desired_heading: float, heading: float, yaw_rate: float, dt: float) -> float:
        error = float(wrap_angle(desired_heading - heading))
        g = self.gains
        unsaturated = g.kp * error - g.kd * yaw_rate + g.ki * (self.integral + error * dt)
        limit = self.rudder_limit
        if -limit < unsaturated < limit:
            self.integral += error * dt
        raw = g.kp * error - g.kd * yaw_rate + g.ki * self.integral
        return min(limit, max(-limit, raw))


def nomoto2_first_order(K: float, T1: float, T2: float, T3: float) -> tuple[float, float]:
    """Nomoto's first-order approximation (K, T = T1 + T2 − T3) of the 2nd-order model."""
    T = T1 + T2 - T3
    if not math.isfinite(T) or T <= 0:
        raise ValueError(f"first-order time constant T = T1 + T2 - T3 = {T} is not positive")
    return K, T
