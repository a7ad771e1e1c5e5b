"""The one evaluation loop: any policy, any scenario, a list of seeds.

:func:`run_episode` runs one episode; :func:`evaluate_batch` runs several in lockstep, as
the rows of one :class:`~shipgym.envs.eval_trials.EvaluationTrialsVectorEnv` (a learned
policy with one network forward per step for all), with the same bits.  Given an
:class:`ActGuard` (the leaderboard, ``evaluate`` and ``run`` give one), a controller that
fails ends its episode as a result, not the run.  Given an :class:`EpisodeLabel` (the
leaderboard's job gives one), each episode's result is made under it: the scenario's table
name, the controller's display name and the training seed.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import json
import math
import os
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import Any, NamedTuple, Protocol, runtime_checkable

import gymnasium as gym
import numpy as np

import shipgym  # noqa: F401  (registers the envs)
from shipgym.envs.core import TRAJECTORY_KEYS, check_action
from shipgym.envs.eval_trials import EvaluationTrialsVectorEnv, lockstep_problem
from shipgym.scenarios import Scenario, load_scenario
from shipgym.scenarios.trials import seed_trials
from shipgym_baselines.errors import ControllerError, RunError
from shipgym_baselines.plugins import ControllerEntry, ControllerSpec
from shipgym_baselines.policy import Policy
from shipgym_baselines.privileged import grants_truth, reset_with_truth
from shipgym_baselines.records.episodes import (
    CONTROLLER_ERROR,
    CONTROLLER_TIMEOUT,
    EpisodeLabel,
    EpisodeResult,
)
from shipgym_baselines.registry import make_controller

ENV_ID = "ShipPathFollow-v0"
#: evaluation seeds start here, apart from the training seeds (0, 1, …) of learned agents
EVAL_SEED_OFFSET = 10_000

#: the clock [s] that times each ``act`` call (``compute_ms``): wall time, unless
#: :func:`act_clock` swaps it (the run-cost profile reads CPU time)
_clock: Callable[[], float] = time.perf_counter


#: the default limit [s] on the wall time of one controller call (``--act-timeout``)
ACT_TIMEOUT_S = 10.0
#: the most characters of an episode's ``error`` (the one-line message of its failure)
ERROR_CHARS = 300


@dataclasses.dataclass(frozen=True)
class ActGuard:
    """A failing controller ends its episode, not the run.

    With a guard the loop ends an episode whose controller's ``reset`` or ``act`` raises,
    or gives an action that is not numbers of the action's shape or holds NaN or inf
    (``termination_reason`` ``"controller_error"``), or whose ``act`` took longer than
    ``timeout`` [s] of wall time (``"controller_timeout"``; ``reset`` has no limit: it may
    build a solver, compiled to C once per machine); the env's ``abandon`` charges it as
    leaving the corridor at that step, and the metric ``error`` says why in one line.
    Without a guard (None) such an error propagates, as a debugger wants it.

    The time limit is checked when the call returns, not by stopping it: a Python call
    cannot be stopped safely from outside in its own process (an exception sent by a
    signal lands in whatever code runs, perhaps a library holding a lock, and does not
    interrupt C code), and a worker process per controller would cost a round trip and
    a pickled observation per step, and would leave a controller's state out of reach.
    So a slow controller holds a run for at most one slow call per episode; a call that
    never returns holds it until the run is stopped (Ctrl-C; ``--resume`` runs that
    episode again).  A batch policy's ``act_batch`` acts for all live episodes: the
    whole call counts against the limit.
    """

    timeout: float = ACT_TIMEOUT_S

    def __post_init__(self) -> None:
        if not self.timeout > 0.0:  # NaN too
            raise RunError(f"--act-timeout must be a positive time in s, got {self.timeout}")


class _Failure(NamedTuple):
    """Why a controller's episode ended early: the termination reason and one line."""

    reason: str
    error: str


def error_line(exc: BaseException) -> str:
    """``Type: message`` of ``exc`` as one printable line of at most :data:`ERROR_CHARS`."""
    text = "".join(c if c.isprintable() else " " for c in f"{type(exc).__name__}: {exc}")
    text = " ".join(text.split())
    return text if len(text) <= ERROR_CHARS else text[: ERROR_CHARS - 1] + "…"


