"""Standard manoeuvres on any ship model: zig-zag (Kempf) and turning circle.

Simulated with the model's own CasADi RK4 step (one substep per call, so the rudder can
switch at the fine step), starting from the model's initial state at nominal speed.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from shipgym.errors import ShipgymError
from shipgym.models.base import ShipModel
from shipgym.models.integrator import PeriodIntegrator

DEG = math.pi / 180.0
#: metres per second in a knot (1852 m per hour)
KNOT = 1852.0 / 3600.0

#: the unit of each figure :func:`zigzag` and :func:`turning_circle` return (``"1"``: a
#: fraction, here of the approach speed U0)
FIGURE_UNITS: dict[str, str] = {
    "time_to_first_switch": "s",
    "overshoot_1": "deg",
    "time_overshoot_1": "s",
    "overshoot_2": "deg",
    "time_overshoot_2": "s",
    "period": "s",
    "t_90": "s",
    "advance": "m",
    "transfer": "m",
    "t_180": "s",
    "tactical_diameter": "m",
    "steady_turn_rate": "deg/s",
    "steady_speed": "m/s",
    "steady_diameter": "m",
    "speed_loss": "1",
}


class ManoeuvreError(ShipgymError, ValueError):
    """A manoeuvre's settings are impossible (a zig-zag angle ≤ 0, a rudder angle beyond the
    ship's limit)."""


def check_rudder(model: ShipModel, rudder_deg: float) -> float:
    """``rudder_deg`` in rad; a rudder beyond the ship's limit is an error, not clipped
    (the plant would saturate it silently and the figures would belong to another angle)."""
    limit = model.rudder_limit
    if not math.isfinite(rudder_deg) or abs(rudder_deg) * DEG > limit * (1.0 + 1e-9):
        raise ManoeuvreError(
            f"rudder {rudder_deg}° is beyond the {model.name} rudder limit "
            f"±{math.degrees(limit):.4g}°"
        )
    return rudder_deg * DEG


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
    #: every state at every sample, (n + 1, n_x), columns as the model's ``state_names``
    states: np.ndarray | None = None


def _simulate(
    model: ShipModel,
    command: Callable[[int, np.ndarray], float | None],
    duration: float,
    h: float,
) -> ManoeuvreLog:
    """Run the model from its cruise state with δc = command(k, x) on [kh, (k+1)h).

    ``command`` returns None to stop early.  One CasADi RK4 substep per call, so the rudder
    command can switch at the fine step.
    """
    integ = PeriodIntegrator(model, h, 1)
    p = model.params.to_vector()[None, :]
    w = np.zeros((1, model.n_disturbances))
    x = model.cruise_state()
    n = round(duration / h)
    states = np.empty((n + 1, model.n_states))
    commands = np.empty(n + 1)
    states[0] = x
    last = 0.0
    for k in range(n):
        c = command(k, x)
        if c is None:
            n = k
            break
        commands[k] = last = c
        x = integ(x, c, w, p)[-1]
        states[k + 1] = x
    states, commands = states[: n + 1], commands[: n + 1]
    commands[n] = last
    return ManoeuvreLog(
        t=h * np.arange(n + 1),
        x=states[:, model.state_index("x")],
        y=states[:, model.state_index("y")],
        psi=states[:, model.state_index("psi")],
        r=states[:, model.state_index("r")],
        delta=states[:, model.state_index("delta")],
        delta_c=commands,
        h=h,
        states=states,
    )


