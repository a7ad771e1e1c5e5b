"""Learning curves of training runs and the plateau rule that stops them.

``learning_curve.json`` (in each run's folder and each shipped ``seed_<k>`` policy folder)::

    {"env_steps": [...], "mean_return": [...], "std_return": [...]}

one entry per periodic validation evaluation, env steps strictly increasing; the run may add
``"selection": [...]`` (the model-selection metric at each evaluation, lower is better, when
the run selects on the relative cost, :mod:`shipgym_baselines.training.selection`).

The plateau rule (:class:`PlateauRule`): training stops once the last ``window`` fraction of
the env steps so far improved the best value of the metric by less than ``min_gain``
(relative), e.g. under 2 % over the last 25 % of training.
"""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import Field

from shipgym.config import StrictModel
from shipgym_baselines.errors import RunError
from shipgym_baselines.records.outfiles import write_text

CURVE_FILE = "learning_curve.json"
CURVE_KEYS = ("env_steps", "mean_return", "std_return")


def write_curve(
    out: str | Path,
    env_steps: list[int],
    returns: list[list[float]],
    selection: list[float] | None = None,
) -> Path:
    """Write ``out/learning_curve.json`` from the evaluations (env steps, the episode returns
    of each evaluation); ``selection``: the selection metric per evaluation."""
    values = [np.asarray(r, dtype=float) for r in returns]
    curve: dict[str, Any] = {
        "env_steps": [int(s) for s in env_steps],
        "mean_return": [float(v.mean()) for v in values],
        "std_return": [float(v.std()) for v in values],
    }
    if selection is not None:
        curve["selection"] = [float(x) for x in selection]
    check_curve(curve, str(out))
    path = Path(out) / CURVE_FILE
    write_text(path, json.dumps(curve, indent=1))  # atomic, through no link
    return path


def check_curve(curve: Any, where: str) -> dict[str, list[float]]:
    """The curve if well formed (the three keys, equal lengths, finite numbers, env steps
    strictly increasing), else a :class:`RunError` naming the problem."""
    if not isinstance(curve, dict) or any(key not in curve for key in CURVE_KEYS):
        raise RunError(f"{where}: a learning curve has the keys {', '.join(CURVE_KEYS)}")
    lengths = {len(curve[key]) for key in CURVE_KEYS}
    if len(lengths) != 1:
        raise RunError(f"{where}: learning curve lists of different lengths {sorted(lengths)}")
    for key in CURVE_KEYS:
        if not all(isinstance(x, int | float) and math.isfinite(x) for x in curve[key]):
            raise RunError(f"{where}: learning curve '{key}' holds a non-finite value")
    steps = curve["env_steps"]
    if any(b <= a for a, b in itertools.pairwise(steps)):
        raise RunError(f"{where}: learning curve env_steps not strictly increasing")
    return curve


def load_curve(folder: str | Path) -> dict[str, list[float]] | None:
    """The learning curve of a run or policy folder, or None when it has none."""
    path = Path(folder) / CURVE_FILE
    if not path.is_file():
        return None
    try:
        curve = json.loads(path.read_text())
    except json.JSONDecodeError as exc:
        raise RunError(f"{path}: not JSON ({exc.msg})") from exc
    return check_curve(curve, str(path))


#: a training seed "never improved" when the best of its selection metric is less than this
#: fraction below its first evaluation's (after eval.freq env steps: training moved it no
#: further)
NEVER_IMPROVED_GAIN = 0.10
#: a training seed is "unstable" when its last evaluation's selection metric is at least this
#: factor over its best (training went on far past the model it ships)
UNSTABLE_FACTOR = 2.0
#: what the flags say, for the page's note and the docs
SEED_FLAG_RULE = (
    f"a training seed is flagged 'unstable' when its last validation cost ratio is "
    f"{UNSTABLE_FACTOR:g}× its best or more, else 'never improved' when its best is less than "
    f"{NEVER_IMPROVED_GAIN:.0%} below its first evaluation's (its learning_curve.json's "
    "selection metric; a curve without one, or with one evaluation, is not judged)"
)


