"""Matplotlib rendering of the env: path, track, ship outline, current error (headless)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np


def ship_outline(x: float, y: float, psi: float, length: float) -> np.ndarray:
    """Closed polygon (6, 2) of a ship hull of length L [m] at pose (x, y, ψ)."""
    b = 0.25 * length
    hull = np.array(
        [[0.5, 0.0], [0.25, 0.5], [-0.5, 0.5], [-0.5, -0.5], [0.25, -0.5], [0.5, 0.0]]
    ) * np.array([length, b])
    c, s = math.cos(psi), math.sin(psi)
    rot = np.array([[c, -s], [s, c]])
    return hull @ rot.T + np.array([x, y])


def render_frame(env: Any, fig: Any, mode: str) -> tuple[Any, np.ndarray | None]:
    """Draw the env's current state; returns (figure, RGB array or None for ``human``)."""
    import matplotlib

    if mode == "rgb_array" and fig is None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        fig = Figure(figsize=(6, 4.5), dpi=80)
        FigureCanvasAgg(fig)
    elif fig is None:
        import matplotlib.pyplot as plt

        plt.ion()
        fig = plt.figure(figsize=(6, 4.5), dpi=80)
    fig.clear()
    ax = fig.add_subplot(111)
    path = env.scenario.path
    s = np.linspace(0.0, path.length, 400)
    pts = path.point(s)
    ax.plot(pts[:, 0], pts[:, 1], "k--", lw=1, label="path")
    wp = np.asarray(path.waypoints)
    ax.plot(wp[:, 0], wp[:, 1], "ko", ms=3)
    track = env.track
    ax.plot(track[:, 0], track[:, 1], "b-", lw=1.2, label="track")
    hull = ship_outline(*env.pose, env.scenario.ship_length)
    ax.fill(hull[:, 0], hull[:, 1], color="tab:red", alpha=0.8)
    frame = env.frame
    ax.set_title(
        f"{env.scenario.name}  t = {env.time:.1f} s  e = {frame.cross_track:+.3f} m", fontsize=9
    )
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend(loc="upper left", fontsize=7)
    if mode == "human":
        import matplotlib.pyplot as plt

        if matplotlib.get_backend().lower() != "agg":
            plt.pause(1.0 / env.metadata["render_fps"])
        return fig, None
    fig.canvas.draw()
    image = np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()
    return fig, image
