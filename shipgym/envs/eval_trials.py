"""Batched evaluation env: given trials as rows, one episode each, the single env's info.

:class:`EvaluationTrialsVectorEnv` runs N episodes of one ship as the rows of one env (the
row machinery of :mod:`shipgym.envs.trial_rows`): row i is the episode of
``gym.make(ENV_ID, scenario=scenarios[i], action_mode=…, randomize=False)`` reset with
``seeds[i]``, bit for bit (observations, rewards, ends, ``info`` and ``episode_metrics``;
tested), with the plant of all rows stepped in one call of the compiled period function.
There is no autoreset: a finished row stays done (:attr:`finished`), its action is ignored
and it is not stepped.

``info`` holds ``"rows"``: per row the single env's ``info`` dict of that step (every key:
``t``, ``cross_track_error``, …, ``samples``; ``termination_reason`` and
``episode_metrics`` at the row's last step), None for a row not stepped; with
``row_infos="end"`` (a policy that reads observations only) a row's ``info`` only at its
last step, and :meth:`~EvaluationTrialsVectorEnv.trajectory` gives its episode's
trajectory columns.  Rows of one route share one batched path tracker
(:class:`~shipgym.envs.row_tracking.RouteGroups`).  The rows must
share the ship and its step constants (:func:`~shipgym.envs.trial_rows.shared_constants_problem`;
:func:`lockstep_problem` says why they do not).  Not registered with ``gym.make``; the
evaluation loop (``shipgym_baselines.evaluation.evaluate_batch``) builds it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, ClassVar

import numpy as np

from shipgym.angles import wrap_angle
from shipgym.envs import core
from shipgym.envs.context import ControllerContext
from shipgym.envs.row_tracking import RouteGroups
from shipgym.envs.trial_rows import Trial, TrialRowsVectorEnv, shared_constants_problem
from shipgym.errors import ShipgymError
from shipgym.metrics import compute_metrics
from shipgym.scenarios.loader import Scenario, load_scenario


class LockstepError(ShipgymError):
    """Trials that cannot be the rows of one env (different ships or step constants)."""


class RowInfosError(ShipgymError, ValueError):
    """An unknown ``row_infos`` choice, or one the ``samples`` setting contradicts."""


#: which steps give a row its ``info`` dict: every step, or its last step only
ROW_INFOS = ("all", "end")

#: the episode columns the env keeps per row and step (column 0: the reset): the
#: trajectory's and the metrics' (core.LOG_FIELDS) values
_COLUMNS = core.TRAJECTORY_KEYS + tuple(f for f in core.LOG_FIELDS if f not in core.TRAJECTORY_KEYS)
_TRAJECTORY = [_COLUMNS.index(name) for name in core.TRAJECTORY_KEYS]
_LOG = [_COLUMNS.index(name) for name in core.LOG_FIELDS]


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
        row_infos: str = "all",
        history_steps: int = 0,
    ) -> None:
        if row_infos not in ROW_INFOS:
            raise RowInfosError(f"row_infos must be one of {ROW_INFOS}, got {row_infos!r}")
        if row_infos == "end" and samples:
            raise RowInfosError(
                "row_infos='end' builds no per-step info, so no samples: pass samples=False"
            )
        #: whether the rows' infos carry ``samples`` (False: for a policy that reads only
        #: observations, e.g. a learned agent; the rest of each info is the same)
        self.record_samples = samples
        #: "all": each stepped row's info every step; "end": only at the row's last step
        #: (the trajectory is kept in arrays: :meth:`trajectory`)
        self.row_infos = row_infos
        self.scenarios = [load_scenario(s) for s in scenarios]
        self.seeds = [int(s) for s in seeds]
        if not self.scenarios or len(self.scenarios) != len(self.seeds):
            raise ValueError(
                f"{len(self.scenarios)} scenarios for {len(self.seeds)} seeds: give one per seed"
            )
        problem = lockstep_problem(self.scenarios)
        if problem is not None:
            raise LockstepError(f"these trials cannot run in one env: {problem}")
        super().__init__(
            len(self.seeds), self.scenarios[0], action_mode, compile, False, history_steps
        )
        n = self.num_envs
        #: rows whose episode has ended (they stay done)
        self.finished = np.ones(n, dtype=bool)
        #: the episode columns (_COLUMNS, row, step) [SI]: the reset and row i's steps[i]
        #: control steps
        self._columns = np.zeros((len(_COLUMNS), n, int(self._max_steps_of().max()) + 1))
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
        trackers = []
        for i, (sc, s) in enumerate(zip(self.scenarios, self.seeds, strict=True)):
            trial = Trial.of(sc, s, self.action_mode, False)
            self._install(i, trial)
            trackers.append(trial.tracker)
        k = self._k0
        x = self._state.x
        self._tracks = RouteGroups(trackers, x[:, k.ix], x[:, k.iy])
        self.finished[:] = False
        self._started = True
        self._reached_goal = np.zeros(self.num_envs, dtype=bool)
        every = np.arange(self.num_envs)
        self._write_columns(every, 0, self._tracks.frame.cross_track, None, None)
        infos: list[dict[str, Any] | None] = [None] * self.num_envs
        if self.row_infos == "all":
            infos = [self._row_info(i) for i in range(self.num_envs)]
        return self._observation(), {"rows": infos}

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if not self._started:
            raise RuntimeError("call reset() before step()")
        live = ~self.finished
        if live.all():
            a = core.batch_actions(actions, self.action_space.shape)
        else:
            a = np.zeros(self.action_space.shape)
            a[live] = core.batch_actions(np.asarray(actions)[live], (int(live.sum()), a.shape[1]))
        period = self._advance(a, live)
        # the period's ends are the stepped rows' (goal, corridor, time limit: of the rows
        # that advanced; a non-finite state: of a live row)
        terminated, truncated = period.terminated, period.truncated
        ended = terminated | truncated
        infos: list[dict[str, Any] | None] = [None] * self.num_envs
        rows = live.nonzero()[0]
        if rows.size:  # the live rows step together: one step count
            step = int(self._state.steps[rows[0]])
            frame = period.frame
            self._write_columns(rows, step, frame.cross_track, period.heading_error, period.reward)
        reasons = period.reasons() if ended.any() else None
        for i in (rows if self.row_infos == "all" else ended.nonzero()[0]).tolist():
            info = self._row_info(i)
            if i in self._samples:
                info["samples"] = self._samples[i]
            if ended[i]:
                self._reached_goal[i] = bool(period.goal[i])
                info["termination_reason"] = reasons[i]
                info["episode_metrics"] = self.episode_metrics(i)
            infos[i] = info
        self.finished |= ended
        return (
            self._observation(period.frame),
            period.reward,
            terminated,
            truncated,
            {"rows": infos},
        )

    def abandon(self, i: int, reason: str) -> dict[str, Any]:
        """End row i's episode now, for a cause outside the plant (e.g. its controller gave
        no usable action): the single env's ``abandon`` (one more control step logged with
        the plant not moved and the last rudder command, charged the corridor penalty from
        this step on).  Returns that step's row ``info`` with ``termination_reason`` =
        ``reason`` and ``episode_metrics``; the row is then finished."""
        if not self._started:
            raise RuntimeError("call reset() before abandon()")
        if self.finished[i]:
            raise ValueError(f"row {i} has finished: it cannot be abandoned")
        k, s = self._k0, self._state
        s.steps[i] += 1
        step = int(s.steps[i])
        s.t[i] = step * k.control_period
        frame = self._tracks.frame
        heading_error = wrap_angle(s.x[:, k.ipsi] - frame.path_angle)
        reward = np.zeros(self.num_envs)
        reward[i] = core.diverged_reward(step, self._trials[i].constants)
        self._write_columns(np.array([i]), step, frame.cross_track, heading_error, reward)
        self.finished[i] = True
        info = self._row_info(i)
        info["termination_reason"] = reason
        info["episode_metrics"] = self.episode_metrics(i)
        return info

    def _write_columns(
        self,
        rows: np.ndarray,
        step: int,
        cross_track: np.ndarray,
        heading_error: np.ndarray | None,
        reward: np.ndarray | None,
    ) -> None:
        """Column ``step`` (0: the reset) of the ``rows``' episode columns (_COLUMNS)."""
        k, s = self._k0, self._state
        whole = rows.size == self.num_envs  # every row: no gathers

        def take(values: np.ndarray) -> np.ndarray:
            return values if whole else values[rows]

        state = take(s.x)
        values = [
            take(s.t),
            state[:, k.ix],
            state[:, k.iy],
            take(cross_track),
            take(s.psi_m),
            state[:, k.idelta],
            take(s.delta_c),
        ]
        if heading_error is not None:
            values += [take(heading_error), take(reward)]
        self._columns[: len(values), slice(None) if whole else rows, step] = values

    def trajectory(self, i: int) -> dict[str, np.ndarray]:
        """Row i's trajectory so far: per key of ``core.TRAJECTORY_KEYS`` its values at the
        reset and each control step (the rows' ``info`` values, bit for bit)."""
        n = int(self._state.steps[i]) + 1
        return {
            name: self._columns[j, i, :n].copy()
            for name, j in zip(core.TRAJECTORY_KEYS, _TRAJECTORY, strict=True)
        }

    def _row_info(self, i: int) -> dict[str, Any]:
        k, s = self._k0, self._state
        x, y = float(s.x[i, k.ix]), float(s.x[i, k.iy])
        return core.info_values(
            float(s.t[i]),
            self._tracks.row_frame(i),
            float(s.psi_m[i]),
            float(s.r_m[i]),
            float(s.x[i, k.idelta]),
            float(s.delta_c[i]),
            (x, y),
        )

    def episode_metrics(self, i: int) -> dict[str, Any]:
        """Row i's episode metrics so far (the single env's ``episode_metrics()``)."""
        sc = self.scenarios[i]
        steps = int(self._state.steps[i])
        columns = {
            name: self._columns[j, i, 1 : steps + 1].copy()
            for name, j in zip(core.LOG_FIELDS, _LOG, strict=True)
        }
        log = core.episode_log(columns, sc, bool(self._reached_goal[i]))
        return compute_metrics(log, core.metric_settings(sc))
