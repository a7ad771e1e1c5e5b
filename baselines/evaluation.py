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
import signal
import threading
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import Any, NamedTuple, Protocol, runtime_checkable

import gymnasium as gym
import numpy as np

import shipgym  # noqa: F401  (registers the envs)
from shipgym.envs.core import TRAJECTORY_KEYS, check_action
from shipgym.envs.eval_trials import EvaluationTrialsVectorEnv, lockstep_problem
from shipgym.errors import ShipgymError
from shipgym.scenarios.loader import Scenario, load_scenario
from shipgym.scenarios.trials import seed_trials
from shipgym_baselines.errors import ControllerError, RunError
from shipgym_baselines.policy import Policy
from shipgym_baselines.privileged import grants_truth, reset_with_truth
from shipgym_baselines.records.episodes import (
    CONTROLLER_ERROR,
    CONTROLLER_STATS,
    CONTROLLER_TIMEOUT,
    STATS_ERROR,
    EpisodeLabel,
    EpisodeResult,
    stats_problem,
)
from shipgym_baselines.registry import (
    ControllerRecord,
    ControllerRef,
    make_controller,
    resolve_controller,
)

ENV_ID = "ShipPathFollow-v0"
#: evaluation seeds start here, apart from the training seeds (0, 1, …) of learned agents
EVAL_SEED_OFFSET = 10_000

#: the clock [s] that times each ``act`` call (``compute_ms``): wall time, unless
#: :func:`act_clock` swaps it (the run-cost profile reads CPU time)
_clock: Callable[[], float] = time.perf_counter


#: the default limit [s] on the CPU time of one controller call (``--act-timeout``)
ACT_TIMEOUT_S = 10.0
#: a call that has not returned after this many times the limit of wall time ends too
#: (one blocked: sleeping, waiting), whatever CPU time it used
WALL_FACTOR = 10.0
#: construction and ``reset`` may take this many times the limit of one ``act`` call
#: (they may load a model or compile a solver to C, once per machine) …
SETUP_FACTOR = 30.0
#: … and at least this many seconds of CPU time
SETUP_MIN_S = 60.0
#: the most characters of an episode's ``error`` (the one-line message of its failure)
ERROR_CHARS = 300


@dataclasses.dataclass(frozen=True)
class ActGuard:
    """A failing controller ends its episode, not the run.

    With a guard the loop ends an episode whose controller cannot be made, whose ``reset``
    or ``act`` raises (any exception but the user's Ctrl-C: ``SystemExit`` too), or gives
    an action that is not numbers of the action's shape or holds NaN or inf
    (``termination_reason`` ``"controller_error"``), or whose ``act`` runs for more than
    ``timeout`` [s] of the process's CPU time, or for :data:`WALL_FACTOR` × ``timeout`` of
    wall time (``"controller_timeout"``); the env's ``abandon`` charges it as leaving the
    corridor at that step, and the metric ``error`` says why in one line.  An
    ``episode_stats`` that fails the same ways, or gives no mapping of figures, leaves the
    episode as it is: its figures are left out and ``stats_error`` says why.  Without a
    guard (None) such an error propagates, as a debugger wants it.

    The limit is CPU time so that a first call that imports a library (torch takes seconds
    of wall time on a loaded machine) is no timeout.  A watchdog thread
    (:class:`_Watch`) ends a call that runs past it while it runs: a signal to the main
    thread raises :class:`CallTimeout` in the controller's code.  Code in C that holds the
    interpreter ends when it returns to Python; off the main thread (no signal can reach
    it) the call is judged when it returns.  A controller whose code is not the
    benchmark's own runs in a process of its own in a run
    (:mod:`shipgym_baselines.isolation`), which is killed when a call outlives the wall
    limit by :data:`~shipgym_baselines.isolation.GRACE_S`: code in C that never returns,
    a controller that ignores the signal or swallows the timeout, one that ends its
    process.  Construction and ``reset`` have a limit too, :attr:`setup_timeout` (they
    may load a model or compile a solver to C, once per machine).  A batch
    policy's ``act_batch`` acts for all live episodes: the whole call counts against the
    limit.  ``timeout`` inf: no limit (the references, never judged as entrants).
    """

    timeout: float = ACT_TIMEOUT_S

    def __post_init__(self) -> None:
        if not self.timeout > 0.0:  # NaN too
            raise RunError(f"--act-timeout must be a positive time in s, got {self.timeout}")

    @property
    def setup_timeout(self) -> float:
        """The limit [s] of CPU time on a controller's construction and on each ``reset``:
        :data:`SETUP_FACTOR` × :attr:`timeout`, at least :data:`SETUP_MIN_S` (inf with
        no limit); the wall limit is :data:`WALL_FACTOR` times it, as an act's."""
        return max(SETUP_FACTOR * self.timeout, SETUP_MIN_S)


