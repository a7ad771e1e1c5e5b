"""Run a picklable function over a list of items, in turn, in local processes or on Ray.

The one executor of the leaderboard's jobs, training sweeps and a tuning study's Ray tasks.
``backend`` is one of :data:`BACKENDS`:

* ``local``: ``workers`` ≤ 1 runs the items in turn in this process; more runs them in a
  :class:`~concurrent.futures.ProcessPoolExecutor` of ``workers`` processes, each started
  with ``initializer`` (the leaderboard's: :func:`shipgym_baselines.signals.worker_init`).
* ``ray``: one Ray task per item (``workers`` and ``initializer`` unused: Ray places the
  tasks on its cluster's CPUs).  A Ray that is not running is started as :class:`RaySetup`
  says: by default connected to ``RAY_ADDRESS`` (else a local instance) and left running.
  Ray is an extra (``pip install "shipgym[ray]"``): without it, a
  :class:`~shipgym_baselines.extras.MissingExtra` names the install.

:func:`map_jobs` yields the results as the jobs finish, or in the order of the items
(``ordered``).  It checks the backend when called (:func:`check_backend`: a
:class:`RunError` naming a bad one).  :func:`task_pool` is the local pool for work
submitted task by task (the leaderboard's figures, DAgger's label rollouts).
A job that raises, Ctrl-C, or a consumer that stops reading (``close()``) ends the rest:
the jobs not started are cancelled, the running ones killed (Ray tasks cancelled;
``finish_running``: a pool's running jobs finish first), and the error propagates.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
from collections.abc import Callable, Generator, Iterable, Iterator, Mapping
from concurrent.futures import Executor, Future, ProcessPoolExecutor, as_completed
from contextlib import closing
from typing import Any, TypeVar

from shipgym_baselines.errors import RunError
from shipgym_baselines.extras import require

#: where jobs run (``--backend``): local processes or a Ray cluster
BACKENDS = ("local", "ray")

T = TypeVar("T")
R = TypeVar("R")
#: (index of the item, its result), as the jobs finish
Pairs = Generator[tuple[int, R], None, None]


@dataclasses.dataclass(frozen=True)
class RaySetup:
    """How the ``ray`` backend starts Ray and its tasks.

    ``init``: ``ray.init``'s keyword arguments when Ray is not running (None: connect to
    ``RAY_ADDRESS``, else start a local instance); ``task``: each task's ``ray.remote``
    options (e.g. ``num_cpus``); ``shutdown``: shut down a Ray this call started once its
    jobs end (a Ray already running is always left running)."""

    init: Mapping[str, Any] | None = None
    task: Mapping[str, Any] = dataclasses.field(default_factory=dict)
    shutdown: bool = False

    def init_kwargs(self) -> dict[str, Any]:
        """``ray.init``'s keyword arguments (``RAY_ADDRESS`` read now)."""
        if self.init is not None:
            return dict(self.init)
        return {"address": os.environ.get("RAY_ADDRESS"), "ignore_reinit_error": True}


def check_backend(backend: str) -> None:
    """A :class:`RunError` naming ``backend`` unless it is one of :data:`BACKENDS`; for
    ``ray``, a :class:`~shipgym_baselines.extras.MissingExtra` naming the install when Ray
    is not installed (a run checks both before its work)."""
    if backend not in BACKENDS:
        raise RunError(f"unknown backend {backend!r}; valid: {', '.join(BACKENDS)}")
    if backend == "ray":
        require("ray", "ray", "--backend ray")


def map_jobs(
    fn: Callable[[T], R],
    items: Iterable[T],
    backend: str = "local",
    workers: int = 1,
    initializer: Callable[[], object] | None = None,
    *,
    ordered: bool = False,
    ray_setup: RaySetup | None = None,
    finish_running: bool = False,
) -> Iterator[R]:
    """``fn(item)`` of each item on ``backend`` (module doc), yielded as each job finishes
    (in turn: in the order of ``items``), or with ``ordered`` in the order of ``items`` (a
    result waits for those before it).  The backend is checked now, the jobs start at the
    first ``next``; closing the iterator stops them."""
    pairs = _indexed(fn, items, backend, workers, initializer, ray_setup, finish_running)
    return _in_order(pairs) if ordered else _values(pairs)