def _call(
    guard: ActGuard | None, call: Callable[[], Any], timed: bool = True
) -> tuple[Any, float, _Failure | None]:
    """``call()`` (a controller's), its time on the act clock [s] and, with a guard, why
    the controller failed (None: it did not; :class:`ActGuard`); ``timed``: held to the
    guard's time limit (an act, not a reset)."""
    start = _clock()
    if guard is None:
        value = call()
        return value, _clock() - start, None
    wall = time.perf_counter()
    try:
        value = call()
    except Exception as exc:  # the controller's, whatever it is: the episode's result
        return None, _clock() - start, _Failure(CONTROLLER_ERROR, error_line(exc))
    took, wall = _clock() - start, time.perf_counter() - wall
    if timed and wall > guard.timeout:
        slow = f"the call took {wall:.3g} s, over the limit of {guard.timeout:g} s"
        return value, took, _Failure(CONTROLLER_TIMEOUT, slow)
    return value, took, None


def _checked(action: Any, shape: tuple[int, ...]) -> tuple[Any, _Failure | None]:
    """``action`` as :func:`~shipgym.envs.core.check_action` gives it, or the failure of
    a controller that gave it (not numbers of ``shape``, or NaN or inf)."""
    try:
        return check_action(action, shape), None
    except ValueError as exc:
        return None, _Failure(CONTROLLER_ERROR, error_line(exc))


def _act(
    guard: ActGuard | None, act: Callable[[], Any], shape: tuple[int, ...]
) -> tuple[Any, float, _Failure | None]:
    """:func:`_call` of a controller's ``act``, its action checked when guarded
    (:func:`_checked`)."""
    action, took, failure = _call(guard, act)
    if guard is not None and failure is None:
        action, failure = _checked(action, shape)
    return action, took, failure


@contextlib.contextmanager
def act_clock(clock: Callable[[], float]) -> Iterator[None]:
    """Time the ``act`` calls with ``clock`` [s] (e.g. :func:`time.process_time`) inside."""
    global _clock
    saved, _clock = _clock, clock
    try:
        yield
    finally:
        _clock = saved


class _Record:
    """One episode's record as the loop keeps it: the time each ``act`` took, the last
    info and (``rows``) the trajectory rows of its infos; without rows (the rows of an
    evaluation env, which keeps the trajectory itself) :meth:`result` is given the
    trajectory, and ``info`` may be None at the steps a lean env gives none."""

    def __init__(
        self, scenario_name: str, seed: int, info: dict[str, Any] | None, rows: bool = True
    ) -> None:
        self.scenario_name = scenario_name
        self.seed = seed
        self.info = info
        self.rows: list[tuple[float, ...]] | None = [_traj_row(info)] if rows else None
        self.act_times: list[float] = []
        #: why the controller failed, if it did (:class:`ActGuard`)
        self.failure: _Failure | None = None

    def add(self, info: dict[str, Any] | None, act_time: float | None) -> None:
        """The info (None: none this step) of a step whose action took ``act_time`` [s]
        (None: no ``act`` call, its ``reset`` failed)."""
        if act_time is not None:
            self.act_times.append(act_time)
        if info is not None:
            self.info = info
            if self.rows is not None:
                self.rows.append(_traj_row(info))

    def result(
        self,
        policy: Policy,
        trajectory: dict[str, np.ndarray] | None = None,
        label: EpisodeLabel | None = None,
    ) -> EpisodeResult:
        """The episode's result; ``trajectory``: a record without rows (the env's);
        ``label``: its scenario, controller and training seed (None: the trial's name, the
        policy's name and its training seed)."""
        metrics = dict(self.info["episode_metrics"])
        metrics["termination_reason"] = self.info.get("termination_reason")
        if self.failure is not None:
            metrics["error"] = self.failure.error
        metrics.update(compute_time_metrics(self.act_times))
        stats = getattr(policy, "episode_stats", None)
        if stats is not None:  # controller-specific figures (e.g. NMPC solver failures)
            try:
                metrics.update(stats())
            except Exception:
                if self.failure is None:
                    raise  # a failed controller's figures may fail too: left out
        if trajectory is None:
            traj = np.array(self.rows)
            trajectory = {k: traj[:, i] for i, k in enumerate(_TRAJ_KEYS)}
        if label is None:
            label = EpisodeLabel(self.scenario_name, policy.name)
        trained = label.training_seed
        return EpisodeResult(
            controller=label.controller,
            kind=policy.kind,
            scenario=label.scenario,
            seed=self.seed,
            metrics=metrics,
            trajectory=trajectory,
            training_seed=training_seed(policy) if trained is None else trained,
        )