class _Failure(NamedTuple):
    """Why a controller's episode ended early: the termination reason and one line."""

    reason: str
    error: str


class CallTimeout(BaseException):
    """Raised in a controller's call that ran past its limit (:class:`_Watch`): a
    BaseException, so that a controller's ``except Exception`` does not swallow it."""


class _NotMade(Exception):
    """The error of a controller that could not be made (:class:`_Unmade`), one line."""


def error_line(exc: BaseException) -> str:
    """``Type: message`` of ``exc`` as one printable line of at most :data:`ERROR_CHARS`."""
    text = str(exc) if isinstance(exc, _NotMade) else f"{type(exc).__name__}: {exc}"
    text = "".join(c if c.isprintable() else " " for c in text)
    text = " ".join(text.split())
    return text if len(text) <= ERROR_CHARS else text[: ERROR_CHARS - 1] + "…"


#: the signal the watchdog sends the main thread to end a call past its limit
_SIGNAL = getattr(signal, "SIGUSR2", None)
#: the watchdog looks at the running call every quarter of the limit, within these [s]
_PERIOD_S = (0.005, 1.0)

#: in a controller's own process (:mod:`shipgym_baselines.isolation`): the shared slots
#: where each guarded call posts when it started [s, ``time.monotonic``; 0: no call runs]
#: and its limit [s], which the process's supervisor reads (None: not in such a process)
BEACON: Any = None


class _Watch:
    """The watchdog of one guarded loop: a thread that looks at the running call every
    :attr:`period` [s] and, once the call has used ``limit`` [s] of the process's CPU time
    or :data:`WALL_FACTOR` × ``limit`` of wall time since it first saw it, marks it over the
    limit and (on the main thread) interrupts it: :meth:`_interrupt` raises
    :class:`CallTimeout` in it.  The loop marks each call with :meth:`begin` and
    :meth:`end` (two attribute writes: no system call per step)."""

    def __init__(self, limit: float) -> None:
        self.limit = limit  # the running call's (an act's, or a setup call's)
        self.period = min(max(limit / 4.0, _PERIOD_S[0]), _PERIOD_S[1])
        self.main = (
            _SIGNAL is not None
            and hasattr(signal, "pthread_kill")
            and threading.current_thread() is threading.main_thread()
        )
        self._call = 0  # the number of the running (or last) call
        self._active = False
        self._over = 0  # the last call found over the limit (0: none) and why
        self._why = ""
        self._requested = 0  # the call the last signal was sent to end
        self._previous: Any = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="shipgym-watchdog", daemon=True)

    def begin(self, limit: float) -> None:
        """A controller's call starts, held to ``limit`` [s]."""
        self.limit = limit
        self._call += 1
        self._active = True
        if BEACON is not None:  # the supervisor of this process sees it too
            BEACON[1] = limit
            BEACON[0] = time.monotonic()

    def end(self) -> str | None:
        """The call ended: why it was over the limit, or None."""
        self._active = False
        if BEACON is not None:
            BEACON[0] = 0.0
        return self._why if self._over == self._call else None

    def _run(self) -> None:
        seen, wall0, cpu0, limit = 0, 0.0, 0.0, self.limit
        main = threading.main_thread().ident
        while not self._stop.wait(self.period):
            call = self._call
            if not self._active:
                continue
            if call != seen:  # a new call: measured from now
                seen, wall0, cpu0, limit = call, time.monotonic(), time.process_time(), self.limit
                continue
            cpu, wall = time.process_time() - cpu0, time.monotonic() - wall0
            if cpu > limit:
                why = f"the call ran {cpu:.3g} s of CPU time, over the limit of {limit:g} s"
            elif wall > WALL_FACTOR * limit:
                why = (
                    f"the call had not returned after {wall:.3g} s, {WALL_FACTOR:g} times the "
                    f"limit of {limit:g} s"
                )
            else:
                continue
            if self._call != call or not self._active:
                continue  # it returned meanwhile
            self._why, self._over = why, call
            if self.main and main is not None:
                self._requested = call
                signal.pthread_kill(main, _SIGNAL)

    def _interrupt(self, signum: int, frame: Any) -> None:
        """The signal handler: end the call the watchdog asked to end, if it still runs."""
        requested, self._requested = self._requested, 0
        if not requested:  # not the watchdog's: the handler there was before
            if callable(self._previous):
                self._previous(signum, frame)
            return
        if requested == self._call and self._active:
            raise CallTimeout(self._why)

    def __enter__(self) -> _Watch:
        if self.main:
            self._previous = signal.signal(_SIGNAL, self._interrupt)
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join()
        if self.main:
            previous = self._previous if self._previous is not None else signal.SIG_DFL
            signal.signal(_SIGNAL, previous)


