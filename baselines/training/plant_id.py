"""Training the learned estimator φ of ``nmpc_learned_id`` (one training seed).

``python -m shipgym_baselines.training.plant_id --seed K --out DIR [--resume]``

1. **Data**: episodes on the training distribution (``configs/distributions/train.yaml``,
   every trained ship), each step's features (:mod:`shipgym_baselines.learned.plant_id.features`)
   with its label read from
   the truth through the training-time teacher channel
   (:func:`shipgym_baselines.privileged.teacher_truth`;
   :mod:`shipgym_baselines.learned.plant_id.labels`).  Round 0 is
   steered by the behaviour controller ``pid_los``; every later round by
   ``nmpc_learned_id`` itself with the previous round's φ (DAgger on the estimate, Ross,
   Gordon & Bagnell 2011: the estimator learns on the states its own closed loop visits).
   The labels cost nothing but simulation.
2. **Fit**: φ on every round's data so far (the Gaussian NLL of
:mod:`shipgym_baselines.learned.plant_id.network`), warm
   started from the previous round, Adam, one thread.
3. **Error curve**: after each round, φ's RMSE per slot on the validation trials' windows
   (``validation:0`` … ``:31``, steered by ``pid_los``; never the held-out split or the
   catalogue), written with the data cost (env steps, CPU seconds) to ``meta.json``.

Each round's data (``data/round_<r>.npz``) and φ (``round_<r>/``) are kept when finished:
``--resume`` starts after the last finished step.  ``DIR/estimator`` is the last round's φ.

``DIR`` is written as every run folder is (:mod:`shipgym_baselines.records`): locked while
the training runs, each file listed in ``manifest.txt`` before it is written, written
whole and through no link; a folder holding a link is refused.
"""

from __future__ import annotations

import argparse
import io
import json
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.envs.path_follow import ShipPathFollowEnv
from shipgym.scenarios.loader import build_scenario, load_scenario
from shipgym.scenarios.sampling import load_distribution, train_rng
from shipgym_baselines.executor import map_jobs
from shipgym_baselines.learned.plant_id.features import STEP_FEATURES, WINDOW, step_row
from shipgym_baselines.learned.plant_id.labels import SLOTS, Labeller, slot_mask
from shipgym_baselines.learned.plant_id.network import Estimator, build, nll, one_thread
from shipgym_baselines.privileged import teacher_truth
from shipgym_baselines.records.folders import check_out_dir, check_out_usable
from shipgym_baselines.records.locking import out_lock
from shipgym_baselines.records.manifest import Manifest
from shipgym_baselines.records.outfiles import check_no_links, make_dir, write_bytes, write_text
from shipgym_baselines.records.runrecord import now
from shipgym_baselines.registry import make_controller

#: the behaviour controller of round 0
BEHAVIOUR = "pid_los"
#: the training seed's salt of the scenario draws (rounds and episodes: their own seeds)
SEED_SALT = 0x1D_E57


def rollout(scenario: Any, policy: Any, seed: int) -> dict[str, np.ndarray]:
    """One episode of ``policy`` on ``scenario``: per step (the reset's included) the
    features, the context row, the label and the slot mask."""
    env = ShipPathFollowEnv(scenario)
    try:
        obs, info = env.reset(seed=seed)
        ctx = env.controller_context
        truth = teacher_truth(env)  # training time: the labels' truth
        labeller = Labeller(ctx)
        policy.reset(ctx, seed=seed)
        rows, labels = [step_row(info, None, ctx)], [labeller(truth())]
        previous, done = info, False
        while not done:
            obs, _, terminated, truncated, info = env.step(policy.act(obs, info))
            done = terminated or truncated
            rows.append(step_row(info, previous, ctx))
            labels.append(labeller(truth()))
            previous = info
        n = len(rows)
        return {
            "rows": np.array(rows, dtype=np.float32),
            "context": np.tile(ctx.feature_row, (n, 1)).astype(np.float32),
            "labels": np.array(labels, dtype=np.float32),
            "mask": np.tile(slot_mask(ctx.ship, learned=True), (n, 1)).astype(np.float32),
        }
    finally:
        env.close()


def _episode(job: tuple[str, dict, int, str | None]) -> dict[str, np.ndarray]:
    """A worker's episode: (scenario name or "train", draw, seed, estimator folder)."""
    kind, draw, seed, folder = job
    if kind == "train":
        config = load_distribution("train").sample(
            train_rng(draw["scenario_seed"]), name=f"train:{draw['scenario_seed']}"
        )
        scenario = build_scenario(config, config.name)
    else:
        scenario = load_scenario(kind)
    if folder is None:
        policy, _ = make_controller(BEHAVIOUR)
    else:
        # the spreads of the fallback before tuning: the chosen ones were tuned on a trained φ
        policy, _ = make_controller("nmpc_learned_id", folder=folder, preset="default")
    return rollout(scenario, policy, seed)