def seed_flag(curve: dict[str, Any]) -> dict[str, Any] | None:
    """The flag of one training seed's learning curve (:data:`SEED_FLAG_RULE`): ``flag``
    ("never improved" or "unstable") with the curve's ``first``, ``best`` and ``final``
    selection values; None when neither applies or the curve has no selection metric."""
    selection = curve.get("selection")
    if not selection or len(selection) < 2:
        return None
    first, best, final = float(selection[0]), float(min(selection)), float(selection[-1])
    values = {"first": first, "best": best, "final": final}
    if final >= UNSTABLE_FACTOR * best:
        return {"flag": "unstable", **values}
    if best > (1.0 - NEVER_IMPROVED_GAIN) * first:
        return {"flag": "never improved", **values}
    return None


def seed_flags(curves: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The flags of an agent's training seeds (:func:`agent_curves`' curves, each with its
    ``seed``): one entry per flagged seed, ``training_seed`` first."""
    flags = []
    for curve in curves:
        flag = seed_flag(curve)
        if flag is not None:
            flags.append({"training_seed": curve["seed"], **flag})
    return flags


def flag_text(flag: dict[str, Any]) -> str:
    """One flagged seed in words: "seed 1 never improved (first 33.63, best 33.62, last
    33.62)" (validation cost ratios)."""
    return (
        f"seed {flag['training_seed']} {flag['flag']} (first {flag['first']:.2f}, best "
        f"{flag['best']:.2f}, last {flag['final']:.2f})"
    )


class PlateauRule(StrictModel):
    """Stop when the best of the metric improved by under ``min_gain`` (relative) over the
    last ``window`` fraction of the env steps so far, after ``min_evaluations`` and not
    before ``min_fraction`` of the run's env-step budget."""

    min_gain: float = Field(0.02, ge=0)
    window: float = Field(0.25, gt=0, lt=1)
    min_evaluations: int = Field(4, ge=2)
    #: no stop before this fraction of the budget (``plateaued``'s ``budget``): early in a
    #: run the window is a few noisy evaluations wide (a PPO run with 0 stopped at 280 k
    #: of 3 M steps on an 8-episode evaluation's 1.87 → 2.34 → 2.21)
    min_fraction: float = Field(0.0, ge=0, lt=1)
    #: "return": the mean validation return (higher is better); "selection": the
    #: selection metric (the relative cost, lower is better)
    metric: str = Field("return", pattern="^(return|selection)$")

    def gain(self, env_steps: list[int], values: list[float]) -> float | None:
        """Relative gain of the best value over the window (positive = better), or None
        while there are too few evaluations or none before the window."""
        if len(values) < self.min_evaluations:
            return None
        steps = np.asarray(env_steps, dtype=float)
        v = np.asarray(values, dtype=float)
        if self.metric == "selection":
            v = -v  # lower cost is better
        start = steps[-1] * (1.0 - self.window)
        before = v[steps <= start]
        if before.size == 0:
            return None
        best_before, best_now = float(before.max()), float(v.max())
        return (best_now - best_before) / max(abs(best_before), 1e-12)

    def plateaued(
        self, env_steps: list[int], values: list[float], budget: int | None = None
    ) -> bool:
        """True when :meth:`gain` is known and below ``min_gain``, and the run is past
        ``min_fraction`` of its ``budget`` env steps (None: no such floor)."""
        if budget is not None and env_steps and env_steps[-1] < self.min_fraction * budget:
            return False
        g = self.gain(env_steps, values)
        return g is not None and g < self.min_gain


def agent_curves(name: str, root: str | Path | None = None) -> list[dict[str, Any]]:
    """The learning curves of a shipped agent ``name`` (``root/<name>/seed_<k>/``, root:
    the shipped policies), each with its ``"seed"``; [] when it ships none."""
    from shipgym_baselines.learned.policy import POLICY_DIR

    agent = Path(root if root is not None else POLICY_DIR) / name
    found = []
    for folder in sorted(agent.glob("seed_*")):
        curve = load_curve(folder)
        suffix = folder.name.removeprefix("seed_")
        if curve is not None and suffix.isdigit():
            found.append({**curve, "seed": int(suffix)})
    return sorted(found, key=lambda c: c["seed"])
