"""Re-record ``shipped_policy_actions.npz`` (tests/golden/README.md) after the shipped agents
change on purpose: every shipped agent's and training seed's actions on the file's fixed
observations, recorded through SB3's own loader (``Algorithm.load``, the pickle path), so
that ``test_safe_loading.py`` keeps checking the data-only loader against it.

``observations`` (80 × 9) are kept from the file as they are.  ``observations_context``
(80 × (9 + context features)) are the same observations with a ship's controller-context
row appended (the four catalogue ships in turn: nomoto2, esso_osaka, mariner, blanke): what
an agent trained with ``context_features`` reads.  ``observations_history_K`` (80 ×
(9 + context features + 7 K)) append K control steps of history to those: step k of row i
holds row i − k's history entries (its measurements and last rudder command; rows before
the first wrap round), what an agent trained with
``history_steps`` K reads.  Run from the checkout::

    python tests/golden/record_policy_actions.py          # record the agents not in the file
    python tests/golden/record_policy_actions.py --all    # record every agent again
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from shipgym.envs.context import ControllerContext
from shipgym.envs.core import HISTORY_MEASUREMENTS, OBS_NAMES
from shipgym.scenarios.loader import load_scenario

GOLDEN = Path(__file__).resolve().parent / "shipped_policy_actions.npz"
#: one scenario per catalogue ship, whose context rows the wide observations carry
CONTEXT_SCENARIOS = ("nominal", "esso_osaka_nominal", "mariner_nominal", "blanke_nominal")


def context_observations(observations: np.ndarray) -> np.ndarray:
    """``observations`` with the ships' context rows appended in turn (float32)."""
    rows = [
        ControllerContext.of(load_scenario(name), "rudder").feature_row
        for name in CONTEXT_SCENARIOS
    ]
    wide = [np.concatenate([obs, rows[i % len(rows)]]) for i, obs in enumerate(observations)]
    return np.asarray(wide, dtype=np.float32)


def history_observations(observations: np.ndarray, steps: int) -> np.ndarray:
    """``context_observations(observations)`` with ``steps`` control steps of history appended
    (module doc; float32)."""
    columns = [OBS_NAMES.index(name) for name in HISTORY_MEASUREMENTS]
    columns.append(OBS_NAMES.index("last_rudder_command"))
    entries = observations[:, columns]
    rows = len(observations)
    window = [
        np.concatenate([entries[(i - k) % rows] for k in range(1, steps + 1)]) for i in range(rows)
    ]
    return np.concatenate([context_observations(observations), window], axis=1).astype(np.float32)


def record() -> dict[str, np.ndarray]:
    """The golden arrays: the observations and each shipped agent's actions (pickle loader)."""
    import torch

    from shipgym_baselines.errors import UnsafeFileError
    from shipgym_baselines.learned import policy as policy_module
    from shipgym_baselines.learned.policy import POLICY_DIR, LearnedPolicy
    from shipgym_baselines.learned.trust import trusting_pickle

    torch.set_num_threads(1)
    observations = np.load(GOLDEN, allow_pickle=False)["observations"]
    out = {"observations": observations, "observations_context": context_observations(observations)}

    def refuse(*args, **kwargs):  # force SB3's Algorithm.load
        raise UnsafeFileError("recording through the pickle loader")

    original = policy_module.load_data_only
    policy_module.load_data_only = refuse
    try:
        with trusting_pickle(True):
            for agent in sorted(p for p in POLICY_DIR.iterdir() if p.is_dir()):
                for seed_dir in sorted(agent.glob("seed_*")):
                    seed = int(seed_dir.name.removeprefix("seed_"))
                    policy = LearnedPolicy(agent.name, training_seed=seed)
                    key = observations_key(policy.context_features, policy.history_steps)
                    obs = out.get(key)
                    if obs is None:
                        obs = out[key] = history_observations(observations, policy.history_steps)
                    actions = np.array([policy.act(o, {}) for o in obs])
                    out[f"{agent.name}__seed_{seed}"] = actions
    finally:
        policy_module.load_data_only = original
    return out


def observations_key(context_features: bool, history_steps: int) -> str:
    """The file's key of the observations an agent with these inputs reads."""
    if history_steps:
        if not context_features:
            raise ValueError("the golden's history observations carry the context features")
        return f"observations_history_{history_steps}"
    return "observations_context" if context_features else "observations"


if __name__ == "__main__":
    import sys

    arrays = record()
    if "--all" not in sys.argv[1:]:  # the recorded agents' arrays kept byte for byte
        with np.load(GOLDEN, allow_pickle=False) as old:
            arrays.update({key: old[key] for key in old.files})
    np.savez(GOLDEN, **arrays)
    print(f"{GOLDEN}: {sorted(arrays)}")