def collect(jobs: Sequence[tuple], workers: int) -> dict[str, np.ndarray]:
    """The episodes of ``jobs`` (in order), concatenated, with ``starts`` (each episode's
    first row)."""
    episodes = list(map_jobs(_episode, jobs, "local", workers, ordered=True))
    lengths = [len(e["rows"]) for e in episodes]
    data = {k: np.concatenate([e[k] for e in episodes]) for k in episodes[0]}
    data["starts"] = np.cumsum([0, *lengths[:-1]]).astype(np.int64)
    return data


def round_jobs(seed: int, round_: int, episodes: int, folder: str | None) -> list[tuple]:
    """The training-distribution episodes of one round (their own scenario seeds)."""
    rng = np.random.default_rng([SEED_SALT, seed, round_])
    return [
        ("train", {"scenario_seed": int(rng.integers(0, 2**62))}, int(rng.integers(2**31)), folder)
        for _ in range(episodes)
    ]


def windows(data: dict[str, np.ndarray], index: np.ndarray) -> np.ndarray:
    """(B, WINDOW·F + C) the windows ending at rows ``index`` (zeros before each episode's
    start, as :class:`~shipgym_baselines.learned.plant_id.features.Window` holds them)."""
    step_of = np.searchsorted(data["starts"], index, side="right") - 1
    first = data["starts"][step_of]
    rows = index[:, None] - (WINDOW - 1) + np.arange(WINDOW)[None, :]
    valid = rows >= first[:, None]
    gathered = data["rows"][np.maximum(rows, 0)] * valid[..., None]
    flat = gathered.reshape(len(index), -1)
    return np.concatenate([flat, data["context"][index]], axis=1).astype(np.float32)


