"""A trained SB3 agent behind the common policy interface (``kind = "learned"``).

It sees exactly what the env's observation holds (measurements, no plant parameters, no
schedule) and acts deterministically.  Recurrent agents (RecurrentPPO) keep their LSTM
state within an episode and start afresh at every ``reset``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from baselines.errors import ControllerError
from baselines.learned.agents import algo_class
from baselines.policy import check_action_mode
from shipgym.envs.context import ControllerContext

POLICY_DIR = Path(__file__).resolve().parent / "policies"


def shipped_policies() -> list[str]:
    """Names of the pre-trained policies shipped in ``baselines/learned/policies``."""
    return sorted(p.name for p in POLICY_DIR.iterdir() if (p / "meta.json").is_file())


def resolve_policy(name_or_path: str | Path) -> tuple[Path, Path]:
    """A shipped policy name, a trained agent's directory or one of its ``.zip`` models
    (``best_model.zip``, a checkpoint) → (model zip, meta.json).  A directory means its
    ``model.zip`` (else ``best_model.zip``); ``meta.json`` is looked for beside the zip and
    one folder up (checkpoints)."""
    path = Path(name_or_path)
    if not path.exists() and (POLICY_DIR / str(name_or_path)).is_dir():
        path = POLICY_DIR / str(name_or_path)
    if path.is_dir():
        zip_path = path / "model.zip"
        if not zip_path.is_file():
            zip_path = path / "best_model.zip"
    else:
        zip_path = path
    meta = next(
        (
            d / "meta.json"
            for d in (zip_path.parent, zip_path.parent.parent)
            if (d / "meta.json").is_file()
        ),
        None,
    )
    if not zip_path.is_file() or meta is None:
        raise ControllerError(
            f"{name_or_path!r} is not a trained policy (a model zip with a meta.json); "
            f"shipped: {', '.join(shipped_policies())}; train one with `shipgym train AGENT`"
        )
    return zip_path, meta


class LearnedPolicy:
    """A trained agent from a policy directory or model zip (see :func:`resolve_policy`)."""

    kind = "learned"

    def __init__(self, path: str | Path, name: str | None = None) -> None:
        zip_path, meta = resolve_policy(path)
        self.model_path = zip_path
        self.meta: dict[str, Any] = json.loads(meta.read_text())
        self.name = name or self.meta["name"]
        self.action_mode: str = self.meta["action_mode"]
        import torch

        torch.set_num_threads(1)  # one small MLP per episode; leaderboard workers share cores
        self.model = algo_class(self.meta["algo"]).load(str(zip_path), device="cpu")
        self.recurrent = self.meta["algo"] == "recurrent_ppo"
        self._state: Any = None
        self._start = True

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        check_action_mode(self, context)
        self._state = None
        self._start = True

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        if self.recurrent:
            action, self._state = self.model.predict(
                obs, state=self._state, episode_start=np.array([self._start]), deterministic=True
            )
            self._start = False
            return action
        action, _ = self.model.predict(obs, deterministic=True)
        return action

    def episode_stats(self) -> dict[str, float]:
        """Training cost, reported beside the metrics on the leaderboard."""
        return {
            "train_env_steps": float(self.meta["env_steps"]),
            "train_wall_s": float(self.meta["wall_time_s"]),
        }
