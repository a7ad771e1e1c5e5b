"""A controller whose code is not the benchmark's own plays in a process of its own.

The evaluation loop's guard (:class:`~shipgym_baselines.evaluation.ActGuard`) ends a call
that runs past its limit by raising :class:`~shipgym_baselines.evaluation.CallTimeout` in
it.  That works only if the call gets back to Python and lets the exception through.
Some calls do not:

* code in C that holds the interpreter and never returns (a solver stuck in its loop);
* a controller that catches every exception, the timeout's too, and goes on;
* one that ignores or blocks the signal the watchdog sends;
* one that ends its process (``os._exit``, a crash in C such as SIGSEGV).

In the process that runs them, any of these would hold the run for ever, or end it.  So in
a run (:func:`shipgym_baselines.leaderboard.jobs.work`: ``leaderboard``, ``evaluate``; and
``shipgym run``) the jobs of a controller whose code is not shipgym's own
(:func:`isolated`: a plug-in file or module, an entry point, a factory registered from
outside the package) are run by :func:`run_isolated` in a child process.  The process
that started it (the supervisor) waits for the job's results and watches two things:

* the child's *beacon*: each guarded call of the controller posts when it started and its
  limit (:data:`shipgym_baselines.evaluation.BEACON`, two numbers in shared memory, set
  without a system call); a call that has not returned :data:`GRACE_S` seconds after ten
  times its limit of wall time (when the guard would have ended it) gets the child killed;
* the child itself: a child that ends without sending the results (killed, crashed,
  ``os._exit``) is noticed at once.

Then every episode of the job is the controller's failure, as if it could not be made
(``controller_timeout`` when killed over its limit, ``controller_error`` when its process
ended: the exit code or the signal is named), and the run goes on.  A job that raises one
of the benchmark's own errors in the child raises it in the supervisor, as without a child.

The child is forked where the platform can (Linux, macOS with ``fork``), so it starts in a
few milliseconds with the modules already loaded; it dies with its supervisor
(:func:`shipgym_baselines.signals.worker_init`).  This is isolation against failures, not
a security sandbox: the controller still runs with the user's rights.
"""

from __future__ import annotations

import multiprocessing
import pickle
import signal
import time
import warnings
from collections.abc import Callable
from typing import Any, TypeVar

from shipgym_baselines import evaluation, signals
from shipgym_baselines.errors import RunError
from shipgym_baselines.records.episodes import CONTROLLER_ERROR, CONTROLLER_TIMEOUT
from shipgym_baselines.registry import ControllerRef, resolve_controller

T = TypeVar("T")
R = TypeVar("R")

#: a call's process is killed this many seconds after the guard would have ended the
#: call (ten times its limit of wall time), when it has not ended
GRACE_S = 5.0
#: how often the supervisor looks at the child's beacon [s]
PERIOD_S = 0.05
#: the top-level packages of the benchmark's own code
OWN_PACKAGES = ("shipgym", "shipgym_baselines")


def isolated(controller: ControllerRef) -> bool:
    """Whether ``controller``'s code is not the benchmark's own (its factory defined
    outside :data:`OWN_PACKAGES`): its jobs run in a process of their own."""
    factory: Any = resolve_controller(controller).factory
    while hasattr(factory, "func"):  # functools.partial: settings bound
        factory = factory.func
    module = getattr(factory, "__module__", None) or ""
    return module.split(".")[0] not in OWN_PACKAGES


def _context() -> Any:
    """The multiprocessing context of a child: forked where the platform can."""
    methods = multiprocessing.get_all_start_methods()
    return multiprocessing.get_context("fork" if "fork" in methods else "spawn")


def _portable(exc: BaseException) -> BaseException:
    """``exc`` if it survives pickling, else a :class:`RunError` of its line."""
    try:
        pickle.loads(pickle.dumps(exc))
    except Exception:
        return RunError(evaluation.error_line(exc))
    return exc


def _child(conn: Any, work: Callable[[T], R], item: T, beacon: Any) -> None:
    """The child: ``work(item)`` sent back as ``("ok", value)`` or ``("raised", error)``."""
    beacon[0] = 0.0  # started (the beacon covered its start: a spawned child imports)
    signals.worker_init()  # no group signals; gone with the supervisor
    evaluation.BEACON = beacon
    try:
        outcome: tuple[str, Any] = ("ok", work(item))
    except BaseException as exc:  # the job's own error: raised again in the supervisor
        outcome = ("raised", _portable(exc))
    try:
        conn.send(outcome)
    except Exception as exc:  # a value that cannot be pickled
        conn.send(("raised", RunError(f"a job's results could not be sent back: {exc}")))
    conn.close()


def _ended(exitcode: int | None) -> str:
    """How a child ended, in words."""
    if exitcode is not None and exitcode < 0:
        with_name = signal.Signals(-exitcode).name if -exitcode in signal.valid_signals() else ""
        return f"was killed by {with_name or f'signal {-exitcode}'}"
    return f"ended with exit code {exitcode}"


def run_isolated(
    work: Callable[[T], R],
    item: T,
    on_failure: Callable[[str, str], R],
    setup_limit: float,
) -> R:
    """``work(item)`` in a child process (module doc); ``on_failure(reason, error)``
    stands for its value when the child ends without it (``reason``:
    ``controller_error`` / ``controller_timeout``; ``error``: one line); ``setup_limit``
    [s]: the guard's limit on construction and ``reset``, which the child's start is held
    to as well.  Ctrl-C in the supervisor kills the child."""
    ctx = _context()
    reader, writer = ctx.Pipe(duplex=False)
    beacon = ctx.RawArray("d", 2)
    beacon[1], beacon[0] = setup_limit, time.monotonic()  # its start, until it runs
    child = ctx.Process(target=_child, args=(writer, work, item, beacon))
    with warnings.catch_warnings():  # Python ≥ 3.12 warns of a fork beside threads
        warnings.simplefilter("ignore", DeprecationWarning)
        child.start()
    writer.close()
    try:
        outcome = _supervise(child, reader, beacon)
    finally:
        if child.is_alive():
            child.kill()
        child.join()
        reader.close()
    kind, value = outcome
    if kind == "ok":
        return value
    if kind == "raised":
        raise value
    return on_failure(*value)


def call(fn: Callable[[], R]) -> R:
    """``fn()``: the work of a child that runs one call (``run_isolated(call, fn, …)``)."""
    return fn()


def _supervise(child: Any, reader: Any, beacon: Any) -> tuple[str, Any]:
    """Wait for the child's outcome; ``("failed", (reason, error))`` when it ends without
    one or is killed for a call that outlived its limit."""
    while True:
        if reader.poll(PERIOD_S):
            try:
                return reader.recv()
            except (EOFError, OSError):  # it ended without sending everything
                break
        if not child.is_alive():
            if reader.poll(0):
                continue  # its last words arrived meanwhile
            break
        started, limit = beacon[0], beacon[1]
        bound = evaluation.WALL_FACTOR * limit + GRACE_S
        if started and time.monotonic() - started > bound:
            child.kill()
            child.join()
            why = (
                f"the call had not returned after {bound:.3g} s, {evaluation.WALL_FACTOR:g} "
                f"times the limit of {limit:g} s and {GRACE_S:g} s more, nor ended when asked: "
                "its process was killed"
            )
            return ("failed", (CONTROLLER_TIMEOUT, why))
    child.join()
    return ("failed", (CONTROLLER_ERROR, f"the controller's process {_ended(child.exitcode)}"))


__all__ = ["GRACE_S", "call", "isolated", "run_isolated"]