def merge(parts: Sequence[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Rounds' data as one set (episode starts shifted)."""
    out: dict[str, list] = {k: [] for k in ("rows", "context", "labels", "mask", "starts")}
    offset = 0
    for part in parts:
        for k in ("rows", "context", "labels", "mask"):
            out[k].append(part[k])
        out["starts"].append(part["starts"] + offset)
        offset += len(part["rows"])
    return {k: np.concatenate(v) for k, v in out.items()}


def fit(
    data: dict[str, np.ndarray],
    seed: int,
    updates: int,
    previous: Estimator | None,
    batch: int = 512,
    learning_rate: float = 1e-3,
) -> Estimator:
    """φ fitted to ``data`` by ``updates`` Adam steps (warm start: ``previous``)."""
    torch = one_thread()
    n = len(data["rows"])
    rng = np.random.default_rng([SEED_SALT, seed, updates, n])
    inputs = len(STEP_FEATURES) * WINDOW + data["context"].shape[1]
    if previous is None:
        sample = windows(data, rng.choice(n, size=min(n, 50_000), replace=False))
        mean, std = sample.mean(axis=0), sample.std(axis=0) + 1e-6
        net = build(inputs, len(SLOTS), seed)
    else:
        mean, std, net = previous.mean, previous.std, previous.net
    net.train()
    optimiser = torch.optim.Adam(net.parameters(), lr=learning_rate)
    schedule = torch.optim.lr_scheduler.CosineAnnealingLR(optimiser, T_max=updates)
    for _ in range(updates):
        index = rng.integers(0, n, size=batch)
        x = torch.from_numpy((windows(data, index) - mean) / std)
        y = torch.from_numpy(data["labels"][index])
        m = torch.from_numpy(data["mask"][index])
        loss = nll(net(x), y, m)
        optimiser.zero_grad()
        loss.backward()
        optimiser.step()
        schedule.step()
    meta = {"inputs": inputs, "outputs": len(SLOTS), "slots": list(SLOTS), "window": WINDOW}
    return Estimator(net, mean.astype(np.float32), std.astype(np.float32), meta)


def rmse(estimator: Estimator, data: dict[str, np.ndarray]) -> dict[str, float]:
    """φ's RMSE per slot over the windows of ``data`` (the slots a ship has)."""
    index = np.arange(len(data["rows"]))
    mean, _ = estimator.predict(windows(data, index))
    err = (mean - data["labels"]) ** 2 * data["mask"]
    counts = data["mask"].sum(axis=0)
    return {s: float(np.sqrt(err[:, i].sum() / max(counts[i], 1))) for i, s in enumerate(SLOTS)}


def save_data(path: Path, data: dict[str, np.ndarray]) -> None:
    """``data`` as ``path`` (written whole, through no link: never half a file)."""
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **data)
    write_bytes(path, buffer.getvalue())


def load_data(path: Path) -> dict[str, np.ndarray]:
    with np.load(path) as f:
        return {k: f[k] for k in f.files}


def train(
    seed: int,
    out: Path,
    resume: bool,
    first: int = 1200,
    later: int = 60,
    rounds: int = 3,
    updates: int = 12_000,
    later_updates: int = 4_000,
    workers: int = 2,
    validation_trials: int = 32,
) -> dict[str, Any]:
    """The rounds of module doc, in the run folder ``out`` (module doc); returns the meta
    written to ``out/estimator/meta.json``.  A folder that is not empty is refused unless
    ``resume`` (:class:`~shipgym_baselines.errors.RunError`, one line)."""
    check_out_usable(out, resume=resume)
    with out_lock(out, now()):
        check_no_links(out)
        if not resume:
            check_out_dir(out, note=" (a φ training's folder)")
        manifest = Manifest(out)
        with manifest.recording():
            meta = _train(
                seed, out, first, later, rounds, updates, later_updates, workers, validation_trials
            )
        manifest.compact()
        return meta


def _train(
    seed: int,
    out: Path,
    first: int,
    later: int,
    rounds: int,
    updates: int,
    later_updates: int,
    workers: int,
    validation_trials: int,
) -> dict[str, Any]:
    """:func:`train` in its folder, locked and recording."""
    make_dir(out / "data")
    cost_file = out / "cost.json"
    cost = json.loads(cost_file.read_text()) if cost_file.exists() else {"rounds": []}
    val_file = out / "data" / "validation.npz"
    if not val_file.exists():
        jobs = [(f"validation:{i}", {}, 10_000, None) for i in range(validation_trials)]
        save_data(val_file, collect(jobs, workers))
    validation = load_data(val_file)
    parts: list[dict[str, np.ndarray]] = []
    estimator: Estimator | None = None
    for r in range(rounds):
        shard = out / "data" / f"round_{r:03d}.npz"
        folder = out / f"round_{r:03d}"
        if not shard.exists():
            behaviour = None if r == 0 else str(out / f"round_{r - 1:03d}")
            start = time.perf_counter()
            data = collect(round_jobs(seed, r, first if r == 0 else later, behaviour), workers)
            save_data(shard, data)
            cost["rounds"] = [c for c in cost["rounds"] if c["round"] != r] + [
                {
                    "round": r,
                    "episodes": len(data["starts"]),
                    "env_steps": len(data["rows"]),
                    "collect_wall_s": time.perf_counter() - start,
                    "behaviour": BEHAVIOUR if r == 0 else "nmpc_learned_id",
                }
            ]
            write_text(cost_file, json.dumps(cost, indent=1))
        parts.append(load_data(shard))
        if (folder / "meta.json").exists():
            estimator = Estimator.load(folder)
            continue
        start = time.perf_counter()
        estimator = fit(merge(parts), seed, updates if r == 0 else later_updates, estimator)
        estimator.meta.update(
            {
                "round": r,
                "seed": seed,
                "fit_wall_s": time.perf_counter() - start,
                "validation_rmse": rmse(estimator, validation),
                "env_steps": int(sum(len(p["rows"]) for p in parts)),
            }
        )
        estimator.save(folder)
    assert estimator is not None
    curve = [json.loads((out / f"round_{r:03d}" / "meta.json").read_text()) for r in range(rounds)]
    meta = {
        **estimator.meta,
        "error_curve": [
            {
                "round": c["round"],
                "env_steps": c["env_steps"],
                "validation_rmse": c["validation_rmse"],
            }
            for c in curve
        ],
        "data_cost": cost["rounds"],
    }
    final = out / "estimator"
    estimator.save(final)  # its two files replaced whole
    write_text(final / "meta.json", json.dumps(meta, indent=1) + "\n")
    return meta


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, required=True)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--resume", action="store_true")
    parser.add_argument("--first", type=int, default=1200, help="round-0 episodes")
    parser.add_argument("--later", type=int, default=60, help="episodes of each later round")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--updates", type=int, default=12_000)
    parser.add_argument("--later-updates", type=int, default=4_000)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--validation-trials", type=int, default=32)
    args = parser.parse_args(argv)
    meta = train(
        args.seed,
        args.out,
        args.resume,
        args.first,
        args.later,
        args.rounds,
        args.updates,
        args.later_updates,
        args.workers,
        args.validation_trials,
    )
    print(json.dumps(meta["error_curve"], indent=1))


if __name__ == "__main__":
    main()
