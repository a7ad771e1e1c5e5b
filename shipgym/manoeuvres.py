"""Standard manoeuvres on any ship model: zig-zag (Kempf) and turning circle.

Simulated with the model's own CasADi RK4 step (one substep per call, so the rudder can
switch at the fine step), starting from the model's initial state at nominal speed.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from shipgym.models.base import ShipModel
from shipgym.models.integrator import PeriodIntegrator

DEG = math.pi / 180.0


@dataclasses.dataclass(frozen=True)
class ManoeuvreLog:
    """Sampled manoeuvre (SI, rad): states at t = 0, h, 2h, …; ``delta_c`` acts on [t, t+h)."""

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    psi: np.ndarray
    r: np.ndarray
    delta: np.ndarray
    delta_c: np.ndarray
    h: float


def zigzag(
    model: ShipModel,
    rudder_deg: float = 20.0,
    switch_deg: float | None = None,
    duration: float | None = None,
    h: float | None = None,
    n_switches: int = 6,
) -> tuple[ManoeuvreLog, dict[str, float]]:
    """A rudder_deg/switch_deg zig-zag: rudder to +δ, switch when ψ passes +ψs, and so on.

    Returns the log and the figures ``overshoot_1``, ``overshoot_2`` (deg) and
    ``period`` (s, between the first and third switch).  Stops after ``n_switches`` or
    ``duration`` seconds (default: 60 ship lengths of travel).
    """
    switch = (switch_deg if switch_deg is not None else rudder_deg) * DEG
    rudder = rudder_deg * DEG
    if rudder <= 0 or switch <= 0:
        raise ValueError("zig-zag rudder and switch angles must be > 0")
    h = h if h is not None else model.fine_step
    duration = duration if duration is not None else 60.0 * model.length / model.nominal_speed
    integ = PeriodIntegrator(model, h, 1)
    p = model.params.to_vector()[None, :]
    w = np.zeros((1, model.n_disturbances))
    x = model.initial_state()
    ipsi, ir, idel = model.state_index("psi"), model.state_index("r"), model.state_index("delta")
    n = round(duration / h)
    states = np.empty((n + 1, model.n_states))
    commands = np.empty(n + 1)
    states[0] = x
    command, sign, switches, switch_times = rudder, 1.0, 0, []
    extremes: list[float] = []
    peak = 0.0
    for k in range(n):
        psi = x[ipsi]
        if sign * psi >= switch:  # heading passed the switch angle: reverse the rudder
            sign, command = -sign, -command
            switches += 1
            switch_times.append(k * h)
            if switches > 1:
                extremes.append(peak)
            peak = psi
            if switches > n_switches:
                n = k
                break
        peak = max(peak, psi) if sign < 0 else min(peak, psi)
        commands[k] = command
        x = integ(x, command, w, p)[-1]
        states[k + 1] = x
    states, commands = states[: n + 1], commands[: n + 1]
    commands[n] = command
    log = ManoeuvreLog(
        t=h * np.arange(n + 1),
        x=states[:, model.state_index("x")],
        y=states[:, model.state_index("y")],
        psi=states[:, ipsi],
        r=states[:, ir],
        delta=states[:, idel],
        delta_c=commands,
        h=h,
    )
    figures: dict[str, float] = {}
    for i, ext in enumerate(extremes[:2], start=1):
        figures[f"overshoot_{i}"] = (abs(ext) - switch) / DEG
    if len(switch_times) >= 3:
        figures["period"] = switch_times[2] - switch_times[0]
    return log, figures