#: the watchdog of the guarded loop running in this thread (None: none)
_watching = threading.local()


@contextlib.contextmanager
def _watched(guard: ActGuard | None) -> Iterator[None]:
    """A watchdog (:class:`_Watch`) for the controller calls of the ``with`` body, when
    ``guard`` has a finite limit."""
    if guard is None or not math.isfinite(guard.timeout):
        yield
        return
    outer = getattr(_watching, "watch", None)
    with _Watch(guard.timeout) as watch:
        _watching.watch = watch
        try:
            yield
        finally:
            _watching.watch = outer


def _timed_call(
    call: Callable[[], Any], watch: _Watch | None, limit: float = math.inf
) -> tuple[Any, str | None]:
    """``call()`` under ``watch``, held to ``limit`` [s]: its value and why it ran over
    the limit (None: it did not, or no watch)."""
    if watch is None:
        return call(), None
    watch.begin(limit)
    try:
        value = call()
    finally:
        over = watch.end()
    return value, over


def _call(
    guard: ActGuard | None, call: Callable[[], Any], setup: bool = False
) -> tuple[Any, float, _Failure | None]:
    """``call()`` (a controller's), its time on the act clock [s] and, with a guard, why
    the controller failed (None: it did not; :class:`ActGuard`); held to the guard's
    limit of an act, or with ``setup`` (a ``reset``) to its :attr:`ActGuard.setup_timeout`."""
    start = _clock()
    if guard is None:
        value = call()
        return value, _clock() - start, None
    watch = getattr(_watching, "watch", None)
    limit = guard.setup_timeout if setup else guard.timeout
    try:
        value, over = _timed_call(call, watch, limit)
    except CallTimeout as exc:
        if watch is not None:
            watch.end()  # the signal may land as the call returns
        return None, _clock() - start, _Failure(CONTROLLER_TIMEOUT, str(exc))
    except KeyboardInterrupt:  # the user's Ctrl-C (or SIGTERM): the run's, not the episode's
        raise
    except BaseException as exc:  # the controller's, whatever it is: the episode's result
        if watch is not None:
            watch.end()
        return None, _clock() - start, _Failure(CONTROLLER_ERROR, error_line(exc))
    took = _clock() - start
    if over is not None:
        return value, took, _Failure(CONTROLLER_TIMEOUT, over)
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
        guard: ActGuard | None = None,
    ) -> EpisodeResult:
        """The episode's result; ``trajectory``: a record without rows (the env's);
        ``label``: its scenario, controller and training seed (None: the trial's name, the
        policy's name and its training seed); ``guard``: the loop's, for the controller's
        ``episode_stats`` (:func:`controller_stats`)."""
        metrics = dict(self.info["episode_metrics"])
        metrics["termination_reason"] = self.info.get("termination_reason")
        if self.failure is not None:
            metrics["error"] = self.failure.error
        metrics.update(compute_time_metrics(self.act_times))
        stats, problem = controller_stats(policy, guard)
        if stats:  # controller-specific figures (e.g. NMPC solver failures): their own key
            metrics[CONTROLLER_STATS] = stats
        if problem is not None:
            metrics[STATS_ERROR] = problem
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


