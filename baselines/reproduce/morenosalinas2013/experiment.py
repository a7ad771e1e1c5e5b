"""Moreno-Salinas et al. (2013) §4: the zig-zag, the LS-SVM fits, the replays and the rows."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.signal import butter, filtfilt

from shipgym.identification.blanke import BlankeFit, fit_blanke, simulate_commands
from shipgym.manoeuvres import turning_circle, zigzag
from shipgym.models.blanke import Blanke, regression_coefficients
from shipgym_baselines.errors import check_seeds
from shipgym_baselines.reproduce.protocol import Outcome, Progress
from shipgym_baselines.reproduce.rows import reproduction_row

DEG = math.pi / 180.0

#: Moreno-Salinas et al. (2013) §4.1: IMU sampling time [s] and one-sigma noise levels
SAMPLING_TIME = 0.2
VELOCITY_NOISE = 0.04  # [m/s]
HEADING_NOISE = 0.05 * DEG  # [rad]
#: manoeuvre durations [s] (§4.1: 90 s zig-zag; §4.2.1: 240 s per turn; §4.2.2: 90 s)
ZIGZAG_DURATION = 90.0
TURNING_DURATION = 240.0
#: low-pass corner of the ``lssvm_blanke_lowpass`` identifier [Hz] (our addition)
LOWPASS_HZ = 0.5

CASES = {  # case -> (manoeuvre, rudder [deg], the paper's section)
    "zigzag_20_20_fit": ("zigzag", 20.0, "§4.1, training data"),
    "turning_circle_-20": ("turning", -20.0, "§4.2.1"),
    "turning_circle_+20": ("turning", 20.0, "§4.2.1"),
    "zigzag_10_10": ("zigzag", 10.0, "§4.2.2"),
}
SIGNALS = ("surge", "sway", "yaw_rate")
CONTROLLERS = ("lssvm_blanke", "lssvm_blanke_lowpass")

#: Moreno-Salinas et al. (2013) §4: error standard deviations [m/s, m/s, rad/s]
PUBLISHED = {
    "zigzag_20_20_fit": (0.0486, 0.0171, 0.0066),
    "turning_circle_-20": (0.1786, 0.0303, 0.0160),
    "turning_circle_+20": (0.04, 0.0236, 0.0129),
    "zigzag_10_10": (0.0466, 0.0239, 0.0097),
}


def _manoeuvre(plant: Blanke, case: str, duration_scale: float) -> np.ndarray:
    """The plant's rudder commands (fine step) of one case."""
    kind, rudder, _ = CASES[case]
    if kind == "zigzag":
        log, _ = zigzag(
            plant, rudder, rudder, duration=ZIGZAG_DURATION * duration_scale, n_switches=1000
        )
    else:
        log, _ = turning_circle(plant, rudder, duration=TURNING_DURATION * duration_scale)
    return log.delta_c[:-1]


def _measure(
    states: np.ndarray, step: int, rng: np.random.Generator, yaw_rate_noise: float
) -> dict[str, np.ndarray]:
    """Samples every ``step`` fine steps with the IMU noise of §4.1 (SI, rad)."""
    s = states[::step]
    n = s.shape[0]
    return {
        "psi": s[:, 2] + HEADING_NOISE * rng.standard_normal(n),
        "u": s[:, 3] + VELOCITY_NOISE * rng.standard_normal(n),
        "v": s[:, 4] + VELOCITY_NOISE * rng.standard_normal(n),
        "r": s[:, 5] + yaw_rate_noise * rng.standard_normal(n),
        "delta": s[:, 6],
    }


def _lowpass(signal: np.ndarray, h: float) -> np.ndarray:
    b, a = butter(2, LOWPASS_HZ / (0.5 / h))
    return filtfilt(b, a, signal)


def _identify(measured: dict[str, np.ndarray], h: float, controller: str) -> BlankeFit:
    u, v, r = measured["u"], measured["v"], measured["r"]
    if controller == "lssvm_blanke_lowpass":
        u, v, r = (_lowpass(z, h) for z in (u, v, r))
    return fit_blanke(u, v, r, measured["delta"], h)