class _Episode:
    """One env's episode as the evaluation loop runs it: made and reset with ``seed``, then
    stepped with the policy's actions and the time each took, then its result."""

    def __init__(self, env_id: str, scenario: Any, seed: int, action_mode: str) -> None:
        self.env = gym.make(env_id, scenario=scenario, action_mode=action_mode)
        self.seed = seed
        try:
            self.obs, info = self.env.reset(seed=seed)
        except BaseException:
            self.env.close()
            raise
        self.base = self.env.unwrapped
        self.record = _Record(self.base.scenario.name, seed, info)
        self.done = False

    @property
    def info(self) -> dict[str, Any]:
        return self.record.info

    def step(self, action: np.ndarray, act_time: float) -> None:
        """Step with ``action``, which took the policy ``act_time`` [s]."""
        self.obs, _reward, terminated, truncated, info = self.env.step(action)
        self.record.add(info, act_time)
        self.done = terminated or truncated

    def abandon(self, failure: _Failure, act_time: float | None) -> None:
        """End the episode now: its controller failed (in a call of ``act_time`` [s])."""
        self.record.add(self.base.abandon(failure.reason), act_time)
        self.record.failure = failure
        self.done = True

    def result(self, policy: Policy, label: EpisodeLabel | None = None) -> EpisodeResult:
        return self.record.result(policy, label=label)


def run_episode(
    policy: Policy,
    scenario: Any,
    seed: int,
    action_mode: str | None = None,
    env_id: str = ENV_ID,
    after_episode: Callable[[Any], None] | None = None,
    privileged: bool = False,
    guard: ActGuard | None = None,
    label: EpisodeLabel | None = None,
) -> EpisodeResult:
    """Run one episode; the policy sees only obs, info and the controller context.

    ``action_mode``: the env's (None: the policy's ``action_mode``, else "rudder").
    ``after_episode``: called with the unwrapped env after the last step, before it is
    closed, to read the env's own episode logs (e.g. ``episode_disturbances()``).
    Controller compute time is measured here, around each ``act`` call, never by the env:
    ``compute_ms`` [ms] is its mean per step and ``compute_ms_max`` [ms] its maximum.
    ``privileged``: set by :func:`evaluate` / :func:`evaluate_batch` for the built-in
    references ``oracle`` and ``oracle_frozen`` only (:mod:`shipgym_baselines.privileged`):
    they then read the true plant.  ``guard``: a failing controller ends the episode
    (:class:`ActGuard`); None: its error propagates.  ``label``: the result's scenario,
    controller and training seed (:class:`EpisodeLabel`; None: the scenario's name, the
    policy's name and its training seed).
    """
    if action_mode is None:
        action_mode = getattr(policy, "action_mode", "rudder")
    episode = _Episode(env_id, scenario, seed, action_mode)
    try:
        base, shape = episode.base, episode.env.action_space.shape
        context = base.controller_context
        if privileged:
            reset = functools.partial(reset_with_truth, policy, context, base, seed)
        else:
            reset = functools.partial(policy.reset, context, seed=seed)
        _, _, failure = _call(guard, reset, timed=False)
        took: float | None = None  # no act call yet
        while failure is None and not episode.done:
            action, took, failure = _act(
                guard, lambda: policy.act(episode.obs, episode.info), shape
            )
            if failure is None:
                episode.step(action, took)
        if failure is not None:
            episode.abandon(failure, took)
        result = episode.result(policy, label)
        if after_episode is not None:
            after_episode(episode.base)
        return result
    finally:
        episode.env.close()


@runtime_checkable
class BatchPolicy(Policy, Protocol):
    """A policy that acts for several episodes in lockstep (a learned policy: one network
    forward for all), each action the one ``act`` would give in that episode alone.  It
    reads the observations only (``act_batch`` gets no info), so its episodes' rows are
    stepped without ``samples``."""

    def reset_batch(self, contexts: Sequence[Any]) -> None: ...

    def act_batch(self, obs: np.ndarray, episodes: Sequence[int]) -> np.ndarray: ...