def _values(pairs: Pairs[R]) -> Iterator[R]:
    """The results of ``pairs`` (index, result); closing this closes ``pairs``."""
    with closing(pairs):
        for _, result in pairs:
            yield result


def _in_order(pairs: Pairs[R]) -> Iterator[R]:
    """The results of ``pairs`` (index, result) by index; closing this closes ``pairs``."""
    held: dict[int, R] = {}
    following = 0  # the index of the next result to yield
    with closing(pairs):
        for index, result in pairs:
            held[index] = result
            while following in held:
                yield held.pop(following)
                following += 1


def _indexed(
    fn: Callable[[T], R],
    items: Iterable[T],
    backend: str,
    workers: int,
    initializer: Callable[[], object] | None,
    ray_setup: RaySetup | None,
    finish_running: bool,
) -> Pairs[R]:
    """(index of the item, its result) as the jobs finish; the backend checked now."""
    check_backend(backend)
    items = list(items)
    if backend == "ray":
        return _on_ray(fn, items, ray_setup or RaySetup())
    if workers <= 1:
        return _in_turn(fn, items)
    return _in_pool(fn, items, workers, initializer, finish_running)


def _in_turn(fn: Callable[[T], R], items: list[T]) -> Pairs[R]:
    for index, item in enumerate(items):
        yield index, fn(item)


def _in_pool(
    fn: Callable[[T], R],
    items: list[T],
    workers: int,
    initializer: Callable[[], object] | None,
    finish_running: bool,
) -> Pairs[R]:
    pool = ProcessPoolExecutor(max_workers=workers, initializer=initializer)
    try:
        futures = {pool.submit(fn, item): index for index, item in enumerate(items)}
        for future in as_completed(futures):
            yield futures[future], future.result()
    except BaseException:  # Ctrl-C, a failed job, or the consumer stopped: stop the workers
        if finish_running:
            pool.shutdown(wait=True, cancel_futures=True)
            raise
        running = list((pool._processes or {}).values())  # shutdown forgets them
        pool.shutdown(wait=False, cancel_futures=True)
        for process in running:
            process.kill()  # workers may ignore SIGTERM (shipgym_baselines.signals)
        raise
    pool.shutdown()


def _call(fn: Callable[[T], R], item: T) -> R:
    """``fn(item)``: the one function Ray runs (any picklable ``fn``, a partial too)."""
    return fn(item)


def _on_ray(fn: Callable[[T], R], items: list[T], setup: RaySetup) -> Pairs[R]:
    import ray

    started = not ray.is_initialized()
    if started:
        ray.init(**setup.init_kwargs())
    try:
        task = ray.remote(**setup.task)(_call) if setup.task else ray.remote(_call)
        refs = {task.remote(fn, item): index for index, item in enumerate(items)}
        pending = list(refs)
        try:
            while pending:
                done, pending = ray.wait(pending)
                for ref in done:
                    yield refs[ref], ray.get(ref)
        except BaseException:  # Ctrl-C, a failed task, or the consumer stopped
            for ref in pending:
                ray.cancel(ref, force=True)
            raise
    finally:
        if started and setup.shutdown:
            ray.shutdown()


__all__ = ["BACKENDS", "RaySetup", "check_backend", "map_jobs"]


class Inline:
    """An executor that runs each task as it is submitted (a small job needs no pool)."""

    def submit(self, fn: Callable[..., R], *args: Any, **kwargs: Any) -> Future:
        future: Future = Future()
        future.set_result(fn(*args, **kwargs))
        return future


@contextlib.contextmanager
def task_pool(
    workers: int, initializer: Callable[[], object] | None = None
) -> Iterator[Executor | Inline]:
    """A :class:`~concurrent.futures.ProcessPoolExecutor` of ``workers`` processes (each
    started with ``initializer``) for tasks submitted one by one, or :class:`Inline` for
    ``workers`` ≤ 1; on leaving, the tasks not started are cancelled and the pool waits for
    the running ones."""
    if workers <= 1:
        yield Inline()
        return
    pool = ProcessPoolExecutor(max_workers=workers, initializer=initializer)
    try:
        yield pool
    finally:
        pool.shutdown(cancel_futures=True)
