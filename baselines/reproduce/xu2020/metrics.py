"""Xu & Guedes Soares (2020) Tables 2–3: the figures of one episode (signed and absolute)."""

from __future__ import annotations

import math

import numpy as np

from shipgym.angles import wrap_angle
from shipgym_baselines.records.episodes import EpisodeResult

#: per-episode figures: metric -> (quantity of PUBLISHED or None, statistic, unit)
EPISODE_METRICS = {
    "mean_cross_track": ("cross_track", 0, "m"),
    "std_cross_track": ("cross_track", 1, "m"),
    "mean_abs_cross_track": ("cross_track", 0, "m"),
    "std_abs_cross_track": ("cross_track", 1, "m"),
    "mean_heading_error_deg": ("heading_error", 0, "deg"),
    "std_heading_error_deg": ("heading_error", 1, "deg"),
    "mean_abs_heading_error_deg": ("heading_error", 0, "deg"),
    "std_abs_heading_error_deg": ("heading_error", 1, "deg"),
    "mean_rudder_deg": ("rudder", 0, "deg"),
    "std_rudder_deg": ("rudder", 1, "deg"),
    "mean_abs_rudder_deg": ("rudder", 0, "deg"),
    "std_abs_rudder_deg": ("rudder", 1, "deg"),
    "mean_abs_path_heading_error_deg": (None, 0, "deg"),
    "max_abs_cross_track": (None, 0, "m"),
    "duration": (None, 0, "s"),
    "success": (None, 0, "-"),
    "pid_kp": (None, 0, "rad/rad"),
    "pid_kd": (None, 0, "s"),
}


def episode_figures(result: EpisodeResult, desired: list[float]) -> dict[str, float]:
    """The figures of :data:`EPISODE_METRICS` for one episode (module doc: samples, units).

    ``desired``: ψd [rad] at each control step (the controller's log).
    """
    tr, m = result.trajectory, result.metrics
    gains = m.get("controller_stats") or {}  # the controller's own figures: its PID gains
    e = tr["cross_track_error"][1:]
    delta = np.degrees(tr["rudder_angle"][1:])
    n = len(desired)
    psi_err = np.degrees(wrap_angle(np.asarray(desired) - tr["heading"][:n]))
    return {
        "mean_cross_track": float(np.mean(e)),
        "std_cross_track": float(np.std(e)),
        "mean_abs_cross_track": float(m["mean_abs_cross_track"]),
        "std_abs_cross_track": float(m["std_abs_cross_track"]),
        "mean_heading_error_deg": float(np.mean(psi_err)),
        "std_heading_error_deg": float(np.std(psi_err)),
        "mean_abs_heading_error_deg": float(np.mean(np.abs(psi_err))),
        "std_abs_heading_error_deg": float(np.std(np.abs(psi_err))),
        "mean_rudder_deg": float(np.mean(delta)),
        "std_rudder_deg": float(np.std(delta)),
        "mean_abs_rudder_deg": math.degrees(m["mean_abs_rudder"]),
        "std_abs_rudder_deg": math.degrees(m["std_abs_rudder"]),
        "mean_abs_path_heading_error_deg": math.degrees(m["mean_abs_heading_error"]),
        "max_abs_cross_track": float(m["max_abs_cross_track"]),
        "duration": float(m["duration"]),
        "success": float(bool(m["success"])),
        "pid_kp": float(gains["pid_kp"]),
        "pid_kd": float(gains["pid_kd"]),
    }