def zigzag(
    model: ShipModel,
    rudder_deg: float = 20.0,
    switch_deg: float | None = None,
    duration: float | None = None,
    h: float | None = None,
    n_switches: int = 6,
) -> tuple[ManoeuvreLog, dict[str, float]]:
    """A rudder_deg/switch_deg zig-zag: rudder to +δ, switch when ψ passes +ψs, and so on.

    Returns the log and the figures ``overshoot_1``, ``overshoot_2`` (deg, heading beyond
    the switch angle), ``time_overshoot_1``/``_2`` (s, of the heading extremes),
    ``period`` (s, between the first and third switch) and ``time_to_first_switch`` (s).
    Stops after ``n_switches`` or ``duration`` seconds (default: 60 ship lengths of
    travel).  Heading is measured from the initial course, positive as the model's ψ.  A
    rudder beyond the ship's limit is a :class:`ManoeuvreError`.
    """
    switch = (switch_deg if switch_deg is not None else rudder_deg) * DEG
    rudder = check_rudder(model, rudder_deg)
    if not rudder > 0 or not math.isfinite(switch) or not switch > 0:
        raise ManoeuvreError("zig-zag rudder and switch angles must be > 0")
    h = h if h is not None else model.fine_step
    duration = duration if duration is not None else 60.0 * model.length / model.nominal_speed
    ipsi = model.state_index("psi")
    psi0 = float(model.cruise_state()[ipsi])
    # follow whichever way the first command turns the ship (decided once the heading
    # has moved by a tenth of the switch angle, past any drift from a yaw bias)
    state = {"command": rudder, "sign": 0.0, "switches": 0, "times": []}

    def command(k: int, x: np.ndarray) -> float | None:
        psi = float(x[ipsi]) - psi0
        if state["sign"] == 0.0 and abs(psi) > 0.1 * switch:  # past any initial drift
            state["sign"] = math.copysign(1.0, psi)
        if state["sign"] != 0.0 and state["sign"] * psi >= switch:
            state["sign"], state["command"] = -state["sign"], -state["command"]
            state["switches"] += 1
            state["times"].append(k * h)
            if state["switches"] > n_switches:
                return None
        return state["command"]

    log = _simulate(model, command, duration, h)
    times = state["times"]
    figures: dict[str, float] = {}
    if times:
        figures["time_to_first_switch"] = times[0]
    psi = log.psi - psi0
    for i in range(min(2, len(times) - 1)):
        a, b = round(times[i] / h), round(times[i + 1] / h)
        segment = np.abs(psi[a : b + 1])
        j = int(np.argmax(segment))
        figures[f"overshoot_{i + 1}"] = (float(segment[j]) - switch) / DEG
        figures[f"time_overshoot_{i + 1}"] = float(log.t[a + j])
    if len(times) >= 3:
        figures["period"] = times[2] - times[0]
    return log, figures


def _crossing(t: np.ndarray, values: np.ndarray, level: float) -> float | None:
    """First time ``values`` reaches ``level`` (linear interpolation), None if never."""
    idx = np.flatnonzero(values >= level)
    if idx.size == 0:
        return None
    k = int(idx[0])
    if k == 0:
        return float(t[0])
    v0, v1 = values[k - 1], values[k]
    return float(t[k - 1] + (level - v0) / (v1 - v0) * (t[k] - t[k - 1]))


