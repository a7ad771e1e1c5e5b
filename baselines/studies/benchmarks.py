"""Benchmarks of the speed targets (docs/benchmarks.md; medians over repeats: machines are
noisy)."""

from __future__ import annotations

import statistics
import time
from typing import Any

import numpy as np

from shipgym.envs.path_follow import ShipPathFollowEnv
from shipgym.models import MODELS

#: the speed floors on the 2-core machine (steps/s, env-steps/s at N = 1024, µs)
SINGLE_ENV_TARGET = 25_000
BATCHED_ENV_TARGET = 350_000
PCHIP_PROJECTION_TARGET_US = 20.0


def bench_env(
    steps: int = 5000, repeats: int = 5, batch: int = 1024, batch_steps: int = 100
) -> dict[str, Any]:
    """Single-env steps/s (nomoto2, rudder mode, h = 0.01 s inside Ts = 0.5 s), the batched
    env at N ships (env-steps/s, all of them stepped per call), and the plain numpy RK4 of
    the same model over N ships for comparison (ship-substeps/s)."""
    from shipgym.envs.vector import ShipPathFollowVectorEnv

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

    batch_actions = rng.uniform(-1, 1, (batch_steps, batch, 1)).astype(np.float32)
    rates = {}
    for metrics in (False, True):  # as in RL training (no per-episode metrics), and with them
        venv = ShipPathFollowVectorEnv(batch, "nominal", episode_metrics=metrics)
        venv.reset(seed=0)
        venv.step(batch_actions[0])
        per_repeat = []
        for _ in range(repeats):
            start = time.perf_counter()
            for a in batch_actions:  # random rudder: episodes end and reset all the time
                venv.step(a)
            per_repeat.append(batch * batch_steps / (time.perf_counter() - start))
        rates[metrics] = statistics.median(per_repeat)
    batched = rates[False]

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
        for _ in range(5):
            for _ in range(n_sub):
                x = model.step_numpy(x, u, w, p, model.fine_step)
        brates.append(batch * n_sub * 5 / (time.perf_counter() - start))
    projection = bench_pchip_projection(repeats=repeats, batch=batch)
    return {
        "single_env_steps_per_s": single,
        "single_env_target_steps_per_s": SINGLE_ENV_TARGET,
        "single_env_ratio_to_target": single / SINGLE_ENV_TARGET,
        "batched_env_steps_per_s": batched,
        "batched_env_steps_per_s_with_episode_metrics": rates[True],
        "batched_ship_substeps_per_s": batched * n_sub,
        "batched_env_target_steps_per_s": BATCHED_ENV_TARGET,
        "batched_ratio_to_target": batched / BATCHED_ENV_TARGET,
        "numpy_rk4_ship_substeps_per_s": statistics.median(brates),
        **projection,
        "batch_size": batch,
        "substeps_per_step": n_sub,
        "repeats": repeats,
    }


