"""Benchmarks of SPEC §10 (medians over repeats; machines are noisy)."""

from __future__ import annotations

import statistics
import time
from typing import Any

import numpy as np

from shipgym.envs.path_follow import ShipPathFollowEnv
from shipgym.models import MODELS


def bench_env(
    steps: int = 5000, repeats: int = 5, batch: int = 1024, batch_periods: int = 20
) -> dict[str, Any]:
    """Single-env steps/s (nomoto2, rudder mode, h = 0.01 s inside Ts = 0.5 s) and the numpy
    batched RK4 stepper of the same model (ship-substeps/s and env-steps/s at N ships)."""
    env = ShipPathFollowEnv("nominal")
    rng = np.random.default_rng(0)
    actions = rng.uniform(-1, 1, (steps, 1)).astype(np.float32)
    rates = []
    for rep in range(repeats):
        env.reset(seed=rep)
        start = time.perf_counter()
        for a in actions:
            _, _, terminated, truncated, _ = env.step(a)
            if terminated or truncated:
                env.reset()
        rates.append(steps / (time.perf_counter() - start))
    single = statistics.median(rates)

    model = MODELS["nomoto2"]()
    n_sub = round(model.control_period / model.fine_step)
    x0 = np.tile(model.initial_state()[:, None], (1, batch))
    p = np.tile(model.params.to_vector()[:, None], (1, batch))
    w = np.zeros((model.n_disturbances, batch))
    brates = []
    for _ in range(repeats):
        x = x0.copy()
        u = [rng.uniform(-0.5, 0.5, batch)]
        start = time.perf_counter()
        for _ in range(batch_periods):
            for _ in range(n_sub):
                x = model.step_numpy(x, u, w, p, model.fine_step)
        brates.append(batch * n_sub * batch_periods / (time.perf_counter() - start))
    substeps = statistics.median(brates)
    return {
        "single_env_steps_per_s": single,
        "single_env_target_steps_per_s": 10_000,
        "single_env_ratio_to_target": single / 10_000,
        "batched_ship_substeps_per_s": substeps,
        "batched_env_steps_per_s": substeps / n_sub,
        "batched_env_target_steps_per_s": 250_000,
        "batched_ratio_to_target": substeps / n_sub / 250_000,
        "batch_size": batch,
        "substeps_per_step": n_sub,
        "repeats": repeats,
    }
