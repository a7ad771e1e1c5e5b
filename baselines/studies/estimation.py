"""How well a controller that estimates the plant knows it: the estimate against the truth.

For a controller that predicts with an estimate of the plant (``nmpc_ekf``, and every
controller that keeps an ``estimate_log`` of (t, state, parameters, disturbances) per step),
this study plays trials and scores, after each episode, the estimate of every sampled step
against the truth the env kept (the scenario's schedule and the disturbance log: read here,
after the episode, never by the controller).

**Error of an estimate** (one number for every change family and ship): from the estimated
state at t, the plant is simulated for 2T (T the ship's nominal yaw time constant) with the
rudder commanded to 10°, once with the estimated parameters and disturbances and once with
the true ones; the error is the distance between the two end positions in ship lengths L.
The same with the nominal ship and no disturbance is the error of an estimator that never
adapts (``nominal``).  The disturbances compared are the current and yaw bias: the true
ones averaged over the control period before t (the waves' load averages out).

**Per trial with a change at t\\*:** the mean error over the steps after t\\*, the nominal's
over the same steps, their ratio (the share of the nominal error left), and the settling
time: from t\\* until the error stays below ``SETTLED_L`` (NaN: it never does), in T.  The
change family is read off the truth: a servo time constant that moved is rudder aging, a
current or yaw bias that moved a current shift, any other parameter a manoeuvrability
change.

``python -m shipgym_baselines.studies.estimation [--controllers C …] [--trials N] [--out DIR]``
plays the first N trials per ship of the validation split (default 8: all of them) and
writes ``estimation.json`` and the figures ``estimation_families.png`` (the error ratio per
family) and ``estimation_trial.png`` (a rudder-aging trial's servo time constant and a
current-shift trial's current speed, estimated against the truth) into DIR.
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from shipgym.identification.adaptation import QUANTITIES
from shipgym.identification.nominal import first_order_nomoto
from shipgym.models import MODELS, UNSEEN_HULLS
from shipgym.scenarios.families import CHANGES, family_label
from shipgym.scenarios.loader import Scenario, load_scenario
from shipgym_baselines.evaluation import EVAL_SEED_OFFSET, run_episode
from shipgym_baselines.registry import make_controller
from shipgym_baselines.studies.change_effect import change_time

#: the error [L] below which an estimate counts as settled
SETTLED_L = 0.1
#: the rudder command of the prediction that measures an estimate [rad]
PROBE_RUDDER = math.radians(10.0)
#: prediction time of the probe [yaw time constants T]
PROBE_T = 2.0
#: steps scored per episode (evenly spaced)
SCORED_STEPS = 60


def probe_positions(
    model: Any, state: np.ndarray, thetas: np.ndarray, ws: np.ndarray, seconds: float, h: float
) -> np.ndarray:
    """(N, 2) end positions [m] of N plants (parameter vectors ``thetas`` (N, n_p),
    disturbances ``ws`` (N, n_w)) simulated from ``state`` for ``seconds`` at RK4 step h
    with the rudder commanded to :data:`PROBE_RUDDER`."""
    n = thetas.shape[0]
    x = np.tile(state[:, None], (1, n))
    command = np.full(n, PROBE_RUDDER)
    for _ in range(max(1, round(seconds / h))):
        x = model.step_numpy(x, [command], ws.T, thetas.T, h)
    return np.stack([x[model.state_index("x")], x[model.state_index("y")]], axis=1)


def truth_family(scenario: Scenario, end: float, w_start: np.ndarray, w_end: np.ndarray) -> str:
    """The family of the trial's change (:data:`shipgym.scenarios.families.CHANGES`), read
    off the truth (module doc; a sampled trial's file names none); "none"."""
    ship = scenario.model.name
    servo = {p for q in QUANTITIES[ship] if q.name == "servo" for p in q.params}
    before = scenario.schedule.record_at(0.0).as_dict()
    after = scenario.schedule.record_at(end).as_dict()
    moved = {k for k in before if not math.isclose(before[k], after[k], rel_tol=1e-9)}
    speed = scenario.model.nominal_speed
    if moved & servo:
        return "rudder_aging"
    if "d0" in moved or float(np.max(np.abs(w_end[:2] - w_start[:2]))) > 0.01 * speed:
        return "current_shift"
    return "maneuverability_change" if moved else "none"


def period_means(disturbances: dict[str, np.ndarray], names: Sequence[str], ts: float):
    """(t_end [s], (n_periods, n_w) the disturbances averaged over each control period)."""
    t = disturbances["t"]
    periods = np.floor(t / ts + 1e-9).astype(int)
    count = int(periods.max()) + 1 if periods.size else 0
    rows = np.zeros((count, len(names)))
    for j, name in enumerate(names):
        rows[:, j] = np.bincount(periods, disturbances[name], count) / np.maximum(
            np.bincount(periods, minlength=count), 1
        )
    return (np.arange(count) + 1) * ts, rows


def score_episode(policy: Any, scenario: Scenario, disturbances: dict[str, np.ndarray]) -> dict:
    """One episode's estimates against the truth (module doc)."""
    model = scenario.model
    nominal = scenario.schedule.nominal
    _, t_yaw = first_order_nomoto(model, nominal)
    ts, h = scenario.control_period, scenario.fine_step
    ends, w_true = period_means(disturbances, model.disturbance_names, ts)
    log = policy.estimate_log
    servo = next(q.params[0] for q in QUANTITIES[model.name] if q.name == "servo")
    i_servo = type(nominal).names().index(servo)
    picks = (
        np.unique(np.linspace(1, len(log) - 1, SCORED_STEPS).astype(int)) if len(log) > 1 else []
    )
    rows = []
    for k in picks:
        t, state, theta, w = log[k]
        period = min(round(t / ts) - 1, len(ends) - 1)
        if period < 0:
            continue
        truth = scenario.schedule.record_at(t).to_vector()
        thetas = np.stack([truth, theta, nominal.to_vector()])
        ws = np.stack([w_true[period], w, np.zeros_like(w)])
        ends_xy = probe_positions(model, state, thetas, ws, PROBE_T * t_yaw, h)
        length = scenario.ship_length
        rows.append(
            (
                t,
                float(np.hypot(*(ends_xy[1] - ends_xy[0])) / length),
                float(np.hypot(*(ends_xy[2] - ends_xy[0])) / length),
                float(theta[i_servo]),
                float(truth[i_servo]),
                float(np.hypot(*w[:2])),
                float(np.hypot(*w_true[period][:2])),
            )
        )
    times = np.array([r[0] for r in rows])
    error = np.array([r[1] for r in rows])
    frozen = np.array([r[2] for r in rows])
    series = {
        "servo_estimate_s": [r[3] for r in rows],
        "servo_true_s": [r[4] for r in rows],
        "current_estimate_m_s": [r[5] for r in rows],
        "current_true_m_s": [r[6] for r in rows],
    }
    change = change_time(scenario)
    family = truth_family(scenario, float(times[-1]) if times.size else 0.0, w_true[0], w_true[-1])
    after = times >= (change if change is not None else math.inf)
    out: dict[str, Any] = {
        "scenario": scenario.name,
        "ship": model.name,
        "family": family,
        "change_time": change,
        "yaw_time_constant": t_yaw,
        "t": times.tolist(),
        "error_L": error.tolist(),
        "nominal_error_L": frozen.tolist(),
        **series,
    }
    if after.any():
        out["error_after_L"] = float(error[after].mean())
        out["nominal_after_L"] = float(frozen[after].mean())
        out["error_share"] = out["error_after_L"] / max(out["nominal_after_L"], 1e-12)
        unsettled = np.nonzero(after & (error > SETTLED_L))[0]
        if unsettled.size == 0:
            out["settling_T"] = 0.0
        elif unsettled[-1] == len(times) - 1:
            out["settling_T"] = math.nan
        else:
            out["settling_T"] = float(times[unsettled[-1] + 1] - change) / t_yaw
    return out


def play(controller: str, scenario: Scenario, seed: int) -> dict:
    """Play one trial with ``controller`` and score its estimates."""
    policy, mode = make_controller(controller)
    if not hasattr(policy, "estimate_log"):
        raise ValueError(f"{controller} keeps no estimate_log: it does not estimate the plant")
    kept: dict[str, Any] = {}

    def keep(env: Any) -> None:
        kept["w"] = env.episode_disturbances()

    result = run_episode(policy, scenario, seed, mode, after_episode=keep)
    row = score_episode(policy, scenario, kept["w"])
    row["controller"] = controller
    row["cost"] = result.metrics["cost"]
    return row


def summary(rows: Sequence[dict]) -> dict[str, dict[str, dict[str, float]]]:
    """controller → family → medians over its trials: the error after the change [L], the
    nominal's, their ratio and the settling time [T] (NaN counted as never)."""
    out: dict[str, dict[str, dict[str, float]]] = {}
    for row in rows:
        if "error_share" not in row or row["family"] == "none":
            continue
        cell = out.setdefault(row["controller"], {}).setdefault(row["family"], {})
        for key in ("error_after_L", "nominal_after_L", "error_share", "settling_T"):
            cell.setdefault(key, []).append(row[key])  # type: ignore[attr-defined]
    for families in out.values():
        for family, cell in families.items():
            settling = np.array(cell["settling_T"], dtype=float)
            families[family] = {
                "trials": len(settling),
                "error_after_L": float(np.median(cell["error_after_L"])),
                "nominal_after_L": float(np.median(cell["nominal_after_L"])),
                "error_share": float(np.median(cell["error_share"])),
                "settling_T": float(np.median(np.where(np.isnan(settling), np.inf, settling))),
                "never_settled": int(np.isnan(settling).sum()),
            }
    return out


def draw(rows: Sequence[dict], summaries: dict, out: Path) -> None:
    """The two figures (module doc)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    controllers = list(summaries)
    fig, ax = plt.subplots(figsize=(6.4, 3.2))
    width = 0.8 / max(1, len(controllers))
    for i, c in enumerate(controllers):
        values = [summaries[c].get(f, {}).get("error_share", np.nan) for f in CHANGES]
        ax.bar(np.arange(len(CHANGES)) + i * width, values, width, label=c)
    ax.set_xticks(np.arange(len(CHANGES)) + 0.4 - width / 2, [family_label(f) for f in CHANGES])
    ax.axhline(1.0, color="0.4", lw=0.8, ls="--")
    ax.set_ylabel("error left of the nominal's (median)")
    ax.legend(frameon=False)
    fig.tight_layout()
    fig.savefig(out / "estimation_families.png", dpi=120)
    plt.close(fig)
    fig, axes = plt.subplots(1, 2, figsize=(9.6, 3.2))
    for ax, family, key, unit in (
        (axes[0], "rudder_aging", "servo", "servo time constant [s]"),
        (axes[1], "current_shift", "current", "current speed [m/s]"),
    ):
        trials = [r for r in rows if r["family"] == family and r.get("error_share") is not None]
        if not trials:
            ax.set_visible(False)
            continue
        trial = trials[0]["scenario"]
        estimate, true = (
            ("servo_estimate_s", "servo_true_s")
            if key == "servo"
            else ("current_estimate_m_s", "current_true_m_s")
        )
        first = None
        for r in rows:
            if r["scenario"] == trial:
                first = first or r
                ax.plot(r["t"], r[estimate], label=r["controller"])
        assert first is not None
        ax.plot(first["t"], first[true], color="k", ls="--", label="truth")
        ax.set_xlabel("t [s]")
        ax.set_ylabel(unit)
        ax.set_title(f"{trial} ({first['ship']})")
        ax.legend(frameon=False)
    fig.tight_layout()
    fig.savefig(out / "estimation_trial.png", dpi=120)
    plt.close(fig)


def validation_trials(per_ship: int) -> list[str]:
    """The first ``per_ship`` validation trials of every trained ship (interleaved)."""
    ships = len([m for m in MODELS if m not in UNSEEN_HULLS])
    return [f"validation:{i}" for i in range(per_ship * ships)]


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--controllers", nargs="+", default=["nmpc_ekf"])
    parser.add_argument("--trials", type=int, default=8, help="validation trials per ship")
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args(argv)
    if args.out.exists() and any(args.out.iterdir()):
        parser.error(f"--out {args.out} is not empty: choose a new folder")
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    for name in validation_trials(args.trials):
        scenario = load_scenario(name)
        for controller in args.controllers:
            row = play(controller, scenario, EVAL_SEED_OFFSET)
            rows.append(row)
            print(
                f"{name:15s} {row['ship']:10s} {row['family']:22s} {controller:16s} "
                f"share {row.get('error_share', math.nan):.2f} "
                f"settling {row.get('settling_T', math.nan):.1f} T",
                flush=True,
            )
    summaries = summary(rows)
    (args.out / "estimation.json").write_text(
        json.dumps({"summary": summaries, "trials": rows}, indent=1, default=float)
    )
    draw(rows, summaries, args.out)
    print(json.dumps(summaries, indent=1))


if __name__ == "__main__":
    main()