def evaluate_batch(
    controller: ControllerSpec | Policy,
    scenarios: Any,
    seeds: Sequence[int],
    training_seed: int | None = None,
    action_mode: str | None = None,
    env_id: str = ENV_ID,
    guard: ActGuard | None = None,
    label: EpisodeLabel | None = None,
    training_seeds: Sequence[int | None] | None = None,
) -> list[EpisodeResult]:
    """The episodes of ``seeds``, the i-th on ``scenarios[i]`` (a list, one scenario per
    seed: e.g. each seed's trial variant) or all on one scenario; equal, bit for bit, to
    :func:`run_episode` one by one (compute times aside).

    ``training_seeds`` (one per seed; a learned agent given by name): the i-th episode is
    played by the agent trained with ``training_seeds[i]``, all in lockstep
    (:class:`DealtPolicy`), each labelled with its own training seed.

    ``controller``: a name, spec or long form (made with ``training_seed``, one of
    :func:`~shipgym_baselines.registry.training_seeds`; None: a learned policy's first) or a Policy
    instance.  The episodes run in lockstep, as the rows of one
    :class:`~shipgym.envs.eval_trials.EvaluationTrialsVectorEnv` (one plant call per step
    for all), when the trials share the ship and its step constants (else one env per
    episode, still in lockstep):

    * a :class:`BatchPolicy` (learned policies) acts with one ``act_batch`` for the live
      episodes per step; its ``compute_ms`` / ``compute_ms_max`` [ms] are the mean and
      maximum over an episode's steps of that call's time divided by the number of
      episodes it acted for;
    * a controller given by name or spec is made afresh per episode (as :func:`evaluate`
      does) and each instance's ``act`` is timed on its own.

    One by one (:func:`run_episode`) run the privileged references (they read their env's
    truth) and a non-batch Policy *instance* (one instance cannot act for several
    episodes at once).  ``guard``: a failing controller ends its episodes
    (:class:`ActGuard`); None: its error propagates.  ``label``: every episode's scenario,
    controller and training seed (:class:`EpisodeLabel`; None: as :func:`run_episode`).
    """
    seeds = list(seeds)
    per_seed = list(scenarios) if isinstance(scenarios, list | tuple) else [scenarios] * len(seeds)
    if len(per_seed) != len(seeds):
        raise ValueError(f"{len(per_seed)} scenarios for {len(seeds)} seeds: give one per seed")
    made = isinstance(controller, str | ControllerEntry)
    if training_seeds is not None:
        return _evaluate_dealt(
            controller, per_seed, seeds, training_seeds, action_mode, env_id, guard, label
        )
    if made:
        policy, mode = make_controller(controller, training_seed=training_seed)
    elif training_seed is not None:
        raise ControllerError(
            f"training_seed={training_seed}: a Policy instance is one trained agent; give the "
            "controller by name to choose its training seed"
        )
    else:
        policy, mode = controller, None
    mode = action_mode or mode or getattr(policy, "action_mode", "rudder")
    if isinstance(policy, BatchPolicy):
        # a batch policy acts on the observations alone: its rows skip the per-step infos
        episodes = _episodes(per_seed, seeds, mode, env_id, lean=True)
        return _run_lockstep(policy, episodes, guard, label)
    privileged = made and grants_truth(controller)
    if made and not privileged and seeds:
        policies = [policy] + [
            make_controller(controller, training_seed=training_seed)[0] for _ in seeds[1:]
        ]
        return _run_lockstep(policies, _episodes(per_seed, seeds, mode, env_id), guard, label)
    results = []
    for i, (scenario, seed) in enumerate(zip(per_seed, seeds, strict=True)):
        if made and i > 0:
            policy, _ = make_controller(controller, training_seed=training_seed)
        result = run_episode(
            policy, scenario, seed, mode, env_id, privileged=privileged, guard=guard, label=label
        )
        results.append(result)
    return results