def bench_pchip_projection(
    scenario: str = "rudder_aging_smooth", points: int = 2000, repeats: int = 5, batch: int = 1024
) -> dict[str, float]:
    """Closest-point tracking on a PCHIP path (the tracker's per-step projection): µs per
    call for one ship along a ship-like track, and µs per ship for ``batch`` ships at once."""
    from shipgym.scenarios.loader import load_scenario
    from shipgym.tracking import PathTracker

    sc = load_scenario(scenario)
    path = sc.path
    s = np.linspace(0.0, path.length, points)
    track = path.point(s) + 0.5 * sc.ship_length * np.sin(s / 7.0)[:, None]  # near the path
    xs, ys = track[:, 0].tolist(), track[:, 1].tolist()
    single, per_ship = [], []
    for _ in range(repeats):
        tracker = PathTracker(path, sc.acceptance_radius)
        tracker.reset(xs[0], ys[0])
        start = time.perf_counter()
        for x, y in zip(xs, ys, strict=True):
            tracker.update(x, y)
        single.append(1e6 * (time.perf_counter() - start) / points)
        many = PathTracker(path, sc.acceptance_radius, batch=batch)
        shift = np.linspace(-0.5, 0.5, batch) * sc.ship_length
        many.reset(track[0, 0] + shift, track[0, 1] + shift)
        start = time.perf_counter()
        for x, y in track[:: max(1, points // 100)]:
            many.update(x + shift, y + shift)
        calls = len(track[:: max(1, points // 100)])
        per_ship.append(1e6 * (time.perf_counter() - start) / (calls * batch))
    return {
        "pchip_projection_us": statistics.median(single),
        "pchip_projection_target_us": PCHIP_PROJECTION_TARGET_US,
        "pchip_projection_batched_us_per_ship": statistics.median(per_ship),
    }


#: the three jump cases of Liu et al. (2019) and the parameters each changes; Case 3 also
#: without its heading noise and outliers, to separate the sensor model from the algorithm
JUMP_CASES = {
    "rudder_aging": ("Tc",),
    "current_shift": ("d0",),
    "maneuverability_change": ("K", "T1", "T2", "T3", "d0", "beta", "Tc"),
    "maneuverability_change_noise_free": ("K", "T1", "T2", "T3", "d0", "beta", "Tc"),
}


def _jump_case(name: str) -> Any:
    """A catalogue scenario, or ``<name>_noise_free``: the same without its sensor model."""
    from shipgym_baselines.reproduce.variants import scenario_variant

    base = name.removesuffix("_noise_free")
    return scenario_variant(base, noise_free=name != base)


def identification_log(
    scenario: str, seed: int = 0, excitation_deg: float = 1.0
) -> tuple[list[dict[str, np.ndarray]], Any]:
    """Per-step ``info["samples"]`` of ``pid_los`` + persistent excitation (eq. (45)) on a case.

    Returns the samples and the scenario (whose schedule is the truth to score against).
    """
    import math

    import gymnasium as gym

    import shipgym  # noqa: F401
    from shipgym.identification.online import PersistentExcitation
    from shipgym_baselines.classical.pid import PIDLOS

    env = gym.make(
        "ShipPathFollow-v0",
        scenario=_jump_case(scenario) if isinstance(scenario, str) else scenario,
        randomize=False,
        max_episode_steps=-1,  # the scenario's own time limit
    )
    obs, info = env.reset(seed=seed)
    ctx = env.unwrapped.controller_context
    pid = PIDLOS(preset="paper")  # the papers' experiment: the paper-literal design
    pid.reset(ctx, seed)
    excite = PersistentExcitation(math.radians(excitation_deg), np.random.default_rng(seed))
    log = []
    while True:
        delta_c = excite(float(pid.act(obs, info)[0]) * ctx.rudder_limit)
        obs, _, terminated, truncated, info = env.step([np.clip(delta_c / ctx.rudder_limit, -1, 1)])
        if "samples" in info:  # absent on a diverged step
            log.append(info["samples"])
        if terminated or truncated:
            return log, env.unwrapped.scenario


def bench_identification(seed: int = 0, excitation_deg: float = 1.0) -> dict[str, Any]:
    """Parameter error and time per update of each online identifier on the three cases,
    with both front ends of the regression (``differences``, the paper's; ``svf``, outlier
    filter + state-variable filter: keys ending in ``_svf``).

    For every case: relative error of each changed parameter at the end of the episode,
    the first time after the change from which the changed parameters (β excepted: it is
    not identifiable at these yaw rates, README) stay within 10 % (``inf`` if never), and
    the median / p99 µs per window update; for λ-LS-SVM also how many updates before the
    change have λ¹ > λc¹ (false detections) and the first time after it that λ¹ > λc¹.
    Batch ``fit_nomoto2`` on the post-change data is reported beside them.
    """
    import math

    from shipgym.identification.errors import IdentificationError
    from shipgym.identification.nomoto import fit_nomoto2
    from shipgym.identification.online import LambdaLSSVM, WeightedLSSVMOnline

    identifiers = (("lambda_lssvm", LambdaLSSVM), ("weighted_lssvm", WeightedLSSVMOnline))
    out: dict[str, Any] = {}
    for case, changed in JUMP_CASES.items():
        log, sc = identification_log(case, seed, excitation_deg)
        truth = sc.schedule.final
        h = sc.fine_step
        change = sc.change_time
        row: dict[str, Any] = {}
        for front_end, suffix in (("differences", ""), ("svf", "_svf")):
            for name, cls in identifiers:
                ident = cls(h, sc.nominal_params, front_end=front_end)
                times = []
                for samples in log:
                    start = time.perf_counter()
                    if ident.update(samples):
                        times.append(time.perf_counter() - start)
                errors = {
                    k: abs(getattr(ident.params, k) - getattr(truth, k)) / abs(getattr(truth, k))
                    for k in changed
                }
                within = math.inf
                for entry in ident.history:
                    ok = entry["t"] > change and all(
                        abs(entry[k] - getattr(truth, k)) <= 0.1 * abs(getattr(truth, k))
                        for k in changed
                        if k != "beta"
                    )
                    if ok and within == math.inf:
                        within = entry["t"]
                    elif not ok and entry["t"] > change:
                        within = math.inf
                figures = {
                    "final_relative_error": errors,
                    "t_within_10pct": within,
                    "update_us_median": 1e6 * statistics.median(times) if times else math.nan,
                    "update_us_p99": 1e6 * float(np.percentile(times, 99)) if times else math.nan,
                    "updates": len(times),
                }
                if isinstance(ident, LambdaLSSVM):
                    over = [
                        e["t"] for e in ident.history if e.get("lambda1", 0.0) > ident.lambda_c[0]
                    ]
                    figures["lambda1_detections_before_change"] = sum(t <= change for t in over)
                    figures["lambda1_first_detection_after_change"] = min(
                        (t for t in over if t > change), default=math.inf
                    )
                row[name + suffix] = figures
            samples = {
                k: np.concatenate([s[k] for s in log]) for k in ("t", "psi", "delta", "delta_c")
            }
            after = samples["t"] >= change
            try:
                fit = fit_nomoto2(
                    samples["psi"][after],
                    samples["delta"][after],
                    samples["delta_c"][after],
                    h,
                    base=sc.nominal_params,
                    front_end=front_end,
                )
                row["batch_fit_nomoto2" + suffix] = {
                    "final_relative_error": {
                        k: abs(getattr(fit, k) - getattr(truth, k)) / abs(getattr(truth, k))
                        for k in changed
                    }
                }
            except IdentificationError as exc:
                row["batch_fit_nomoto2" + suffix] = {"error": str(exc)}
        out[case] = row
    return out


#: the NMPC family (the solve-time targets hold for each member on every ship)
NMPC_FAMILY = (
    "nmpc",
    "nmpc_wlssvm",
    "nmpc_lambda_lssvm",
    "nmpc_wlssvm_svf",
    "nmpc_lambda_lssvm_svf",
)
#: each ship's scenarios for the per-ship solve times (nomoto2: the top-level three)
SHIP_SCENARIOS: dict[str, tuple[str, ...]] = {
    "nomoto2": ("nominal", "rudder_aging", "current_shift"),
    "esso_osaka": ("osaka_stochastic_current",),
    "mariner": ("mariner_track",),
    "blanke": ("blanke_current_shift",),
}
#: per-ship episodes are cut after this many control steps (the bench's run time)
PER_SHIP_MAX_STEPS = 1000
#: the same for the oracle (``oracle_median_ms`` / ``oracle_p99_ms``; target median ≤ 20 ms)
ORACLE_MAX_STEPS = 300
#: the controllers that steer with the oracle's NMPC on an estimated plant: their whole
#: step (estimate and solve) is timed on every ship, KVLCC2 included (target: the oracle's
#: median ≤ 20 ms), each ship's changing scenario of the default suite
ESTIMATING = ("nmpc_ekf", "nmpc_learned_id")
ESTIMATING_SCENARIOS: dict[str, tuple[str, ...]] = {
    "nomoto2": ("rudder_aging", "maneuverability_change"),
    "esso_osaka": ("esso_osaka_rudder_aging",),
    "mariner": ("mariner_rudder_aging",),
    "blanke": ("blanke_maneuverability_change",),
    "kvlcc2": ("kvlcc2_current_shift",),
}


def _percentiles_ms(times: list[float], prefix: str) -> dict[str, float]:
    """``{prefix}_median_ms`` and ``{prefix}_p99_ms`` of times [s]."""
    return {
        f"{prefix}_median_ms": 1e3 * statistics.median(times),
        f"{prefix}_p99_ms": 1e3 * float(np.percentile(times, 99)),
    }


def solve_times_per_ship(
    controller: str,
    ships: dict[str, tuple[str, ...]] | None = None,
    max_steps: int | None = None,
    seed: int = 0,
    clock: str = "solve",
) -> dict[str, dict[str, Any]]:
    """Per ship, the solve times of ``controller`` (a registered name) in closed loop on the
    ship's scenarios (``ships``: ship → scenario names; None: :data:`SHIP_SCENARIOS`), each
    cut after ``max_steps`` control steps (None: :data:`PER_SHIP_MAX_STEPS`):
    ``{controller}_median_ms``,
    ``{controller}_p99_ms`` (wall clock, of the policy's ``solve_times`` [s]),
    ``{controller}_cpu_median_ms`` / ``_cpu_p99_ms`` where the policy also records
    ``solve_cpu_times`` (its thread's CPU time: not inflated by a loaded machine), and
    ``{controller}_solves``.  ``clock="step"``: the whole step's times instead (``step_times``
    and ``step_cpu_times``: estimate and solve, of a controller that estimates the plant),
    the keys ``{controller}_step_…``."""
    from shipgym.scenarios.loader import load_scenario
    from shipgym_baselines.evaluation import run_episode
    from shipgym_baselines.privileged import grants_truth
    from shipgym_baselines.registry import make_controller

    max_steps = PER_SHIP_MAX_STEPS if max_steps is None else max_steps
    privileged = grants_truth(controller)  # the oracle reads the truth, as in a run
    out: dict[str, dict[str, Any]] = {}
    for ship, names in (SHIP_SCENARIOS if ships is None else ships).items():
        wall: list[float] = []
        cpu: list[float] = []
        for name in names:
            scenario = load_scenario(name)
            limit = min(scenario.config.time_limit, max_steps * scenario.control_period)
            scenario = scenario.with_overrides({"time_limit": limit})
            policy, _ = make_controller(controller)
            run_episode(policy, scenario, seed=seed, privileged=privileged)
            wall += getattr(policy, f"{clock}_times")
            cpu += getattr(policy, f"{clock}_cpu_times", [])
        key = controller if clock == "solve" else f"{controller}_{clock}"
        entry = _percentiles_ms(wall, key)
        if cpu:
            entry |= _percentiles_ms(cpu, f"{key}_cpu")
        entry[f"{key}s" if clock == "step" else f"{controller}_solves"] = len(wall)
        out[ship] = entry
    return out


def bench_nmpc(
    scenarios: tuple[str, ...] = ("nominal", "rudder_aging", "current_shift"),
    family: tuple[str, ...] | None = None,
    max_steps: int | None = None,
) -> dict:
    """NMPC solve time in closed loop: median, p99, ratio to Ts (``nmpc`` on nomoto2's
    ``scenarios``, the paper's settings), and ``per_ship``: every ``family`` member on each
    ship, as the leaderboard runs it (its tuned settings)
    (:func:`solve_times_per_ship`) with ``family_median_ms`` / ``family_p99_ms``, the
    largest over the members (targets ≤ 1 ms / ≤ 5 ms), and the privileged
    ``oracle``'s ``oracle_median_ms`` / ``oracle_p99_ms`` (target median ≤ 20 ms, its
    episodes cut after ``max_steps`` or :data:`ORACLE_MAX_STEPS`); None: :data:`NMPC_FAMILY`,
    :data:`PER_SHIP_MAX_STEPS`."""
    from shipgym_baselines.classical.nmpc import NMPC
    from shipgym_baselines.evaluation import run_episode

    times: list[float] = []
    solves = failures = 0
    control_period = None
    for name in scenarios:
        policy = NMPC(preset="paper")  # the paper's controller (the targets' figure)
        run_episode(policy, name, seed=0)
        times += policy.solve_times
        solves += policy.solves
        failures += policy.failures
        control_period = policy.ctx.control_period
    median = statistics.median(times)
    p99 = float(np.percentile(times, 99))
    family = NMPC_FAMILY if family is None else family
    oracle_steps = ORACLE_MAX_STEPS if max_steps is None else max_steps
    max_steps = PER_SHIP_MAX_STEPS if max_steps is None else max_steps
    per_ship: dict[str, dict[str, Any]] = {ship: {} for ship in SHIP_SCENARIOS}
    for controller in family:
        for ship, entry in solve_times_per_ship(controller, max_steps=max_steps).items():
            per_ship[ship] |= entry
    for ship, entry in solve_times_per_ship("oracle", max_steps=oracle_steps).items():
        per_ship[ship] |= entry
    estimating: dict[str, dict[str, Any]] = {ship: {} for ship in ESTIMATING_SCENARIOS}
    for controller in ESTIMATING:
        steps = solve_times_per_ship(
            controller, ESTIMATING_SCENARIOS, max_steps=oracle_steps, clock="step"
        )
        for ship, entry in steps.items():
            estimating[ship] |= entry
    for entry in per_ship.values():
        for stat in ("median", "p99", "cpu_median", "cpu_p99"):
            values = [entry[f"{c}_{stat}_ms"] for c in family if f"{c}_{stat}_ms" in entry]
            if values:
                entry[f"family_{stat}_ms"] = max(values)
    return {
        "nmpc_median_ms": 1e3 * median,
        "nmpc_p99_ms": 1e3 * p99,
        "nmpc_target_median_ms": 0.5,
        "nmpc_target_p99_ms": 2.0,
        "median_ratio_to_control_period": median / control_period,
        "solves": solves,
        "failures": failures,
        "per_ship": per_ship,
        "per_ship_target_median_ms": 1.0,
        "per_ship_target_p99_ms": 5.0,
        "oracle_target_median_ms": 20.0,
        "estimating_per_ship": estimating,
        "estimating_target_median_ms": 20.0,
    }


#: PPO training on the distribution through the per-ship batched envs runs at
#: least this many times as fast as through SB3's DummyVecEnv (env steps/s, learning included)
BATCHED_OVER_DUMMY_TARGET = 2.0


def _env_clock(venv: Any) -> Any:
    """``venv`` wrapped so that the CPU time [s] of this process spent inside its ``reset``
    and ``step`` is added up in the wrapper's ``cpu_s`` (the env's share of a training;
    the rest is the agent's: forward passes, returns and gradient updates)."""
    from stable_baselines3.common.vec_env import VecEnvWrapper

    class EnvClock(VecEnvWrapper):
        cpu_s = 0.0

        def _timed(self, call: Any, *args: Any) -> Any:
            start = time.process_time()
            try:
                return call(*args)
            finally:
                self.cpu_s += time.process_time() - start

        def reset(self) -> Any:
            return self._timed(self.venv.reset)

        def step_async(self, actions: np.ndarray) -> None:
            self._timed(self.venv.step_async, actions)

        def step_wait(self) -> Any:
            return self._timed(self.venv.step_wait)

    return EnvClock(venv)


def bench_training(
    n_envs: int | None = None,
    timesteps: int = 16_384,
    scenario: str | None = None,
    repeats: int = 1,
    kinds: tuple[str, ...] = ("batched", "dummy", "subproc"),
    wide_envs: int | None = 64,
) -> dict[str, Any]:
    """PPO training throughput (env steps/s, learning included) of the shipped PPO
    configuration (configs/agents/ppo.yaml: the training distribution, its n_envs and
    hyperparameters) through the per-ship batched envs (``vec_env: batched``, a fresh trial
    per env at every reset), SB3's DummyVecEnv and SubprocVecEnv over the randomised single
    env: same config, env steps and machine, measured in the same run, one torch thread.
    ``scenario``: one fixed scenario instead of the distribution.

    ``wide_envs``: also the batched path and DummyVecEnv with that many envs
    (``batched_wide``, ``dummy_wide``; n_steps scaled so that a rollout has the config's
    n_steps·n_envs env steps: the same gradient updates per env step), since the batched
    envs' per-call cost is spread over more envs; 64 × 32 is the tuned agents' rollout
    (docs/tuning.md).  ``batched_wide_over_dummy_wide`` compares equal widths.  The first
    rollout of each run (process start-up, torch warm-up, compile) is excluded.
    Besides the wall-clock rate, ``…_cpu_s`` is this process's CPU time of the timed part
    (subprocess workers not counted), for loaded machines, split into the env's
    (``…_env_cpu_s``: inside the VecEnv's reset and step) and the agent's
    (``…_agent_cpu_s``, the median whole less the median env: forward passes, returns,
    gradient updates, and VecNormalize's reward scaling, which wraps the env's clock); not
    for SubprocVecEnv.
    ``…_cpu_bound`` is Amdahl's bound on a ratio: the DummyVecEnv run's CPU over the
    batched run's agent CPU alone (the ratio if the batched env cost nothing);
    ``…_env_cpu`` is the ratio of the two env shares alone.
    """
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize

    from shipgym_baselines.training.agents import (
        build_hyperparams,
        load_agent_config,
        make_training_env,
    )

    torch.set_num_threads(1)  # as `shipgym train`
    config = load_agent_config("ppo")
    n_envs = config.env.n_envs if n_envs is None else n_envs
    source = {"scenario": scenario, "distribution": None} if scenario else {}
    figures: dict[str, Any] = {
        "config": config.name,
        "training": scenario or config.env.distribution,
        "n_envs": n_envs,
        "timesteps": timesteps,
        "torch_threads": torch.get_num_threads(),
    }
    runs = [(kind, kind, n_envs) for kind in kinds]
    if wide_envs:  # the same comparison at the tuned agents' width (64 envs × 32 steps)
        runs += [
            (f"{kind}_wide", kind, wide_envs) for kind in ("batched", "dummy") if kind in kinds
        ]
        figures["wide_envs"] = wide_envs
    rollout = int(config.hyperparams.get("n_steps", 2048)) * n_envs
    for label, kind, count in runs:
        env_config = config.env.model_copy(update={"vec_env": kind, "n_envs": count, **source})
        hyper = build_hyperparams(config, 1)
        hyper["n_steps"] = max(rollout // count, 1)
        rates, cpu, env_cpu = [], [], []
        for rep in range(repeats):
            clock = _env_clock(make_training_env(env_config, seed=rep))
            venv = VecNormalize(clock, norm_obs=False, norm_reward=config.env.normalize_reward)
            model = PPO(config.policy, venv, seed=rep, device="cpu", **hyper)
            warm = model.n_steps * count
            model.learn(warm)
            done, start, start_cpu = model.num_timesteps, time.perf_counter(), time.process_time()
            env_cpu0 = clock.cpu_s
            model.learn(timesteps, reset_num_timesteps=False)
            rates.append((model.num_timesteps - done) / (time.perf_counter() - start))
            cpu.append(time.process_time() - start_cpu)
            env_cpu.append(clock.cpu_s - env_cpu0)
            venv.close()
        figures[f"ppo_{label}_env_steps_per_s"] = statistics.median(rates)
        figures[f"ppo_{label}_cpu_s"] = statistics.median(cpu)
        figures[f"ppo_{label}_env_steps_per_cpu_s"] = timesteps / statistics.median(cpu)
        if kind != "subproc":  # its env runs in the workers, whose CPU is not counted
            figures[f"ppo_{label}_env_cpu_s"] = statistics.median(env_cpu)
            # the whole's median less the env's: env + agent = the whole over repeats too
            # (non-negative: each repeat's env CPU is part of its whole)
            figures[f"ppo_{label}_agent_cpu_s"] = statistics.median(cpu) - statistics.median(
                env_cpu
            )
    if "batched" in kinds and "dummy" in kinds:
        for label, dummy in (
            ("batched", "dummy"),
            ("batched_wide", "dummy"),
            ("batched_wide", "dummy_wide"),
        ):
            if f"ppo_{label}_cpu_s" in figures and f"ppo_{dummy}_cpu_s" in figures:
                figures[f"{label}_over_{dummy}"] = (
                    figures[f"ppo_{label}_env_steps_per_s"]
                    / figures[f"ppo_{dummy}_env_steps_per_s"]
                )
                figures[f"{label}_over_{dummy}_cpu"] = (
                    figures[f"ppo_{dummy}_cpu_s"] / figures[f"ppo_{label}_cpu_s"]
                )
                # Amdahl's bound: the CPU ratio if the batched env cost nothing at all
                figures[f"{label}_over_{dummy}_cpu_bound"] = (
                    figures[f"ppo_{dummy}_cpu_s"] / figures[f"ppo_{label}_agent_cpu_s"]
                )
                figures[f"{label}_over_{dummy}_env_cpu"] = (
                    figures[f"ppo_{dummy}_env_cpu_s"] / figures[f"ppo_{label}_env_cpu_s"]
                )
        figures["batched_over_dummy_target"] = BATCHED_OVER_DUMMY_TARGET
    if "batched" in kinds and "subproc" in kinds:
        figures["batched_over_subproc"] = (
            figures["ppo_batched_env_steps_per_s"] / figures["ppo_subproc_env_steps_per_s"]
        )
    return figures
