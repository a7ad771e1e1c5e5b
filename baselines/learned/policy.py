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

from baselines.learned.agents import algo_class
from shipgym.envs.context import ControllerContext

POLICY_DIR = Path(__file__).resolve().parent / "policies"


def shipped_policies() -> list[str]:
    """Names of the pre-trained policies shipped in ``baselines/learned/policies``."""
    return sorted(p.name for p in POLICY_DIR.iterdir() if (p / "meta.json").is_file())


def resolve_policy_dir(name_or_path: str | Path) -> Path:
    """A shipped policy name or a directory / zip path → the policy directory."""
    path = Path(name_or_path)
    if path.suffix == ".zip":
        path = path.parent
    if not path.is_dir():
        path = POLICY_DIR / str(name_or_path)
    if not (path / "meta.json").is_file():
        raise ValueError(
            f"{name_or_path!r} is not a trained policy (no meta.json); shipped: "
            f"{', '.join(shipped_policies())}; train one with `shipgym train AGENT`"
        )
    return path


class LearnedPolicy:
    """Loads ``model.zip`` (or ``best_model.zip``) and ``meta.json`` from a policy directory."""

    kind = "learned"

    def __init__(self, path: str | Path, name: str | None = None) -> None:
        self.directory = resolve_policy_dir(path)
        self.meta: dict[str, Any] = json.loads((self.directory / "meta.json").read_text())
        self.name = name or self.meta["name"]
        self.action_mode: str = self.meta["action_mode"]
        zip_path = self.directory / "model.zip"
        if not zip_path.is_file():
            zip_path = self.directory / "best_model.zip"
        import torch

        torch.set_num_threads(1)  # one small MLP per episode; leaderboard workers share cores
        self.model = algo_class(self.meta["algo"]).load(str(zip_path), device="cpu")
        self.recurrent = self.meta["algo"] == "recurrent_ppo"
        self._state: Any = None
        self._start = True

    def reset(self, context: ControllerContext, seed: int | None = None) -> None:
        if context.action_mode != self.action_mode:
            raise ValueError(
                f"policy {self.name!r} was trained for action_mode {self.action_mode!r}, "
                f"the env uses {context.action_mode!r}"
            )
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