class DealtPolicy:
    """Several trained agents of one learned controller acting in lockstep, each for its own
    episodes: ``policies`` maps a training seed to its :class:`BatchPolicy`, ``owners`` the
    training seed of each episode of :meth:`reset_batch`.  Each agent acts for its episodes
    with one ``act_batch``: the actions it would give them alone, bit for bit (a learned
    policy's rows do not depend on the other rows of its batch)."""

    def __init__(self, policies: Mapping[int | None, BatchPolicy], owners: Sequence[int | None]):
        missing = sorted({k for k in owners if k not in policies}, key=str)
        if missing:
            raise ValueError(f"no policy for training seeds {missing}")
        first = next(iter(policies.values()))
        self.policies = dict(policies)
        self.owners = list(owners)
        self.name, self.kind = first.name, first.kind
        self.action_mode = getattr(first, "action_mode", "rudder")
        #: episode → its position among its owner's episodes
        self._local = [self.owners[:i].count(k) for i, k in enumerate(self.owners)]

    def reset(self, context: Any, seed: int | None = None) -> None:
        raise TypeError("a DealtPolicy acts for several episodes: use reset_batch")

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        raise TypeError("a DealtPolicy acts for several episodes: use act_batch")

    def reset_batch(self, contexts: Sequence[Any]) -> None:
        for k, policy in self.policies.items():
            policy.reset_batch(
                [c for c, owner in zip(contexts, self.owners, strict=True) if owner == k]
            )

    def act_batch(self, obs: np.ndarray, episodes: Sequence[int]) -> np.ndarray:
        out: np.ndarray | None = None
        for k, policy in self.policies.items():
            rows = [j for j, i in enumerate(episodes) if self.owners[i] == k]
            if not rows:
                continue
            actions = np.asarray(
                policy.act_batch(obs[rows], [self._local[episodes[j]] for j in rows])
            )
            if out is None:
                out = np.empty((len(episodes), *actions.shape[1:]), dtype=actions.dtype)
            out[rows] = actions
        assert out is not None  # episodes is never empty
        return out


def _evaluate_dealt(
    controller: ControllerSpec | Policy,
    scenarios: list[Any],
    seeds: list[int],
    training_seeds: Sequence[int | None],
    action_mode: str | None,
    env_id: str,
    guard: ActGuard | None,
    label: EpisodeLabel | None,
) -> list[EpisodeResult]:
    """:func:`evaluate_batch` of a learned agent's training seeds sharing ``seeds``."""
    owners = list(training_seeds)
    if len(owners) != len(seeds):
        raise ValueError(f"{len(owners)} training seeds for {len(seeds)} seeds: give one per seed")
    if not isinstance(controller, str | ControllerEntry):
        raise ControllerError("training_seeds: give the learned controller by name, not a Policy")
    made = {k: make_controller(controller, training_seed=k) for k in dict.fromkeys(owners)}
    if not all(isinstance(policy, BatchPolicy) for policy, _ in made.values()):
        raise ControllerError(f"training_seeds: {controller!r} is not a learned agent")
    policy = DealtPolicy({k: p for k, (p, _) in made.items()}, owners)
    mode = action_mode or next(iter(made.values()))[1] or policy.action_mode
    episodes = _episodes(scenarios, seeds, mode, env_id, lean=True)
    if label is not None:
        labels = [label._replace(training_seed=k) for k in owners]
    else:  # as the loop labels an episode: its scenario's name and the policy's
        loaded = [load_scenario(sc) if isinstance(sc, str) else sc for sc in scenarios]
        labels = [
            EpisodeLabel(sc.name, policy.name, k) for sc, k in zip(loaded, owners, strict=True)
        ]
    return _run_lockstep(policy, episodes, guard, labels)


class _Episodes(Protocol):
    """The episodes of a lockstep run: per episode its observation, info, end and result."""

    seeds: list[int]
    obs: Sequence[np.ndarray]
    done: list[bool]
    #: one episode's action shape
    shape: tuple[int, ...]

    def info(self, i: int) -> dict[str, Any]: ...

    def stacked_obs(self, live: list[int]) -> np.ndarray: ...

    def contexts(self) -> list[Any]: ...

    def step(
        self, live: list[int], actions: Sequence[np.ndarray] | np.ndarray, times: list[float]
    ) -> None: ...

    def abandon(self, i: int, failure: _Failure, act_time: float | None) -> None: ...

    def result(self, i: int, policy: Policy, label: EpisodeLabel | None) -> EpisodeResult: ...

    def close(self) -> None: ...