def controller_stats(policy: Policy, guard: ActGuard | None) -> tuple[dict[str, Any], str | None]:
    """The controller's own figures of its episode (its ``episode_stats()``, if it has one)
    and why they were left out (None: they were not).  With a guard, a call that fails or
    runs over the limit, or figures that are no mapping of names to numbers
    (:func:`~shipgym_baselines.records.episodes.stats_problem`), are left out (the
    result's ``stats_error`` says why; a run names it once per controller on stderr:
    :func:`shipgym_baselines.leaderboard.run.announce_failure`); the episode stays as the
    env ended it.  Without a guard they raise."""
    stats = getattr(policy, "episode_stats", None)
    if stats is None:
        return {}, None
    figures, _, failure = _call(guard, stats)
    problem = failure.error if failure is not None else stats_problem(figures)
    if problem is None:
        return dict(figures), None
    if failure is None:
        why = f"episode_stats() {problem}"
    elif failure.reason == CONTROLLER_TIMEOUT:
        why = f"episode_stats() ran over its limit ({problem})"
    else:
        why = f"episode_stats() raised {problem}"
    if guard is None:
        raise ControllerError(f"{policy.name}: {why}")
    return {}, why


class _Unmade:
    """A controller that could not be made (with a guard), or whose episodes could not be
    played: each of its episodes ends at its ``reset`` with ``error`` (after ``prefix``),
    a counted failure of the controller (``reason``: ``controller_error``, or
    ``controller_timeout`` for a construction over its limit)."""

    def __init__(
        self,
        name: str,
        kind: str,
        action_mode: str,
        training_seed: int | None,
        error: str,
        reason: str = CONTROLLER_ERROR,
        prefix: str = "the controller could not be made: ",
    ) -> None:
        self.name, self.kind, self.action_mode = name, kind, action_mode
        self.training_seed = training_seed
        self.error = f"{prefix}{error}"
        self.reason = reason

    def reset(self, context: Any, seed: int | None = None) -> None:
        if self.reason == CONTROLLER_TIMEOUT:
            raise CallTimeout(self.error)
        raise _NotMade(self.error)

    def act(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        self.reset(None)


def _make(
    controller: ControllerRef,
    guard: ActGuard | None,
    label: EpisodeLabel | None = None,
    **settings: Any,
) -> tuple[Policy, str]:
    """:func:`~shipgym_baselines.registry.make_controller`; with a guard, a controller
    whose construction raises (any exception but Ctrl-C) or runs over the guard's
    :attr:`~ActGuard.setup_timeout` is an :class:`_Unmade` named as ``label`` says.  A
    name that is no controller, and the benchmark's own refusals (a
    :class:`~shipgym.errors.ShipgymError`: a model that cannot be read, a pickle not
    trusted), are the caller's errors, raised in one line as without a guard."""
    record = resolve_controller(controller)
    if guard is None:
        return make_controller(record, **settings)
    reason = CONTROLLER_ERROR
    try:
        with _watched(guard):
            watch = getattr(_watching, "watch", None)
            made, over = _timed_call(
                lambda: make_controller(record, **settings), watch, guard.setup_timeout
            )
        if over is None:
            return made
        error, reason = over, CONTROLLER_TIMEOUT  # it returned, over its limit
    except (KeyboardInterrupt, ShipgymError):
        raise
    except CallTimeout as exc:
        error, reason = str(exc), CONTROLLER_TIMEOUT
    except BaseException as exc:  # the controller's own code: a failure of its episodes
        error = error_line(exc)
    name = label.controller if label is not None else record.name
    seed = settings.get("training_seed")
    unmade = _Unmade(name, record.kind, record.action_mode, seed, error, reason)
    return unmade, record.action_mode


def failed_episode(
    controller: ControllerRef,
    scenario: Any,
    seed: int,
    reason: str,
    error: str,
    guard: ActGuard,
    label: EpisodeLabel,
) -> EpisodeResult:
    """The episode of ``controller`` (its kind and action mode; nothing of it is made)
    that ended at its reset with ``reason`` and ``error`` (one line), as a controller's that
    could not be made: a job whose process ended or was killed before it gave its results
    (:mod:`shipgym_baselines.isolation`)."""
    record = resolve_controller(controller)
    policy = _Unmade(
        label.controller, record.kind, record.action_mode, label.training_seed, error, reason, ""
    )
    return run_episode(policy, scenario, seed, record.action_mode, guard=guard, label=label)


class _Episode:
    """One env's episode as the evaluation loop runs it: made and reset with ``seed``, then
    stepped with the policy's actions and the time each took, then its result."""

    def __init__(self, env_id: str, scenario: Any, seed: int, action_mode: str) -> None:
        # the given trial itself (no trial drawn at reset), truncated at its own time limit
        self.env = gym.make(
            env_id,
            scenario=scenario,
            action_mode=action_mode,
            randomize=False,
            max_episode_steps=-1,
        )
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

    def result(
        self, policy: Policy, label: EpisodeLabel | None = None, guard: ActGuard | None = None
    ) -> EpisodeResult:
        return self.record.result(policy, label=label, guard=guard)


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
        if privileged and not isinstance(policy, _Unmade):
            reset = functools.partial(reset_with_truth, policy, context, base, seed)
        else:
            reset = functools.partial(policy.reset, context, seed=seed)
        with _watched(guard):
            _, _, failure = _call(guard, reset, setup=True)
            took: float | None = None  # no act call yet
            while failure is None and not episode.done:
                action, took, failure = _act(
                    guard, lambda: policy.act(episode.obs, episode.info), shape
                )
                if failure is None:
                    episode.step(action, took)
            if failure is not None:
                episode.abandon(failure, took)
            result = episode.result(policy, label, guard)
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
    controller: ControllerRef | Policy,
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
    made = isinstance(controller, ControllerRef)
    if training_seeds is not None:
        return _evaluate_dealt(
            controller, per_seed, seeds, training_seeds, action_mode, env_id, guard, label
        )
    if made:  # resolved once: every episode's instance is made from the record
        controller = resolve_controller(controller)
    if made:
        policy, mode = _make(controller, guard, label, training_seed=training_seed)
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
            _make(controller, guard, label, training_seed=training_seed)[0] for _ in seeds[1:]
        ]
        return _run_lockstep(policies, _episodes(per_seed, seeds, mode, env_id), guard, label)
    results = []
    for i, (scenario, seed) in enumerate(zip(per_seed, seeds, strict=True)):
        if made and i > 0:
            policy, _ = _make(controller, guard, label, training_seed=training_seed)
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
    controller: ControllerRef | Policy,
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
    if not isinstance(controller, ControllerRef):
        raise ControllerError("training_seeds: give the learned controller by name, not a Policy")
    shown = controller.name if isinstance(controller, ControllerRecord) else controller
    controller = resolve_controller(controller)
    made = {k: _make(controller, guard, label, training_seed=k) for k in dict.fromkeys(owners)}
    unmade = [i for i, k in enumerate(owners) if isinstance(made[k][0], _Unmade)]
    if not all(isinstance(p, BatchPolicy | _Unmade) for p, _ in made.values()):
        first = next(p for p, _ in made.values())
        if first.kind != "learned":
            raise ControllerError(f"training_seeds: {shown!r} is not a learned agent")
        # a learned controller that acts per episode (nmpc_learned_id): each episode its own
        # instance of its owner's training seed, all in lockstep
        policies = [made[owners[0]][0]] + [
            _make(controller, guard, label, training_seed=k)[0] for k in owners[1:]
        ]
        mode = action_mode or made[owners[0]][1] or first.action_mode
        labels = _dealt_labels(scenarios, owners, first.name, label)
        return _run_lockstep(policies, _episodes(scenarios, seeds, mode, env_id), guard, labels)
    out: dict[int, EpisodeResult] = {}
    if unmade:  # their episodes end at reset; the other training seeds' run as dealt
        policies = [made[owners[i]][0] for i in unmade]
        mode = made[owners[unmade[0]]][1]
        picked = [scenarios[i] for i in unmade], [seeds[i] for i in unmade]
        labels = _dealt_labels(picked[0], [owners[i] for i in unmade], policies[0].name, label)
        done = _run_lockstep(policies, _episodes(*picked, mode, env_id), guard, labels)
        out.update(zip(unmade, done, strict=True))
    rest = [i for i in range(len(seeds)) if i not in set(unmade)]
    if rest:
        dealt = [owners[i] for i in rest]
        policy = DealtPolicy({k: made[k][0] for k in dict.fromkeys(dealt)}, dealt)
        mode = action_mode or made[dealt[0]][1] or policy.action_mode
        picked = [scenarios[i] for i in rest], [seeds[i] for i in rest]
        episodes = _episodes(*picked, mode, env_id, lean=True)
        labels = _dealt_labels(picked[0], dealt, policy.name, label)
        out.update(zip(rest, _run_lockstep(policy, episodes, guard, labels), strict=True))
    return [out[i] for i in range(len(seeds))]


