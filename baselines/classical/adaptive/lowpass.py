"""Low-pass filter C(s) of the L1 controller — Xu, Oliveira & Guedes Soares (2021) eq. (39).

C(s) = ω²/(s² + 2ζωs + ω²), unit DC gain (ω = 0.25 rad/s, ζ = 1 in §5.2).  Sampled at the
control period Ts with its input held (ZOH): the filter states at the sample instants are
those of C(s)'s exact continuous response, and the value returned for [t_k, t_k + Ts) is
the period average (1/Ts)∫y dt of the continuous output (exact ZOH discretisation, by the
matrix exponential, of C(s) in controllable form augmented with ∫y).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg


def low_pass_transfer_function(frequency: float, damping: float) -> tuple[np.ndarray, np.ndarray]:
    """(num, den) of C(s) = ω²/(s² + 2ζωs + ω²), ω [rad/s], for scipy.signal / numpy."""
    w = frequency
    return np.array([w * w]), np.array([1.0, 2.0 * damping * w, w * w])


class SecondOrderLowPass:
    """C(s) (eq. (39)) sampled at period Ts [s] with the input held (module doc).

    :meth:`step` returns the period average of C(s)'s exact continuous output,
    (1/Ts)∫y dt over [t_k, t_k + Ts), and advances the state to t_k + Ts.
    """

    def __init__(self, frequency: float, damping: float, period: float) -> None:
        if not (frequency > 0 and damping > 0 and period > 0):
            raise ValueError(
                f"need frequency, damping, period > 0, got {frequency}, {damping}, {period}"
            )
        self.frequency, self.damping, self.period = frequency, damping, period
        num, den = self.transfer_function()
        # states [y, ẏ, ∫y]; ÿ = −den[2]·y − den[1]·ẏ + num[0]·u
        a = np.array([[0.0, 1.0, 0.0], [-den[2], -den[1], 0.0], [1.0, 0.0, 0.0]])
        b = np.array([[0.0], [num[0]], [0.0]])
        m = np.zeros((4, 4))
        m[:3, :3], m[:3, 3:] = a, b
        e = scipy.linalg.expm(m * period)
        self._ad, self._bd = e[:3, :3], e[:3, 3]
        self.state = np.zeros(3)

    def transfer_function(self) -> tuple[np.ndarray, np.ndarray]:
        """(num, den) of C(s) for scipy.signal."""
        return low_pass_transfer_function(self.frequency, self.damping)

    def reset(self, output: float = 0.0) -> None:
        """At rest at ``output`` (the steady state for a constant input of that value)."""
        self.state = np.array([output, 0.0, 0.0])

    @property
    def output(self) -> float:
        """y(t) at the current sample instant."""
        return float(self.state[0])

    def step(self, u: float) -> float:
        """Hold u over one period; return the period-average output."""
        nxt = self._ad @ np.array([self.state[0], self.state[1], 0.0]) + self._bd * u
        self.state = np.array([nxt[0], nxt[1], 0.0])
        return float(nxt[2]) / self.period