class _VectorEpisodes:
    """The episodes as the rows of one :class:`EvaluationTrialsVectorEnv`, the
    trajectories the env's columns; ``lean`` (a batch policy, which reads observations
    only): the rows give no per-step info (``row_infos="end"``, no samples)."""

    def __init__(
        self, scenarios: list[Scenario], seeds: list[int], action_mode: str, lean: bool = False
    ) -> None:
        self.lean = lean
        self.env = EvaluationTrialsVectorEnv(
            scenarios,
            seeds,
            action_mode,
            samples=not lean,
            row_infos="end" if lean else "all",
        )
        self.seeds = seeds
        #: the rows' latest observations (n_rows, n_obs): a finished row's is its last
        self.obs, info = self.env.reset()
        self.records = [
            _Record(sc.name, seed, row, rows=False)
            for sc, seed, row in zip(self.env.scenarios, seeds, info["rows"], strict=True)
        ]
        self.done = [False] * len(seeds)
        self._actions = np.zeros(self.env.action_space.shape)
        self.shape = self.env.single_action_space.shape

    def info(self, i: int) -> dict[str, Any]:
        return self.records[i].info

    def contexts(self) -> list[Any]:
        return [self.env.controller_context(i) for i in range(self.env.num_envs)]

    def stacked_obs(self, live: list[int]) -> np.ndarray:
        return self.obs[live]

    def step(
        self, live: list[int], actions: Sequence[np.ndarray] | np.ndarray, times: list[float]
    ) -> None:
        width = self._actions.shape[1]
        try:  # a batch policy's array, or the controllers' actions of one shape: one call
            stacked = np.asarray(actions, dtype=np.float64).reshape(len(live), width)
        except ValueError:  # shapes that differ: one by one (a bad one names its shape)
            for i, action in zip(live, actions, strict=True):
                self._actions[i] = np.asarray(action, dtype=np.float64).reshape(width)
        else:
            self._actions[live] = stacked
        self.obs, _rewards, _term, _trunc, info = self.env.step(self._actions)
        rows = info["rows"]
        for i, act_time in zip(live, times, strict=True):
            self.records[i].add(rows[i], act_time)  # lean: an info at the last step only
        self.done = self.env.finished.tolist()

    def abandon(self, i: int, failure: _Failure, act_time: float | None) -> None:
        """End episode i now: its controller failed (in a call of ``act_time`` [s])."""
        self.records[i].add(self.env.abandon(i, failure.reason), act_time)
        self.records[i].failure = failure
        self.done[i] = True

    def result(self, i: int, policy: Policy, label: EpisodeLabel | None) -> EpisodeResult:
        return self.records[i].result(policy, self.env.trajectory(i), label)

    def close(self) -> None:
        self.env.close()


class _SingleEpisodes:
    """The episodes as one single env each (trials that cannot share one env)."""

    def __init__(self, scenarios: list[Any], seeds: list[int], action_mode: str, env_id: str):
        self.seeds = seeds
        self.episodes: list[_Episode] = []
        try:
            for scenario, seed in zip(scenarios, seeds, strict=True):
                self.episodes.append(_Episode(env_id, scenario, seed, action_mode))
        except BaseException:
            self.close()
            raise
        self.obs = [e.obs for e in self.episodes]
        self.done = [e.done for e in self.episodes]
        self.shape = self.episodes[0].env.action_space.shape if self.episodes else ()

    def info(self, i: int) -> dict[str, Any]:
        return self.episodes[i].info

    def contexts(self) -> list[Any]:
        return [e.base.controller_context for e in self.episodes]

    def stacked_obs(self, live: list[int]) -> np.ndarray:
        return np.stack([self.obs[i] for i in live])

    def step(
        self, live: list[int], actions: Sequence[np.ndarray] | np.ndarray, times: list[float]
    ) -> None:
        for i, action, act_time in zip(live, actions, times, strict=True):
            episode = self.episodes[i]
            episode.step(action, act_time)
            self.obs[i], self.done[i] = episode.obs, episode.done

    def abandon(self, i: int, failure: _Failure, act_time: float | None) -> None:
        """End episode i now: its controller failed (in a call of ``act_time`` [s])."""
        self.episodes[i].abandon(failure, act_time)
        self.done[i] = True

    def result(self, i: int, policy: Policy, label: EpisodeLabel | None) -> EpisodeResult:
        return self.episodes[i].result(policy, label)

    def close(self) -> None:
        for e in self.episodes:
            e.env.close()


