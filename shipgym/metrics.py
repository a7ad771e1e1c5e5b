"""Episode metrics for ship path following (docs/disturbances.md, "Metrics").

One function, :func:`compute_metrics`, turns an :class:`EpisodeLog` (arrays over the control
steps of one episode) into a flat ``dict`` of JSON-serialisable numbers. The environment, the
scripts and the leaderboard all call it, so every controller is scored the same way.
:func:`aggregate` combines the per-seed dicts into mean and population std.

Sources:

- ACE and t_c: Liu, Zheng, Negenborn, Chu, Xie (2019), Asian J. Control, eq. (46) and the
  text of §5 Case 1 (t_c = "the moment when |e| keeps below 0.05 m after the model parameters
  change", reported as absolute simulation time, e.g. 35.5 s with the change at T = 12 s).
- Mean / std of |e|, |ψ̃| and |δ|: Xu & Guedes Soares (2020), Int. J. Maritime Eng.,
  Tables 2–3 ("mean value and standard deviation").
- Quality index J: Borkowski (2018), Sensors, eq. (29) with the weights of §5
  (λy = 1/2000, λψ = 1, λδ = 5).

Units: SI throughout (m, s, rad). The papers print headings and rudder angles in degrees;
this module reports radians.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = [
    "ARRAY_FIELDS",
    "DEFAULT_SETTINGS",
    "EpisodeLog",
    "MetricSettings",
    "aggregate",
    "compute_metrics",
    "episode_cost",
]

#: Reference ship of Liu et al. (2019): L = 0.95 m, t_c threshold 0.05 m.
_LIU_SHIP_LENGTH = 0.95  # m
_LIU_THRESHOLD = 0.05  # m

#: Per-step array fields of :class:`EpisodeLog`, in order.
ARRAY_FIELDS: tuple[str, ...] = (
    "t",
    "cross_track_error",
    "heading_error",
    "rudder_angle",
    "rudder_command",
    "reward",
)


@dataclass
class EpisodeLog:
    """Per-control-step record of one episode.

    Arrays have length n (one entry per control step) and are stored as 1-D float64.

    Attributes:
        t: time at the end of each control step (s), strictly increasing.
        cross_track_error: TRUE signed cross-track error e (m), not the measured one.
        heading_error: heading error to the path ψ̃ (rad).
        rudder_angle: actual rudder angle δ (rad).
        rudder_command: commanded rudder angle δc (rad).
        reward: per-step reward (dimensionless).
        ship_length: ship length L (m).
        dt: control period Ts (s).
        change_time: time of the first parameter change (s), ``None`` if nothing changes.
        reached_goal: whether the last waypoint was reached.
        goal_bonus: the reward's bonus for reaching the goal (in ``reward`` of the last
            step when ``reached_goal``); the cost leaves it out.

    Raises:
        ValueError: empty log, unequal lengths, non-finite values (NaN/inf) in any array,
            non-increasing ``t``, or non-positive ``ship_length``/``dt``.
            The message names the offending field.
    """

    t: np.ndarray
    cross_track_error: np.ndarray
    heading_error: np.ndarray
    rudder_angle: np.ndarray
    rudder_command: np.ndarray
    reward: np.ndarray
    ship_length: float
    dt: float
    change_time: float | None = None
    reached_goal: bool = False
    goal_bonus: float = 0.0

    def __post_init__(self) -> None:
        n: int | None = None
        for name in ARRAY_FIELDS:
            value = getattr(self, name)
            try:
                arr = np.asarray(value, dtype=np.float64)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"EpisodeLog.{name}: not convertible to float64 ({exc})") from exc
            if arr.ndim != 1:
                raise ValueError(f"EpisodeLog.{name}: expected a 1-D array, got shape {arr.shape}")
            setattr(self, name, arr.copy())
            if n is None:
                n = arr.shape[0]
        self.ship_length = float(self.ship_length)
        self.dt = float(self.dt)
        if self.change_time is not None:
            self.change_time = float(self.change_time)
        self.reached_goal = bool(self.reached_goal)
        self.goal_bonus = float(self.goal_bonus)
        self.validate()

    @property
    def n(self) -> int:
        """Number of control steps."""
        return int(self.t.shape[0])

    def validate(self) -> None:
        """Check lengths, finiteness and scalars; raise ``ValueError`` naming the field."""
        n = int(np.shape(self.t)[0]) if np.ndim(self.t) == 1 else -1
        if n == 0:
            raise ValueError("EpisodeLog.t: empty episode log (no control steps)")
        for name in ARRAY_FIELDS:
            arr = getattr(self, name)
            if not isinstance(arr, np.ndarray) or arr.ndim != 1:
                raise ValueError(f"EpisodeLog.{name}: expected a 1-D numpy array")
            if arr.shape[0] != n:
                raise ValueError(
                    f"EpisodeLog.{name}: length {arr.shape[0]} differs from len(t) = {n}"
                )
        for name in ARRAY_FIELDS:
            arr = getattr(self, name)
            bad = ~np.isfinite(arr)
            if bad.any():
                i = int(np.argmax(bad))
                raise ValueError(
                    f"EpisodeLog.{name}: non-finite value {arr[i]!r} at step {i} "
                    f"({int(bad.sum())} in total)"
                )
        if n > 1 and not np.all(np.diff(self.t) > 0.0):
            raise ValueError("EpisodeLog.t: times must be strictly increasing")
        if not (math.isfinite(self.ship_length) and self.ship_length > 0.0):
            raise ValueError(f"EpisodeLog.ship_length: must be > 0 m, got {self.ship_length!r}")
        if not (math.isfinite(self.dt) and self.dt > 0.0):
            raise ValueError(f"EpisodeLog.dt: must be > 0 s, got {self.dt!r}")
        if self.change_time is not None and not math.isfinite(self.change_time):
            raise ValueError(f"EpisodeLog.change_time: must be finite, got {self.change_time!r}")
        if not math.isfinite(self.goal_bonus):
            raise ValueError(f"EpisodeLog.goal_bonus: must be finite, got {self.goal_bonus!r}")

    @classmethod
    def from_records(cls, records: Sequence[Mapping[str, Any]], **scalars: Any) -> EpisodeLog:
        """Build a log from one dict per control step.

        Each record needs the keys ``t``, ``cross_track_error``, ``heading_error``,
        ``rudder_angle``, ``rudder_command``, ``reward``. Other keys (e.g. the rest of an env
        ``info``) are ignored.
        ``scalars`` are the remaining constructor arguments: ``ship_length``, ``dt`` and
        optionally ``change_time``, ``reached_goal``, ``goal_bonus``.

        Raises:
            ValueError: no records, or a record lacks a required key (named in the message).
        """
        if len(records) == 0:
            raise ValueError("EpisodeLog.t: empty episode log (no records)")
        columns: dict[str, list[float]] = {name: [] for name in ARRAY_FIELDS}
        for i, rec in enumerate(records):
            for name in ARRAY_FIELDS:
                if name not in rec:
                    raise ValueError(f"EpisodeLog.{name}: missing from record {i}")
                columns[name].append(_to_float(rec[name], name, i))
        arrays = {name: np.asarray(col, dtype=np.float64) for name, col in columns.items()}
        return cls(**arrays, **scalars)


def _to_float(value: Any, name: str, i: int) -> float:
    try:
        return float(np.asarray(value, dtype=np.float64).reshape(()))
    except (TypeError, ValueError) as exc:
        raise ValueError(f"EpisodeLog.{name}: record {i} is not a scalar number ({exc})") from exc


@dataclass(frozen=True)
class MetricSettings:
    """Settings of :func:`compute_metrics`.

    Attributes:
        convergence_threshold: |e| threshold for t_c (m). ``None`` scales Liu et al. (2019)'s
            0.05 m for their L = 0.95 m ship with the ship length: 0.05·L/0.95.
        lambda_y: weight of e² in J (1/m²; Borkowski 2018 §5: 1/2000).
        lambda_psi: weight of ψ̃² in J (1/rad²; Borkowski 2018 §5: 1).
        lambda_delta: weight of δ² in J (1/rad²; Borkowski 2018 §5: 5).
    """

    convergence_threshold: float | None = None
    lambda_y: float = 1.0 / 2000.0
    lambda_psi: float = 1.0
    lambda_delta: float = 5.0

    def __post_init__(self) -> None:
        thr = self.convergence_threshold
        if thr is not None and not (math.isfinite(thr) and thr > 0.0):
            raise ValueError(f"MetricSettings.convergence_threshold: must be > 0 m, got {thr!r}")
        for name in ("lambda_y", "lambda_psi", "lambda_delta"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f"MetricSettings.{name}: must be finite and >= 0, got {v!r}")

    def threshold(self, ship_length: float) -> float:
        """t_c threshold (m) for a ship of length ``ship_length`` (m)."""
        if self.convergence_threshold is not None:
            return float(self.convergence_threshold)
        # Liu et al. (2019) §5: |e| < 0.05 m for the 0.95 m model ship; scaled with L.
        return _LIU_THRESHOLD * float(ship_length) / _LIU_SHIP_LENGTH


DEFAULT_SETTINGS = MetricSettings()


def _wrap_angle(a: np.ndarray) -> np.ndarray:
    """Wrap angles (rad) to [-π, π)."""
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def _convergence_time(t: np.ndarray, abs_e: np.ndarray, start: float | None, thr: float) -> float:
    """Liu et al. (2019) t_c: time (s) of the first sample of the final run with |e| < thr.

    Only samples with t >= ``start`` are searched (all if ``start`` is None). Returns ``inf``
    if the last sample is not below ``thr``; NaN if no sample lies in the window.
    """
    idx = np.arange(t.shape[0]) if start is None else np.flatnonzero(t >= start)
    if idx.size == 0:
        return math.nan
    below = abs_e[idx] < thr
    if not below[-1]:
        return math.inf
    above = np.flatnonzero(~below)
    first = 0 if above.size == 0 else int(above[-1]) + 1
    return float(t[idx[first]])


def compute_metrics(
    log: EpisodeLog, settings: MetricSettings = DEFAULT_SETTINGS
) -> dict[str, float]:
    """Metrics of one episode. All values are plain Python ``float``/``bool``/``int``.

    Keys:
        ace (m): Liu et al. (2019) eq. (46), e_a = (1/N_T) Σ |e(i)| over the N_T control steps
            strictly after the first parameter change (t > change_time); whole episode when
            ``change_time`` is None; NaN if no step lies after the change.
        ace_L (-): ace / L.
        t_c (s): absolute time from which |e| < threshold until the end of the episode (Liu
            et al. 2019 §5, e.g. 35.5 s for a change at 12 s): time of the first sample of the
            final run of below-threshold samples among the steps with t >= change_time (all
            steps if no change); ``inf`` if the last sample is not below the threshold; NaN if
            no step lies at/after the change.
        t_c_after_change (s): t_c − change_time (t_c when no change).
        convergence_threshold (m): the threshold used for t_c.
        mean_abs_cross_track, std_abs_cross_track, max_abs_cross_track (m): of |e| over the
            whole episode (Xu & Guedes Soares 2020, Tables 2–3; std is population, ddof=0).
        mean_abs_heading_error, std_abs_heading_error (rad): of |ψ̃|, ψ̃ wrapped to [-π, π).
        mean_abs_rudder, std_abs_rudder (rad): of |δ| (actual rudder angle).
        rudder_travel (rad): Σ_{k=1}^{n-1} |δ_k − δ_{k-1}| (first sample has no predecessor).
        rudder_command_travel (rad): the same for δc.
        J: Borkowski (2018) eq. (29), J = ∫_0^∞ (λy·y_r² + λψ·ψ_r² + λδ·δ²) dt, with
            y_r = e (m), ψ_r = ψ̃ (rad), δ (rad). The paper writes a plain integral (no 1/T
            normalisation, so J grows with episode length); here the integral runs over the
            episode and is discretised as a right Riemann sum Σ_k (λy e_k² + λψ ψ̃_k² +
            λδ δ_k²)·dt over the end-of-step samples. A constant e gives λy·e²·T, T = n·dt.
        return: Σ reward.
        cost (-): the episode cost C = Σ step costs + any corridor (or divergence) penalty,
            i.e. −(return − goal bonus when the goal was reached); ≥ 0 for the env's reward
            (every term a cost). The leaderboard's score divides it by the oracle's.
        success (bool): ``log.reached_goal``.
        steps (int): n.
        duration (s): n·dt.

    Raises:
        ValueError: invalid log (see :class:`EpisodeLog`), naming the field.
    """
    log.validate()
    t = log.t
    e_abs = np.abs(log.cross_track_error)
    psi_err = _wrap_angle(log.heading_error)
    psi_abs = np.abs(psi_err)
    delta = log.rudder_angle
    delta_abs = np.abs(delta)
    n = log.n
    L = log.ship_length
    tch = log.change_time

    # ACE, Liu et al. (2019) eq. (46): steps strictly after the first parameter change.
    after = np.ones(n, dtype=bool) if tch is None else t > tch
    ace = float(np.mean(e_abs[after])) if after.any() else math.nan

    # t_c, Liu et al. (2019) §5: reported as absolute simulation time.
    thr = settings.threshold(L)
    t_c = _convergence_time(t, e_abs, tch, thr)
    t_c_after = t_c if tch is None else t_c - tch

    # J, Borkowski (2018) eq. (29), right Riemann sum over control steps.
    integrand = (
        settings.lambda_y * log.cross_track_error**2
        + settings.lambda_psi * psi_err**2
        + settings.lambda_delta * delta**2
    )
    J = float(np.sum(integrand) * log.dt)

    return {
        "ace": ace,
        "ace_L": ace / L,
        "t_c": t_c,
        "t_c_after_change": float(t_c_after),
        "convergence_threshold": float(thr),
        # Xu & Guedes Soares (2020) Tables 2–3: mean value and standard deviation.
        "mean_abs_cross_track": float(np.mean(e_abs)),
        "std_abs_cross_track": float(np.std(e_abs)),
        "max_abs_cross_track": float(np.max(e_abs)),
        "mean_abs_heading_error": float(np.mean(psi_abs)),
        "std_abs_heading_error": float(np.std(psi_abs)),
        "mean_abs_rudder": float(np.mean(delta_abs)),
        "std_abs_rudder": float(np.std(delta_abs)),
        "rudder_travel": float(np.sum(np.abs(np.diff(delta)))),
        "rudder_command_travel": float(np.sum(np.abs(np.diff(log.rudder_command)))),
        "J": J,
        "return": float(np.sum(log.reward)),
        "cost": episode_cost(log),
        "success": bool(log.reached_goal),
        "steps": int(n),
        "duration": float(n * log.dt),
    }


def episode_cost(log: EpisodeLog) -> float:
    """The episode cost C = (goal bonus if reached) − Σ reward: every step cost and penalty,
    without the bonus (see :func:`compute_metrics`)."""
    bonus = log.goal_bonus if log.reached_goal else 0.0
    return float(bonus - np.sum(log.reward))


def _as_float(value: Any, key: str) -> float:
    if value is None:  # e.g. NaN that went through JSON as null
        return math.nan
    try:
        return float(value)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"aggregate: value {value!r} of key {key!r} is not numeric") from exc


def aggregate(
    rows: Sequence[Mapping[str, Any]], keys: Iterable[str] | None = None
) -> dict[str, float]:
    """Combine per-seed metric dicts into ``{key: mean, key + "_std": population std}``.

    - NaN (and ``None``) values are ignored; mean and std of no remaining value are NaN.
    - Infinite values: t_c = inf means "never converged", so one such seed makes the mean
      ``inf`` (``-inf`` for −inf; NaN if both signs occur) and the std NaN (undefined spread).
    - Boolean keys (e.g. ``success``) become a rate in [0, 1]; ``_std`` is the population
      std of the 0/1 values.
    - ``n`` is the number of rows.

    Args:
        rows: metric dicts, e.g. from :func:`compute_metrics` for several seeds.
        keys: keys to aggregate; ``None`` → every key of the first row whose value is a
            number or bool.

    Raises:
        ValueError: no rows, a row lacks a key, or a value is not numeric.
    """
    if len(rows) == 0:
        raise ValueError("aggregate: no rows")
    if keys is None:
        keys = [
            k
            for k, v in rows[0].items()
            if v is None or isinstance(v, bool | int | float | np.floating | np.integer)
        ]
    out: dict[str, float] = {"n": len(rows)}
    for key in keys:
        raw = []
        for i, row in enumerate(rows):
            if key not in row:
                raise ValueError(f"aggregate: row {i} has no key {key!r}")
            raw.append(_as_float(row[key], key))
        vals = np.asarray(raw, dtype=np.float64)
        vals = vals[~np.isnan(vals)]
        n_inf = int(np.isinf(vals).sum())
        if vals.size == 0:
            mean, std = math.nan, math.nan
        elif n_inf:
            pos, neg = bool((vals == np.inf).any()), bool((vals == -np.inf).any())
            mean = math.nan if (pos and neg) else (math.inf if pos else -math.inf)
            std = math.nan
        else:
            mean, std = float(np.mean(vals)), float(np.std(vals, ddof=0))
        out[key] = mean
        out[f"{key}_std"] = std
    return out


# --------------------------------------------------------------------------------------------
# Spectral content of a signal (e.g. rudder activity above a filter corner)
# --------------------------------------------------------------------------------------------
def high_frequency_power(signal: np.ndarray, period: float, cutoff: float) -> float:
    """Power of a signal above ``cutoff`` [rad/s]: ∫ PSD over f ≥ cutoff/2π [signal²].

    Welch's one-sided power spectral density (scipy.signal.welch, Hann segments of up to
    256 samples, mean removed) of ``signal`` sampled at ``period`` [s], integrated by the
    trapezoid rule; √ of the result is the RMS of the signal's content above the cutoff
    (Xu, Oliveira & Guedes Soares 2021 §3.2: C(s) removes the rudder's high frequencies).
    """
    from scipy.signal import welch  # only this metric needs scipy

    x = np.asarray(signal, dtype=float)
    if x.ndim != 1 or x.size < 8:
        raise ValueError(f"need a 1-D signal of at least 8 samples, got shape {x.shape}")
    if not (period > 0 and cutoff >= 0):
        raise ValueError(f"need period > 0 and cutoff ≥ 0, got {period}, {cutoff}")
    freq, psd = welch(x, fs=1.0 / period, nperseg=min(256, x.size))
    high = freq >= cutoff / (2.0 * math.pi)
    if high.sum() < 2:
        return 0.0
    return float(np.trapezoid(psd[high], freq[high]))
