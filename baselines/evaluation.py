"""The one evaluation loop: any policy, any scenario, a list of seeds (SPEC §8–9)."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from typing import Any

import gymnasium as gym
import numpy as np

import shipgym  # noqa: F401  (registers the envs)
from baselines.plugins import ControllerEntry, ControllerSpec
from baselines.policy import Policy
from baselines.registry import make_controller

ENV_ID = "ShipPathFollow-v0"
#: evaluation seeds start here, apart from the training seeds (0, 1, …) of learned agents
EVAL_SEED_OFFSET = 10_000


@dataclasses.dataclass
class EpisodeResult:
    """Metrics and trajectory of one (controller, scenario, seed) episode; ``training_seed``:
    the seed a learned policy was trained with (None for the rest)."""

    controller: str
    kind: str
    scenario: str
    seed: int
    metrics: dict[str, Any]
    trajectory: dict[str, np.ndarray]
    training_seed: int | None = None

    def row(self) -> dict[str, Any]:
        return {
            "scenario": self.scenario,
            "controller": self.controller,
            "kind": self.kind,
            "seed": self.seed,
            **self.metrics,
        }


def run_episode(
    policy: Policy,
    scenario: Any,
    seed: int,
    action_mode: str | None = None,
    env_id: str = ENV_ID,
    after_episode: Callable[[Any], None] | None = None,
) -> EpisodeResult:
    """Run one episode; the policy sees only obs, info and the controller context.

    ``action_mode``: the env's (None: the policy's ``action_mode``, else "rudder").
    ``after_episode``: called with the unwrapped env after the last step, before it is
    closed, to read the env's own episode logs (e.g. ``episode_disturbances()``).
    Controller compute time is measured here, around each ``act`` call, never by the env:
    ``compute_ms`` [ms] is its mean per step and ``compute_ms_max`` [ms] its maximum.
    """
    if action_mode is None:
        action_mode = getattr(policy, "action_mode", "rudder")
    env = gym.make(env_id, scenario=scenario, action_mode=action_mode)
    try:
        obs, info = env.reset(seed=seed)
        base = env.unwrapped
        policy.reset(base.controller_context, seed=seed)
        act_times: list[float] = []
        rows: list[tuple[float, ...]] = [_traj_row(info)]
        while True:
            start = time.perf_counter()
            action = policy.act(obs, info)
            act_times.append(time.perf_counter() - start)
            obs, _reward, terminated, truncated, info = env.step(action)
            rows.append(_traj_row(info))
            if terminated or truncated:
                break
        metrics = dict(info["episode_metrics"])
        metrics["termination_reason"] = info.get("termination_reason")
        metrics.update(compute_time_metrics(act_times))
        stats = getattr(policy, "episode_stats", None)
        if stats is not None:  # controller-specific figures (e.g. NMPC solver failures)
            metrics.update(stats())
        if after_episode is not None:
            after_episode(base)
        traj = np.array(rows)
        trajectory = {k: traj[:, i] for i, k in enumerate(_TRAJ_KEYS)}
        return EpisodeResult(
            controller=policy.name,
            kind=policy.kind,
            scenario=base.scenario.name,
            seed=seed,
            metrics=metrics,
            trajectory=trajectory,
            training_seed=training_seed(policy),
        )
    finally:
        env.close()


def training_seed(policy: Policy) -> int | None:
    """The seed ``policy`` was trained with: its ``training_seed`` attribute, else the
    ``seed`` of its training meta (learned policies); None when it has neither."""
    seed = getattr(policy, "training_seed", None)
    meta = getattr(policy, "meta", None)
    if seed is None and isinstance(meta, dict):
        seed = meta.get("seed")
    return int(seed) if seed is not None else None


def compute_time_metrics(act_times: list[float]) -> dict[str, float]:
    """``compute_ms`` (mean) and ``compute_ms_max`` [ms] of the ``act`` durations [s]."""
    return {
        "compute_ms": 1e3 * float(np.mean(act_times)),
        "compute_ms_max": 1e3 * float(np.max(act_times)),
    }


_TRAJ_KEYS = ("t", "x", "y", "cross_track_error", "heading", "rudder_angle", "rudder_command")


def _traj_row(info: dict[str, Any]) -> tuple[float, ...]:
    x, y = info["position"]
    return (
        info["t"],
        x,
        y,
        info["cross_track_error"],
        info["heading"],
        info["rudder_angle"],
        info["rudder_command"],
    )


def evaluate(
    controller: ControllerSpec | Policy, scenario: Any, seeds: list[int], **settings: Any
) -> list[EpisodeResult]:
    """Evaluate a controller on a scenario over seeds.

    ``controller``: a name, spec or long form :func:`~baselines.registry.make_controller`
    knows (made afresh per seed with ``settings``) or a Policy instance (``settings`` may
    give its ``action_mode``; default: the policy's own).
    """
    results = []
    for seed in seeds:
        if isinstance(controller, str | ControllerEntry):
            policy, mode = make_controller(controller, **settings)
        else:
            policy, mode = controller, settings.get("action_mode")
        results.append(run_episode(policy, scenario, seed, mode))
    return results