#: the env class the vectorized rows reproduce (other env ids run one env per episode)
_SINGLE_ENTRY_POINT = "shipgym.envs.path_follow:ShipPathFollowEnv"


def _episodes(
    scenarios: list[Any], seeds: list[int], action_mode: str, env_id: str, lean: bool = False
) -> _Episodes:
    """The episodes as the rows of one vectorized env when they can be (the env is the
    single ShipPathFollow env and the trials share the ship and its step constants: see
    :func:`~shipgym.envs.eval_trials.lockstep_problem`), else one env each.  ``lean``: the
    rows give no per-step info and no samples (a batch policy reads observations only)."""
    if gym.spec(env_id).entry_point == _SINGLE_ENTRY_POINT:
        loaded = [load_scenario(s) for s in scenarios]
        if loaded and lockstep_problem(loaded) is None:
            return _VectorEpisodes(loaded, seeds, action_mode, lean)
        scenarios = loaded
    return _SingleEpisodes(scenarios, seeds, action_mode, env_id)


def _run_lockstep(
    policy: BatchPolicy | list[Policy],
    episodes: _Episodes,
    guard: ActGuard | None = None,
    label: EpisodeLabel | Sequence[EpisodeLabel] | None = None,
) -> list[EpisodeResult]:
    """:func:`evaluate_batch`'s loop: every episode steps in lockstep, acted on by one
    :class:`BatchPolicy` or by its own policy of a list; ``guard``: a failing controller
    ends its episodes (:class:`ActGuard`); ``label``: every result's (:class:`EpisodeLabel`),
    or one per episode."""
    n = len(episodes.obs)
    batch = not isinstance(policy, list)
    try:
        contexts = episodes.contexts()
        if batch:
            _, _, failure = _call(guard, lambda: policy.reset_batch(contexts), timed=False)
            failures = [failure] * n
        else:
            failures = [
                _call(guard, functools.partial(p.reset, context, seed=seed), timed=False)[2]
                for p, context, seed in zip(policy, contexts, episodes.seeds, strict=True)
            ]
        for i, failure in enumerate(failures):
            if failure is not None:
                episodes.abandon(i, failure, None)
        live = [i for i in range(n) if not episodes.done[i]]
        while live:
            if batch:
                stepped, actions, times = _act_batch(policy, episodes, live, guard)
            else:
                stepped, actions, times = [], [], []
                for i in live:
                    act = functools.partial(policy[i].act, episodes.obs[i], episodes.info(i))
                    action, took, failure = _act(guard, act, episodes.shape)
                    if failure is not None:
                        episodes.abandon(i, failure, took)
                        continue
                    stepped.append(i)
                    actions.append(action)
                    times.append(took)
            if stepped:
                episodes.step(stepped, actions, times)
            live = [i for i in live if not episodes.done[i]]
        labels = label if isinstance(label, list) else [label] * n
        return [episodes.result(i, _policy_of(policy, i), labels[i]) for i in range(n)]
    finally:
        episodes.close()


def _policy_of(policy: BatchPolicy | list[Policy], i: int) -> Policy:
    """The policy that played episode ``i`` (its name, kind and figures go in the result)."""
    if isinstance(policy, list):
        return policy[i]
    if isinstance(policy, DealtPolicy):
        return policy.policies[policy.owners[i]]
    return policy


def _act_batch(
    policy: BatchPolicy, episodes: _Episodes, live: list[int], guard: ActGuard | None
) -> tuple[list[int], Any, list[float]]:
    """One ``act_batch`` for the ``live`` episodes: the episodes to step, their actions
    and each one's share of the call's time [s].  With a guard, the episodes whose action
    failed are abandoned: all of them when the call failed or its array has the wrong
    shape, else those whose row holds NaN or inf."""
    obs = episodes.stacked_obs(live)
    raw, took, failure = _call(guard, lambda: policy.act_batch(obs, live))
    share = took / len(live)
    if guard is None:
        return live, np.asarray(raw), [share] * len(live)
    shape = (len(live), *episodes.shape)
    if failure is None:
        actions, failure = _checked(raw, shape)
        if failure is None:
            return live, actions, [share] * len(live)
        if tuple(getattr(raw, "shape", ())) == shape:  # the rows with NaN or inf fail
            rows = [_checked(row, episodes.shape) for row in np.asarray(raw)]
            stepped = []
            for i, (row, row_failure) in zip(live, rows, strict=True):
                if row_failure is None:
                    stepped.append((i, row))
                else:
                    episodes.abandon(i, row_failure, share)
            return [i for i, _ in stepped], [row for _, row in stepped], [share] * len(stepped)
    for i in live:
        episodes.abandon(i, failure, share)
    return [], [], []


