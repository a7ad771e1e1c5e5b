"""Batched evaluation env: given trials as rows, one episode each, the single env's info.

:class:`EvaluationTrialsVectorEnv` runs N episodes of one ship as the rows of one env (the
row machinery of :mod:`shipgym.envs.trial_rows`): row i is the episode of
``gym.make(ENV_ID, scenario=scenarios[i], action_mode=…)`` reset with ``seeds[i]``, bit for
bit (observations, rewards, ends, ``info`` and ``episode_metrics``; tested), with the plant
of all rows stepped in one call of the compiled period function.  There is no autoreset: a
finished row stays done (:attr:`finished`), its action is ignored and it is not stepped.

``info`` holds ``"rows"``: per row the single env's ``info`` dict of that step (every key:
``t``, ``cross_track_error``, …, ``samples``; ``termination_reason`` and
``episode_metrics`` at the row's last step), None for a row not stepped.  The rows must
share the ship and its step constants (:func:`~shipgym.envs.trial_rows.shared_constants_problem`;
:func:`lockstep_problem` says why they do not).  Not registered with ``gym.make``; the
evaluation loop (``shipgym_baselines.evaluation.evaluate_batch``) builds it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, ClassVar

import numpy as np

from shipgym.envs import core
from shipgym.envs.context import ControllerContext
from shipgym.envs.trial_rows import Trial, TrialRowsVectorEnv, shared_constants_problem
from shipgym.errors import ShipgymError
from shipgym.metrics import compute_metrics
from shipgym.scenarios import Scenario, load_scenario


class LockstepError(ShipgymError):
    """Trials that cannot be the rows of one env (different ships or step constants)."""


def lockstep_problem(scenarios: Sequence[Scenario]) -> str | None:
    """Why ``scenarios`` cannot run as the rows of one env (None: they can)."""
    for i, sc in enumerate(scenarios[1:], start=1):
        problem = shared_constants_problem(scenarios[0], sc)
        if problem is not None:
            return f"trial {i} ({sc.name!r}): {problem}"
    return None


class EvaluationTrialsVectorEnv(TrialRowsVectorEnv):
    """One episode per given trial, in lockstep (module doc)."""

    metadata: ClassVar[dict[str, Any]] = {"render_modes": []}
    record_samples = True

    def __init__(
        self,
        scenarios: Sequence[Any],
        seeds: Sequence[int],
        action_mode: str = "rudder",
        compile: bool = True,
        samples: bool = True,
    ) -> None:
        #: whether the rows' infos carry ``samples`` (False: for a policy that reads only
        #: observations, e.g. a learned agent; the rest of each info is the same)
        self.record_samples = samples
        self.scenarios = [load_scenario(s) for s in scenarios]
        self.seeds = [int(s) for s in seeds]
        if not self.scenarios or len(self.scenarios) != len(self.seeds):
            raise ValueError(
                f"{len(self.scenarios)} scenarios for {len(self.seeds)} seeds: give one per seed"
            )
        problem = lockstep_problem(self.scenarios)
        if problem is not None:
            raise LockstepError(f"these trials cannot run in one env: {problem}")
        # one thread: the least CPU (the leaderboard's workers already fill the cores)
        super().__init__(len(self.seeds), self.scenarios[0], action_mode, compile, False, 1)
        n = self.num_envs
        #: rows whose episode has ended (they stay done)
        self.finished = np.ones(n, dtype=bool)
        #: the episode logs: (LOG_FIELDS, row, step) [SI], row i's first steps[i] columns
        self._log = np.zeros((len(core.LOG_FIELDS), n, int(self._max_steps_of().max())))
        self._started = False

    def _max_steps_of(self) -> np.ndarray:
        """Each row's time limit in control periods."""
        return np.array([core.StepConstants.of(sc).max_steps for sc in self.scenarios])

    def controller_context(self, i: int) -> ControllerContext:
        """What row i's controller may know (as the single env's ``controller_context``)."""
        return ControllerContext.of(self.scenarios[i], self.action_mode)

    def reset(
        self, *, seed: Any = None, options: dict | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start every row's episode (the seeds are the constructor's: ``seed`` must be None)."""
        if seed is not None:
            raise ValueError("the rows' seeds are given at construction; reset takes none")
        for i, (sc, s) in enumerate(zip(self.scenarios, self.seeds, strict=True)):
            self._install(i, Trial.of(sc, s, self.action_mode, False))
        self.finished[:] = False
        self._started = True
        self._reached_goal = np.zeros(self.num_envs, dtype=bool)
        frames = self._frames
        infos = [self._row_info(i, frames[i]) for i in range(self.num_envs)]
        return self._observation(), {"rows": infos}

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if not self._started:
            raise RuntimeError("call reset() before step()")
        live = ~self.finished
        a = np.zeros(self.action_space.shape)
        a[live] = core.batch_actions(np.asarray(actions)[live], (int(live.sum()), a.shape[1]))
        period = self._advance(a, live)
        terminated, truncated = period.terminated & live, period.truncated & live
        reasons = period.reasons()
        k = self._k0
        infos: list[dict[str, Any] | None] = [None] * self.num_envs
        x_col, y_col = self._state[:, k.ix], self._state[:, k.iy]
        rows = np.flatnonzero(live)
        self._log[:, rows, self._steps[rows] - 1] = (
            self._t[rows],
            period.frame.cross_track[rows],
            period.heading_error[rows],
            self._state[rows, k.idelta],
            self._delta_c[rows],
            period.reward[rows],
        )
        for i in rows.tolist():
            frame = self._frames[i]
            info = self._row_info(i, frame, float(x_col[i]), float(y_col[i]))
            if i in period.samples:
                info["samples"] = period.samples[i]
            if reasons[i] is not None:
                self._reached_goal[i] = bool(period.goal[i])
                info["termination_reason"] = reasons[i]
                info["episode_metrics"] = self.episode_metrics(i)
            infos[i] = info
        self.finished |= terminated | truncated
        return (
            self._observation(period.frame),
            period.reward,
            terminated,
            truncated,
            {"rows": infos},
        )

    def _row_info(
        self, i: int, frame: Any, x: float | None = None, y: float | None = None
    ) -> dict[str, Any]:
        k = self._k0
        if x is None:
            x, y = float(self._state[i, k.ix]), float(self._state[i, k.iy])
        return core.info_values(
            float(self._t[i]),
            frame,
            float(self._psi_m[i]),
            float(self._r_m[i]),
            float(self._state[i, k.idelta]),
            float(self._delta_c[i]),
            (x, y),
        )

    def episode_metrics(self, i: int) -> dict[str, Any]:
        """Row i's episode metrics so far (the single env's ``episode_metrics()``)."""
        sc = self.scenarios[i]
        steps = int(self._steps[i])
        columns = {name: self._log[j, i, :steps].copy() for j, name in enumerate(core.LOG_FIELDS)}
        log = core.episode_log(columns, sc, bool(self._reached_goal[i]))
        return compute_metrics(log, core.metric_settings(sc))
