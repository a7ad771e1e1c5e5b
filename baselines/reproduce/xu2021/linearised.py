"""Xu et al. (2021) §3–4: the law (35) with exact estimates on its design model, at r = 0."""

from __future__ import annotations

import math
from typing import Any

import gymnasium as gym
import numpy as np
import scipy.optimize

from shipgym.identification.nominal import first_order_nomoto
from shipgym_baselines.classical.adaptive.design_model import nominal_design_model
from shipgym_baselines.classical.adaptive.loop_analysis import linearised_closed_loop_poles
from shipgym_baselines.classical.adaptive.settings import Gains, L1BacksteppingSettings
from shipgym_baselines.classical.pid import PIDTVVF
from shipgym_baselines.reproduce.xu2021.controllers import AB, L1, L1_ADAPTIVE, PID


def loop_margins(num: np.ndarray, den: np.ndarray) -> tuple[float, float]:
    """(crossover [rad/s], phase margin [deg]) of the open loop L(s) = num(s)/den(s).

    The crossover is the highest frequency with |L(jω)| = 1 (bracketed on a log grid over
    1e-4…1e3 rad/s, refined by Brent's method); NaN if |L| never crosses 1 there.
    """

    def log_gain(w: float) -> float:
        return math.log(abs(np.polyval(num, 1j * w) / np.polyval(den, 1j * w)))

    grid = np.logspace(-4, 3, 4000)
    gain = np.array([log_gain(w) for w in grid])
    cross = np.flatnonzero(np.sign(gain[:-1]) != np.sign(gain[1:]))
    if cross.size == 0:
        return math.nan, math.nan
    i = int(cross[-1])
    wc = float(scipy.optimize.brentq(log_gain, grid[i], grid[i + 1]))
    phase = math.degrees(np.angle(np.polyval(num, 1j * wc) / np.polyval(den, 1j * wc)))
    return wc, float((phase + 360.0) % 360.0 - 180.0)


def linear_analysis(scenario: Any) -> dict[str, dict[str, float]]:
    """Per controller label: largest closed-loop pole real part [1/s], crossover [rad/s] and
    phase margin [deg] of the loop linearised on the design model (module doc).

    L1 variants and adaptive backstepping: eq. (35) with exact estimates is the PD law
    δ = −(Kp·z1 + Kd·r), Kp = (c + K1K2)/K, Kd = (K2 + T·K1 − 1)/K, on K/(s(Ts + 1)) with
    C(s) in series for ``l1_backstepping``; with the ``adaptive`` placement the filtered
    share is zero at exact estimates and C(s) drops out of the loop.  PID: its gains on its
    first-order Nomoto design model, L = K(Kd·s² + Kp·s + Ki)/(s²(Ts + 1)).
    """
    env = gym.make("ShipPathFollow-v0", scenario=scenario, randomize=False)
    try:
        env.reset(seed=0)
        ctx = env.unwrapped.controller_context
    finally:
        env.close()
    model = nominal_design_model(ctx.nominal_model)
    s = L1BacksteppingSettings()
    gains = Gains.transfer(s, ctx.ship_length, ctx.nominal_speed, ctx.guidance.tvvf_error_unit)
    kp = (gains.z1_weight + gains.K1 * gains.K2) / model.K
    kd = (gains.K2 + model.T * gains.K1 - 1.0) / model.K
    plant_den = np.array([model.T, 1.0, 0.0])
    out: dict[str, dict[str, float]] = {}
    for label, w in ((L1, gains.filter_frequency), (L1_ADAPTIVE, None), (AB, None)):
        num, den = model.K * np.array([kd, kp]), plant_den
        if w is not None:
            num = num * w * w
            den = np.polymul(den, [1.0, 2.0 * s.filter_damping * w, w * w])
        poles = linearised_closed_loop_poles(model, gains, w, s.filter_damping)
        wc, pm = loop_margins(num, den)
        out[label] = {"max_pole_real": float(poles.real.max()), "crossover": wc, "phase_margin": pm}
    pid = PIDTVVF(preset="paper")
    pid.reset(ctx)
    K, T = first_order_nomoto(ctx.nominal_model)
    g = pid.gains
    num, den = K * np.array([g.kd, g.kp, g.ki]), np.array([T, 1.0, 0.0, 0.0])
    poles = np.roots(np.polyadd(den, num))
    wc, pm = loop_margins(num, den)
    out[PID] = {"max_pole_real": float(poles.real.max()), "crossover": wc, "phase_margin": pm}
    return out