def training_seed(policy: Policy) -> int | None:
    """The seed ``policy`` was trained with: its ``training_seed`` attribute, else the
    ``seed`` of its training meta (learned policies); None when it has neither."""
    seed = getattr(policy, "training_seed", None)
    meta = getattr(policy, "meta", None)
    if seed is None and isinstance(meta, dict):
        seed = meta.get("seed")
    return int(seed) if seed is not None else None


def compute_time_metrics(act_times: list[float]) -> dict[str, float]:
    """``compute_ms`` (mean) and ``compute_ms_max`` [ms] of the ``act`` durations [s] (NaN
    without any: a controller whose ``reset`` failed)."""
    if not act_times:
        return {"compute_ms": math.nan, "compute_ms_max": math.nan}
    return {
        "compute_ms": 1e3 * float(np.mean(act_times)),
        "compute_ms_max": 1e3 * float(np.max(act_times)),
    }


_TRAJ_KEYS = TRAJECTORY_KEYS


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


def suite_trials(scenario: Any, seeds: Sequence[int], suite: str | os.PathLike) -> list[Any]:
    """The trial of ``scenario`` (a name, YAML path, :class:`~shipgym.scenarios.Scenario`
    or settings dict) that each seed draws with ``suite``'s ``randomize`` ranges: the
    leaderboard's own drawing (:func:`shipgym_baselines.leaderboard.trials`), so seed
    10000 + i is the leaderboard's trial i of the scenario."""
    # the suite file's reader sits beside this loop (the leaderboard's suite module imports
    # nothing above it); the drawing is the leaderboard job's: the scenario loaded by name,
    # else rebuilt from its settings, each seed's trial from the suite's ranges
    from shipgym_baselines.leaderboard.suite import load_suite

    spec = load_suite(suite)
    if isinstance(scenario, str | os.PathLike):
        base = load_scenario(str(scenario))
    else:
        loaded = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
        settings = json.dumps(loaded.config.model_dump(mode="json"), sort_keys=True)
        base = load_scenario(json.loads(settings))
    randomize = None if spec.randomize is None else spec.randomize.model_dump(mode="json")
    return seed_trials(base, randomize, seeds)


def evaluate(
    controller: ControllerSpec | Policy,
    scenario: Any,
    seeds: list[int],
    *,
    suite: str | os.PathLike | None = None,
    guard: ActGuard | None = None,
    label: EpisodeLabel | None = None,
    **settings: Any,
) -> list[EpisodeResult]:
    """Evaluate a controller on a scenario over seeds.

    ``controller``: a name, spec or long form :func:`~shipgym_baselines.registry.make_controller`
    knows (made afresh per seed with ``settings``) or a Policy instance (``settings`` may
    give its ``action_mode``; default: the policy's own).  ``suite``: a suite name or file;
    each seed then runs its trial of the scenario as that suite's leaderboard draws it
    (:func:`suite_trials`: start, jump time and current from the seed; seed 10000 + i is
    the leaderboard's i-th); None: every seed runs the scenario as written.  ``guard``: a
    failing controller ends its episode (:class:`ActGuard`); None: its error propagates.
    ``label``: every episode's scenario, controller and training seed
    (:class:`EpisodeLabel`; None: as :func:`run_episode`).
    """
    trials = [scenario] * len(seeds) if suite is None else suite_trials(scenario, seeds, suite)
    results = []
    for seed, trial in zip(seeds, trials, strict=True):
        privileged = False
        if isinstance(controller, str | ControllerEntry):
            policy, mode = make_controller(controller, **settings)
            plain = all(k == "training_seed" and v is None for k, v in settings.items())
            privileged = plain and grants_truth(controller)
        else:
            policy, mode = controller, settings.get("action_mode")
        results.append(
            run_episode(policy, trial, seed, mode, privileged=privileged, guard=guard, label=label)
        )
    return results
