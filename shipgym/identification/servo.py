"""The rudder servo identified from its measured input and output.

Every ship's steering gear is a first-order lag behind the saturated command with a rate
limit (nomoto2: eq. (2) with Kc = 1 and no rate limit)::

    δ̇ = clip((clip(δc, ±δmax) − δ)/T, ±δ̇max)

and both its input δc and its output δ are measured (``info["samples"]``: δ and δc at every
fine step h).  :class:`ServoFit` estimates (T, δ̇max) by least squares over a window of
those samples, each predicted by the RK4 step of the env's integrator at h, so that the
residual is exactly zero at the truth.

Why not in the augmented EKF: when the servo slows (rudder aging: T × 3–60 with δ̇max ×
1/3–1/2), a prediction from the nominal servo is rate-limited wherever |δc − δ| > δ̇max·T, so
∂δ⁺/∂T = 0 there and the filter explains the slow rudder by a lower rate limit alone; once
that estimate is low, every prediction is rate-limited and T is never observed (measured on
``mariner_rudder_aging``: the rate limit estimated at ×0.10 and T at ×0.6 for 120 s after
the change, cost 1743 against the oracle's 140).  The fit here starts, besides from its
previous estimate, from the closed-form lag that ignores the limit (1/T = Σ eΔ / Σ e², e =
δc − δ, Δ the measured rate), and keeps the better of the two: that start sees T directly.
"""

from __future__ import annotations

import collections
import math

import numpy as np
from scipy.optimize import least_squares

from shipgym.models.base import ShipModel, rk4_step


def servo_step(
    delta: np.ndarray, target: np.ndarray, time_constant: float, rate: float, h: float
) -> np.ndarray:
    """δ after one RK4 step (:func:`shipgym.models.base.rk4_step`, the env's) of h [s] of
    δ̇ = clip((target − δ)/T, ±rate) (rad, s, rad/s; ``rate`` inf: no limit), elementwise."""

    def f(d: np.ndarray, u: np.ndarray, w: object, p: object) -> np.ndarray:
        return np.clip((u - d) / time_constant, -rate, rate)

    return rk4_step(f, delta, target, None, None, h)


class ServoFit:
    """Windowed least squares of (T, δ̇max) (module doc).

    ``time_constant`` [s] and ``rate`` [rad/s] (inf: none) are the nominal servo's, where
    the fit starts; ``factors`` bound the estimates as factors on them ((low, high) for T,
    then for the rate); ``window`` [samples] the fine samples kept; ``limit`` [rad] δmax.
    """

    def __init__(
        self,
        time_constant: float,
        rate: float,
        step: float,
        window: int,
        limit: float,
        factors: tuple[tuple[float, float], tuple[float, float]],
    ) -> None:
        self.nominal = (time_constant, rate)
        self.h, self.limit = step, limit
        self.has_rate = math.isfinite(rate)
        (t_lo, t_hi), (r_lo, r_hi) = factors
        self.lower = np.log([time_constant * t_lo, rate * r_lo if self.has_rate else 1.0])
        self.upper = np.log([time_constant * t_hi, rate * r_hi if self.has_rate else 2.0])
        self._delta: collections.deque[float] = collections.deque(maxlen=window + 1)
        self._command: collections.deque[float] = collections.deque(maxlen=window)
        self.estimate = (time_constant, rate)
        #: RMS residual [rad/s] below which the previous estimate is kept without a fit:
        #: 1e-4 of the nominal servo's fastest slope
        self.tolerance = 1e-4 * 2.0 * limit / time_constant

    def add(self, delta: np.ndarray, command: np.ndarray, delta_end: float) -> None:
        """One control period's fine samples: δ and δc at the substep starts [rad], and δ
        at the period's end (the next period's first sample)."""
        if self._delta:
            self._delta.pop()  # the previous period's end is this period's first sample
        self._delta.extend(float(d) for d in delta)
        self._delta.append(float(delta_end))
        self._command.extend(float(c) for c in command)

    def _residual(self, log_values: np.ndarray, d: np.ndarray, target: np.ndarray) -> np.ndarray:
        t, rate = np.exp(log_values)
        rate = rate if self.has_rate else math.inf
        return (servo_step(d[:-1], target, t, rate, self.h) - d[1:]) / self.h

    def fit(self) -> tuple[float, float]:
        """(T [s], δ̇max [rad/s]) over the window; the previous estimate where the samples
        say nothing (a rudder at rest on its command) or where it explains them (RMS
        residual below ``tolerance``)."""
        d = np.array(self._delta)
        target = np.clip(np.array(self._command), -self.limit, self.limit)
        if d.size < 3:
            return self.estimate
        error = target - d[:-1]
        slope = np.diff(d) / self.h
        if float(np.max(np.abs(error))) < 1e-6:
            return self.estimate
        previous = np.log([self.estimate[0], self.estimate[1] if self.has_rate else 1.5])
        residual = self._residual(previous, d, target)
        if float(np.sqrt(np.mean(residual**2))) <= self.tolerance:
            return self.estimate  # the window's samples are the previous estimate's
        starts = [previous]
        along = float(error @ slope)
        if along > 0.0:  # the lag that ignores the limit: 1/T = Σ eΔ / Σ e²
            free = float(error @ error) / along
            fastest = float(np.max(np.abs(slope)))
            starts.append(np.log([free, 1.5 * fastest if self.has_rate else 1.5]))
        best = None
        for start in starts:
            x0 = np.clip(start, self.lower + 1e-9, self.upper - 1e-9)
            if not self.has_rate:
                x0[1] = 0.0
            fit = least_squares(
                self._residual,
                x0,
                bounds=(self.lower, self.upper),
                args=(d, target),
                x_scale=1.0,
                max_nfev=50,
            )
            if best is None or fit.cost < best.cost:
                best = fit
        t, rate = np.exp(best.x)
        self.estimate = (float(t), float(rate) if self.has_rate else math.inf)
        return self.estimate


def servo_constants(model: ShipModel, params: np.ndarray, limit: float) -> tuple[float, float]:
    """(T [s], δ̇max [rad/s]; inf: no limit) of ``model``'s servo with the parameter vector
    ``params``, read off its right-hand side's δ row (module doc's form): δ̇ at a small
    error gives T, δ̇ from −δmax to +δmax the rate limit if it binds there."""
    index = model.state_index("delta")
    x = np.tile(model.cruise_state()[:, None], (1, 2))
    x[index] = (0.0, -limit)
    command = np.array([1e-4, limit])
    w = np.zeros((model.n_disturbances, 2))
    p = np.tile(params[:, None], (1, 2))
    small, full = model.f_numpy(x, [command], w, p)[index]
    time_constant = 1e-4 / float(small)
    unlimited = 2.0 * limit / time_constant
    return time_constant, float(full) if float(full) < 0.999 * unlimited else math.inf