def _std(a: np.ndarray) -> float:
    return float(np.std(a)) if np.all(np.isfinite(a)) else math.nan


def run_experiment(
    seeds: int = 1,
    progress: Progress | None = None,
    yaw_rate_noise: float = 0.0,
    duration_scale: float = 1.0,
) -> Outcome:
    """The reproduction rows (plus ``ours_std`` and ``seeds``).

    ``seeds``: noise realisations (``ours`` is their mean, ``ours_std`` the spread);
    ``yaw_rate_noise`` [rad/s] one-sigma gyro noise (the paper gives none);
    ``duration_scale`` shortens the manoeuvres (e.g. 0.5 for a quick run).  ``episodes``:
    (plant, noise-free states per case, seed-0 measurements and predictions, samples per
    IMU period) for :func:`~shipgym_baselines.reproduce.morenosalinas2013.figures.plot_series`;
    ``documents``: the identified coefficients (seed 0) beside the plant's.
    """
    check_seeds(seeds)
    plant = Blanke()
    h_fine = plant.fine_step
    step = round(SAMPLING_TIME / h_fine)
    commands = {case: _manoeuvre(plant, case, duration_scale) for case in CASES}
    truth = {case: simulate_commands(plant, commands[case], h_fine) for case in CASES}
    results: dict[tuple[str, str, str], list[float]] = {}
    examples: dict[str, Any] = {}
    fits: dict[str, BlankeFit] = {}
    for seed in range(seeds):
        rng = np.random.default_rng(seed)
        measured = {case: _measure(truth[case], step, rng, yaw_rate_noise) for case in CASES}
        if seed == 0:
            examples["measured"] = measured
        for controller in CONTROLLERS:
            fit = _identify(measured["zigzag_20_20_fit"], SAMPLING_TIME, controller)
            model = fit.model()
            if seed == 0:
                fits[controller] = fit
            for case in CASES:
                predicted = simulate_commands(model, commands[case], h_fine)[::step]
                clean = truth[case][::step]
                for i, signal in enumerate(SIGNALS):
                    col = 3 + i
                    key = ("u", "v", "r")[i]
                    results.setdefault((case, controller, f"std_error_{signal}"), []).append(
                        _std(predicted[:, col] - measured[case][key])
                    )
                    results.setdefault(
                        (case, controller, f"std_error_{signal}_vs_plant"), []
                    ).append(_std(predicted[:, col] - clean[:, col]))
                if seed == 0:
                    examples[(case, controller)] = predicted
        if progress is not None:
            progress()
    rows: list[dict[str, Any]] = []
    for (case, controller, metric), values in results.items():
        paper = None
        if not metric.endswith("_vs_plant"):
            paper = PUBLISHED[case][SIGNALS.index(metric.removeprefix("std_error_"))]
        finite = [x for x in values if math.isfinite(x)]
        complete = len(finite) == len(values)
        rows.append(
            reproduction_row(
                case,
                controller,
                metric,
                float(np.mean(finite)) if complete else None,
                paper,
                seeds,
                ours_std=float(np.std(finite)) if complete else None,
            )
        )
    documents = {"morenosalinas2013_coefficients.json": _coefficient_table(plant, fits)}
    return Outcome(rows, (plant, truth, examples, step), documents)


def _coefficient_table(plant: Blanke, fits: dict[str, BlankeFit]) -> dict[str, Any]:
    """Identified coefficients (seed 0) beside the plant's linearised regression form."""
    truth = regression_coefficients(
        plant.params, rudder=plant.variant, rudder_regressors="paper"
    ).as_dict()
    table: dict[str, Any] = {}
    for name in next(iter(fits.values())).coefficients():
        table[name] = {"plant_linearised": truth[name]}
        for controller, fit in fits.items():
            table[name][controller] = fit.coefficients()[name]
    return table
