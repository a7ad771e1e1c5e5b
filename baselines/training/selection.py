"""Model selection on the cost relative to a reference, so that every ship counts.

Raw mean validation return is decided by the long full-scale episodes (their returns are
10²–10³ times nomoto2's).  Instead, with ``eval.select_on: relative_cost``, each periodic
evaluation runs the agent on fixed validation trials (validation scenario i with env seed
``EVAL_SEED_OFFSET + i``, the same trials every time) and scores it by

    R = exp( mean_i log(C_i / C_ref,i) )        (geometric mean; lower is better)

with C the episode cost (:func:`shipgym.metrics.episode_cost`) and C_ref the ``oracle``'s
cost on the same trial from the shipped reference table
(:mod:`shipgym_baselines.references`) where present, else ``pid_los``'s, computed once per
run (``eval/reference_costs.json`` in the run folder, with the oracle revision it was read
at: a file of another revision is read again).  The trials are every validation trial by
default (:data:`SELECTION_TRIALS`: ``validation:0`` … ``validation:31``, eight per ship);
never a ``test_only`` split (the held-out and in-range ones the leaderboard ranks).
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from shipgym_baselines.errors import RunError
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET
from shipgym_baselines.privileged import ORACLE
from shipgym_baselines.registry import BASELINE
from shipgym_baselines.scoring.intervals import geometric_mean
from shipgym_baselines.scoring.scores import cost_ratio

#: the fallback reference where the oracle's table has no entry for a trial
FALLBACK_REFERENCE = BASELINE
REFERENCE_FILE = "reference_costs.json"
#: the selection's trials by default (``eval.n_episodes``): all 32 validation trials (with
#: 8, two per ship, the selection score was mostly noise)
SELECTION_TRIALS = 32


def validation_trials(
    distribution: str, n_episodes: int = SELECTION_TRIALS
) -> list[tuple[str, int]]:
    """(scenario name, env seed) of the selection's trials: the first ``n_episodes``
    scenarios of the validation distribution (a test split drawn from the training ranges,
    never a ``test_only`` one), scenario i with seed EVAL_SEED_OFFSET + i."""
    from shipgym.scenarios.sampling import load_distribution
    from shipgym_baselines.tuning.validation import check_validation_split

    dist = load_distribution(distribution)
    if dist.split != "test":
        raise RunError(f"eval.distribution {distribution!r} is not a test split")
    check_validation_split(distribution)
    if n_episodes > len(dist):
        raise RunError(
            f"eval.n_episodes {n_episodes}: {distribution!r} has {len(dist)} scenarios; "
            "relative-cost selection runs each once"
        )
    return [(name, EVAL_SEED_OFFSET + i) for i, name in enumerate(dist.test_names()[:n_episodes])]


def geometric_mean_ratio(costs: Sequence[float], references: Sequence[float]) -> float:
    """exp(mean log(C / C_ref)) over trials: the geometric mean of the leaderboard's cost
    ratios (:func:`~shipgym_baselines.scoring.scores.cost_ratio`); inf where a trial has no
    ratio (a diverged episode), so that a checkpoint with one is never selected."""
    if len(costs) != len(references) or not costs:
        raise ValueError("need one reference cost per cost, and at least one")
    ratios = [cost_ratio(c, r) for c, r in zip(costs, references, strict=True)]
    if any(r is None for r in ratios):
        return math.inf
    return geometric_mean(ratios)


def reference_cost(scenario_name: str, seed: int, action_mode: str = "rudder") -> dict[str, Any]:
    """{"cost": C_ref, "reference": "oracle" | "pid_los"} of one trial (module doc)."""
    from shipgym.scenarios.loader import load_scenario
    from shipgym_baselines.evaluation import evaluate
    from shipgym_baselines.references import shipped_table

    entry = shipped_table().lookup(load_scenario(scenario_name), seed)
    if entry is not None:
        return {"cost": float(entry["metrics"]["cost"]), "reference": ORACLE}
    result = evaluate(FALLBACK_REFERENCE, scenario_name, [seed])[0]
    return {"cost": float(result.metrics["cost"]), "reference": FALLBACK_REFERENCE}


def reference_costs(
    trials: Sequence[tuple[str, int]], cache_dir: str | Path | None = None
) -> list[dict[str, Any]]:
    """The reference cost of every trial, read from / written to ``cache_dir`` (once per
    run: a cache for other trials, or of another oracle revision or env revision, is
    recomputed)."""
    from shipgym_baselines.references import oracle_header

    cache = None if cache_dir is None else Path(cache_dir) / REFERENCE_FILE
    wanted = [[name, seed] for name, seed in trials]
    header = oracle_header()
    revision = {"env_revision": header["env_revision"], "oracle": header["oracle"]}
    if cache is not None and cache.is_file():
        try:  # a cache: an unreadable one is computed again
            data = json.loads(cache.read_text())
            if data.get("trials") == wanted and all(data.get(k) == v for k, v in revision.items()):
                return list(data["references"])
        except (OSError, ValueError, AttributeError, KeyError, TypeError):
            pass
    refs = [reference_cost(name, seed) for name, seed in trials]
    if cache is not None:
        from shipgym_baselines.learned.agent_folder import write_json_file

        write_json_file(cache, {"trials": wanted, "references": refs, **revision}, indent=1)
    return refs


def run_agent_episode(
    model: Any,
    scenario_name: str,
    seed: int,
    action_mode: str,
    context_features: bool,
    history_steps: int = 0,
) -> tuple[float, float]:
    """(episode return, episode cost C) of an SB3 model acting deterministically on one
    trial (RecurrentPPO's memory carried through the episode); ``history_steps``: the
    model's observation history (the env's argument)."""
    from shipgym.envs.path_follow import ShipPathFollowEnv

    env = ShipPathFollowEnv(
        scenario_name,
        action_mode=action_mode,
        context_features=context_features,
        history_steps=history_steps,
    )
    try:
        obs, _ = env.reset(seed=seed)
        state, start, total = None, True, 0.0
        while True:
            action, state = model.predict(
                obs[None], state=state, episode_start=np.array([start]), deterministic=True
            )
            start = False
            obs, reward, terminated, truncated, info = env.step(action[0])
            total += reward
            if terminated or truncated:
                return total, float(info["episode_metrics"]["cost"])
    finally:
        env.close()


def evaluate_relative(
    model: Any,
    trials: Sequence[tuple[str, int]],
    references: Sequence[dict[str, Any]],
    action_mode: str,
    context_features: bool,
    history_steps: int = 0,
) -> dict[str, Any]:
    """The agent on every trial: {"returns", "costs", "selection" (the geometric-mean cost
    ratio)}."""
    returns, costs = [], []
    for name, seed in trials:
        ret, cost = run_agent_episode(
            model, name, seed, action_mode, context_features, history_steps
        )
        returns.append(ret)
        costs.append(cost)
    ratio = geometric_mean_ratio(costs, [r["cost"] for r in references])
    return {"returns": returns, "costs": costs, "selection": ratio}