def _dealt_labels(
    scenarios: list[Any], owners: list[int | None], name: str, label: EpisodeLabel | None
) -> list[EpisodeLabel]:
    """Each dealt episode's label: ``label`` with the episode's training seed, else as the
    loop labels an episode (its scenario's name and the policy's)."""
    if label is not None:
        return [label._replace(training_seed=k) for k in owners]
    loaded = [load_scenario(sc) if isinstance(sc, str) else sc for sc in scenarios]
    return [EpisodeLabel(sc.name, name, k) for sc, k in zip(loaded, owners, strict=True)]


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

    def result(
        self, i: int, policy: Policy, label: EpisodeLabel | None, guard: ActGuard | None
    ) -> EpisodeResult: ...

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

    def result(
        self, i: int, policy: Policy, label: EpisodeLabel | None, guard: ActGuard | None
    ) -> EpisodeResult:
        return self.records[i].result(policy, self.env.trajectory(i), label, guard)

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

    def result(
        self, i: int, policy: Policy, label: EpisodeLabel | None, guard: ActGuard | None
    ) -> EpisodeResult:
        return self.episodes[i].result(policy, label, guard)

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
    try:
        with _watched(guard):
            return _lockstep(policy, episodes, guard, label)
    finally:
        episodes.close()


def _lockstep(
    policy: BatchPolicy | list[Policy],
    episodes: _Episodes,
    guard: ActGuard | None,
    label: EpisodeLabel | Sequence[EpisodeLabel] | None,
) -> list[EpisodeResult]:
    """:func:`_run_lockstep`'s body, its episodes open."""
    n = len(episodes.obs)
    batch = not isinstance(policy, list)
    contexts = episodes.contexts()
    if batch:
        _, _, failure = _call(guard, lambda: policy.reset_batch(contexts), setup=True)
        failures = [failure] * n
    else:
        failures = [
            _call(guard, functools.partial(p.reset, context, seed=seed), setup=True)[2]
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
    return [episodes.result(i, _policy_of(policy, i), labels[i], guard) for i in range(n)]


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
    """The trial of ``scenario`` (a name, YAML path, :class:`~shipgym.scenarios.loader.Scenario`
    or settings dict) that each seed draws with ``suite``'s ``randomize`` ranges: the
    leaderboard's own drawing (:func:`shipgym_baselines.leaderboard.jobs.trials`), so seed
    10000 + i is the leaderboard's trial i of the scenario."""
    # the suite file's reader sits beside this loop (the leaderboard's suite module imports
    # nothing above it); the drawing is the leaderboard job's: the scenario loaded by name,
    # else rebuilt from its settings, each seed's trial from the suite's ranges
    from shipgym_baselines.suite import load_suite

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
    controller: ControllerRef | Policy,
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
        if isinstance(controller, ControllerRef):
            controller = resolve_controller(controller)  # once: a record resolves to itself
            policy, mode = _make(controller, guard, label, **settings)
            plain = all(k == "training_seed" and v is None for k, v in settings.items())
            privileged = plain and grants_truth(controller)
        else:
            policy, mode = controller, settings.get("action_mode")
        results.append(
            run_episode(policy, trial, seed, mode, privileged=privileged, guard=guard, label=label)
        )
    return results
