"""Xu et al. (2021) §5.2: the figures of one episode, per current phase."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from shipgym.angles import wrap_angle
from shipgym.metrics import high_frequency_power
from shipgym.tracking import PathTracker
from shipgym_baselines.records.episodes import CONTROLLER_STATS, EpisodeResult
from shipgym_baselines.reproduce.xu2021.controllers import Recorded
from shipgym_baselines.reproduce.xu2021.scenario import switch_time

#: the HF band: above the filter corner ω = 0.25 rad/s of eq. (39) (Xu et al. 2021 §5.2)
CUTOFF = 0.25  # [rad/s]
#: a second band, above 4ω, where C(s) attenuates by more than 24 dB
CUTOFF_HIGH = 1.0  # [rad/s]
PHASES = ("weak_current", "strong_current", "episode")
DEG = 180.0 / math.pi

#: per-phase metrics: name -> (unit, description) for the table
METRICS = {
    "ace": ("m", "ACE = mean |e|"),
    "std_abs_e": ("m", "std |e|"),
    "max_abs_e": ("m", "max |e|"),
    "mean_abs_heading_error_deg": ("°", "mean |ψ − γp|"),
    "mean_abs_reference_error_deg": ("°", "mean |ψ − ψd|"),
    "rms_reference_error_deg": ("°", "RMS ψ − ψd"),
    "mean_abs_rudder_deg": ("°", "mean |δ|"),
    "rms_rudder_deg": ("°", "RMS δ"),
    "mean_abs_rudder_rate_deg_s": ("°/s", "mean |δ̇|"),
    "command_hf_rms_deg": ("°", "δc RMS above 0.25 rad/s"),
    "rudder_hf_rms_deg": ("°", "δ RMS above 0.25 rad/s"),
    "command_hf1_rms_deg": ("°", "δc RMS above 1 rad/s"),
    "rudder_hf1_rms_deg": ("°", "δ RMS above 1 rad/s"),
    "drift_std_deg": ("°", "std β (over ground)"),
    "drift_hf_rms_deg": ("°", "β RMS above 0.25 rad/s"),
    "settle_time_s": ("s", "settling after a waypoint switch (mean, ∞ if one never)"),
    "settled_fraction": ("", "share of switches after which |e| settles"),
    "settle_time_settled_s": ("s", "settling, mean over the settled switches"),
    "b_hat_hf_rms_deg_s": ("°/s", "b̂ RMS above 0.25 rad/s"),
}
#: episode-only metrics straight from the leaderboard's metrics
EPISODE_METRICS = ("success", "duration", "J")
#: the L1 controllers' episode_stats: final estimates and the predictor's mean |r̃| [rad/s]
ADAPTIVE_METRICS = ("rho_hat", "sigma_hat", "b_hat", "mean_abs_r_prediction_error")


def _hf_rms(x: np.ndarray, dt: float, cutoff: float = CUTOFF) -> float:
    """RMS [unit of x] of x above ``cutoff`` [rad/s]; NaN for fewer than 8 samples."""
    if x.size < 8:
        return math.nan
    return math.sqrt(high_frequency_power(x, dt, cutoff))


def _settle_times(t: np.ndarray, abs_e: np.ndarray, legs: np.ndarray, thr: float) -> list[tuple]:
    """(switch time [s], settling time [s]) per waypoint switch: from the switch to the first
    sample of the final below-``thr`` run before the next switch (inf if |e| ends above)."""
    starts = np.flatnonzero(np.diff(legs) != 0) + 1
    out = []
    for i, s in enumerate(starts):
        end = starts[i + 1] if i + 1 < len(starts) else len(t)
        below = abs_e[s:end] < thr
        if below.size == 0:
            continue
        if not below[-1]:
            out.append((float(t[s]), math.inf))
            continue
        above = np.flatnonzero(~below)
        first = s if above.size == 0 else s + int(above[-1]) + 1
        out.append((float(t[s]), float(t[first] - t[s])))
    return out


def episode_figures(
    scenario: Any, result: EpisodeResult, recorder: Recorded
) -> dict[str, dict[str, Any]]:
    """{phase: {metric: value}} of one episode (module doc), SI except the named units."""
    tr = result.trajectory
    dt = scenario.control_period
    tracker = PathTracker(scenario.path, scenario.acceptance_radius, scenario.config.path.switching)
    x, y, psi = tr["x"], tr["y"], tr["heading"]
    frames = [tracker.reset(float(x[0]), float(y[0]))]
    frames += [tracker.update(float(a), float(b)) for a, b in zip(x[1:], y[1:], strict=True)]
    path_angle = np.array([f.path_angle for f in frames])
    legs = np.array([f.leg for f in frames])
    # drift angle over ground per step k (course of the step minus the step's mean heading)
    course = np.arctan2(np.diff(y), np.diff(x))
    mean_heading = psi[:-1] + 0.5 * wrap_angle(np.diff(psi))
    drift = np.concatenate(([math.nan], wrap_angle(course - mean_heading)))
    t = tr["t"]
    e_abs = np.abs(tr["cross_track_error"])
    heading_err = np.abs(wrap_angle(psi - path_angle))
    delta, command = tr["rudder_angle"], tr["rudder_command"]
    rate = np.concatenate(([math.nan], np.abs(np.diff(delta)) / dt))
    thr = float(result.metrics["convergence_threshold"])
    settles = _settle_times(t, e_abs, legs, thr)
    rec_t = np.array(recorder.log["t"])
    ref_err = np.array(recorder.log["ref_error"])
    b_hat = np.array(recorder.log["b_hat"])
    t_switch = switch_time(scenario)
    steps = np.arange(t.size) >= 1  # the env's log: after each step, not the reset sample
    windows = {
        "weak_current": (steps & (t < t_switch), rec_t < t_switch, (0.0, t_switch)),
        "strong_current": (steps & (t >= t_switch), rec_t >= t_switch, (t_switch, math.inf)),
        "episode": (steps, np.ones(rec_t.size, dtype=bool), (0.0, math.inf)),
    }
    out: dict[str, dict[str, Any]] = {}
    for phase, (w, wr, (t0, t1)) in windows.items():
        if not w.any():
            out[phase] = {m: math.nan for m in METRICS}
            continue
        st = [s for ts, s in settles if t0 <= ts < t1]
        d = drift[w]
        out[phase] = {
            "ace": float(np.mean(e_abs[w])),
            "std_abs_e": float(np.std(e_abs[w])),
            "max_abs_e": float(np.max(e_abs[w])),
            "mean_abs_heading_error_deg": DEG * float(np.mean(heading_err[w])),
            "mean_abs_reference_error_deg": DEG * float(np.mean(np.abs(ref_err[wr]))),
            "rms_reference_error_deg": DEG * float(np.sqrt(np.mean(ref_err[wr] ** 2))),
            "mean_abs_rudder_deg": DEG * float(np.mean(np.abs(delta[w]))),
            "rms_rudder_deg": DEG * float(np.sqrt(np.mean(delta[w] ** 2))),
            "mean_abs_rudder_rate_deg_s": DEG * float(np.mean(rate[w])),
            "command_hf_rms_deg": DEG * _hf_rms(command[w], dt),
            "rudder_hf_rms_deg": DEG * _hf_rms(delta[w], dt),
            "command_hf1_rms_deg": DEG * _hf_rms(command[w], dt, CUTOFF_HIGH),
            "rudder_hf1_rms_deg": DEG * _hf_rms(delta[w], dt, CUTOFF_HIGH),
            "drift_std_deg": DEG * float(np.std(d)),
            "drift_hf_rms_deg": DEG * _hf_rms(d, dt),
            "settle_time_s": float(np.mean(st)) if st else math.nan,
            "settled_fraction": float(np.mean(np.isfinite(st))) if st else math.nan,
            "settle_time_settled_s": (
                float(np.mean([v for v in st if math.isfinite(v)]))
                if any(math.isfinite(v) for v in st)
                else math.nan
            ),
            "b_hat_hf_rms_deg_s": (
                DEG * _hf_rms(b_hat[wr], dt) if np.isfinite(b_hat).all() else math.nan
            ),
        }
    # the adaptive figures: the L1 variants' own (their episode_stats)
    figures = {**result.metrics.get(CONTROLLER_STATS, {}), **result.metrics}
    for key in EPISODE_METRICS + ADAPTIVE_METRICS:
        if key in figures:
            value = figures[key]
            out["episode"][key] = float(value) if not isinstance(value, bool) else value
    return out