def turning_circle(
    model: ShipModel,
    rudder_deg: float | None = None,
    execute_time: float = 0.0,
    duration: float | None = None,
    h: float | None = None,
) -> tuple[ManoeuvreLog, dict[str, float]]:
    """Turning circle: straight ahead at nominal speed, δc = rudder_deg from ``execute_time``
    (default 35° or the ship's smaller rudder limit; beyond the limit: :class:`ManoeuvreError`).

    Figures (SI; distances from the execute point along / across the approach course,
    times from execute; the turn direction is whichever way the ship turns):
    ``advance`` and ``transfer`` at 90° heading change, ``tactical_diameter`` (transfer at
    180°), ``t_90``, ``t_180``; over the last full 360° of the run: ``steady_turn_rate``
    (deg/s, signed as the model's ψ), ``steady_speed`` (m/s, over ground),
    ``steady_diameter`` (2·U/|r|, m) and ``speed_loss`` (1 − U/U0).  The run lasts until
    the heading has changed by 720° or ``duration`` (default 200 L/U0) has passed.
    """
    h = h if h is not None else model.fine_step
    duration = duration if duration is not None else 200.0 * model.length / model.nominal_speed
    if rudder_deg is None:
        rudder_deg = min(35.0, math.degrees(model.rudder_limit))
    rudder = check_rudder(model, rudder_deg)
    ipsi = model.state_index("psi")
    psi0 = float(model.cruise_state()[ipsi])
    k_exec = round(execute_time / h)

    def command(k: int, x: np.ndarray) -> float | None:
        if abs(float(x[ipsi]) - psi0) >= 4.0 * math.pi:
            return None
        return rudder if k >= k_exec else 0.0

    log = _simulate(model, command, duration, h)
    i0 = k_exec
    t = log.t[i0:] - log.t[i0]
    dpsi = np.unwrap(log.psi[i0:]) - log.psi[i0]
    direction = math.copysign(1.0, float(dpsi[-1])) if dpsi[-1] != 0 else 1.0
    turned = direction * dpsi
    heading0 = psi0
    dx, dy = log.x[i0:] - log.x[i0], log.y[i0:] - log.y[i0]
    along = dx * math.cos(heading0) + dy * math.sin(heading0)
    across = direction * (-dx * math.sin(heading0) + dy * math.cos(heading0))
    figures: dict[str, float] = {}
    for angle, label in ((math.pi / 2, "90"), (math.pi, "180")):
        tc = _crossing(t, turned, angle)
        if tc is None:
            continue
        figures[f"t_{label}"] = tc
        a = float(np.interp(tc, t, along))
        c = float(np.interp(tc, t, across))
        if label == "90":
            figures["advance"], figures["transfer"] = a, c
        else:
            figures["tactical_diameter"] = c
    speed = np.sqrt(np.diff(log.x) ** 2 + np.diff(log.y) ** 2) / log.h
    if turned[-1] >= 2.0 * math.pi + 1e-9 and speed.size:
        t_last = float(t[-1])
        t_start = _crossing(t, turned, float(turned[-1]) - 2.0 * math.pi)
        sel = t[1:] >= t_start if t_start is not None else slice(None)
        u_ss = float(np.mean(speed[i0:][sel]))
        r_ss = (float(dpsi[-1]) - float(np.interp(t_start, t, dpsi))) / (t_last - t_start)
        figures["steady_turn_rate"] = r_ss / DEG
        figures["steady_speed"] = u_ss
        figures["steady_diameter"] = 2.0 * u_ss / abs(r_ss)
        figures["speed_loss"] = 1.0 - u_ss / model.nominal_speed
    return log, figures


#: the longest line [characters] of the time-series panel's title of figures
TITLE_LINE_CHARS = 48


def figures_title(figures: dict[str, float], width: int = TITLE_LINE_CHARS) -> str:
    """The figures as "name value unit", comma-separated, broken between figures into lines
    of at most ``width`` characters (a single longer figure keeps a line of its own)."""
    lines: list[str] = []
    for k, v in figures.items():
        item = f"{k} {v:.4g} {FIGURE_UNITS.get(k, '')}".rstrip()
        if lines and len(lines[-1]) + len(", ") + len(item) <= width:
            lines[-1] += f", {item}"
        else:
            if lines:
                lines[-1] += ","
            lines.append(item)
    return "\n".join(lines)


def manoeuvre_figure(
    model: ShipModel, kind: str, log: ManoeuvreLog, figures: dict[str, float]
) -> Any:
    """The figure of a manoeuvre: its track, and heading ψ and rudder δ [deg] over time
    under the figures (:func:`figures_title`)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    axes[0].plot(log.y, log.x, lw=1.2)
    axes[0].set(xlabel="y [m]", ylabel="x [m]", title=f"{model.name}: {kind} track")
    axes[0].set_aspect("equal", adjustable="datalim")
    axes[1].plot(log.t, np.degrees(log.psi), label="ψ [deg]")
    axes[1].plot(log.t, np.degrees(log.delta), label="δ [deg]")
    axes[1].set_xlabel("t [s]")
    axes[1].set_title(figures_title(figures), fontsize=10)
    axes[1].legend()
    fig.tight_layout()
    return fig


def plot_manoeuvre(
    model: ShipModel, kind: str, log: ManoeuvreLog, figures: dict[str, float], path: str
) -> None:
    """Track and heading/rudder time series of a manoeuvre (:func:`manoeuvre_figure`),
    saved to ``path`` (PNG)."""
    import matplotlib.pyplot as plt

    fig = manoeuvre_figure(model, kind, log, figures)
    fig.savefig(path, dpi=90)
    plt.close(fig)
