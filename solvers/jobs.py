"""How many worker processes a parallel search uses, and the one ordered map that farms its
subtrees out: to forked local processes, or to a Dask cluster (``scheduler``), results in task
order whatever the number of workers, so the figures built from them are the same bytes."""

from __future__ import annotations

import importlib
import multiprocessing as mp
import os
import threading
import time
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from multiprocessing import TimeoutError as PoolTimeout
from multiprocessing.pool import Pool
from typing import Any, Final, Generic, TypeVar

S = TypeVar("S")
T = TypeVar("T")
R = TypeVar("R")

#: Seconds between two looks at the caller's deadline while waiting for a worker.
POLL_SECONDS: Final = 0.05


def default_jobs() -> int:
    """The cores this process may run on (``os.process_cpu_count``, else its affinity)."""
    count = getattr(os, "process_cpu_count", None)
    if count is not None:
        n = count()
    elif hasattr(os, "sched_getaffinity"):
        n = len(os.sched_getaffinity(0))
    else:
        n = os.cpu_count()
    return max(1, int(n or 1))


def check_jobs(jobs: int | None) -> int:
    """``jobs`` as a number of processes (None: :func:`default_jobs`); ValueError below 1."""
    if jobs is None:
        return default_jobs()
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise ValueError(f"jobs: expected a positive number of processes, got {jobs!r}")
    return jobs


def fork_pool(jobs: int, start: Callable[..., None], args: tuple[Any, ...]) -> Pool:
    """``jobs`` worker processes, each first running ``start(*args)``: forked where the platform
    can (they inherit the compiled kernels and the problem, nothing is pickled), else spawned.
    Workers never print nor start threads, so forking from a process whose progress thread
    runs is safe here; Python 3.12's warning about it is silenced."""
    method = "fork" if "fork" in mp.get_all_start_methods() else "spawn"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        return mp.get_context(method).Pool(jobs, initializer=start, initargs=args)


@dataclass(frozen=True)
class Farm:
    """Where subtrees are searched: ``jobs`` local processes (1: this process), or the Dask
    cluster at ``scheduler`` (then ``jobs`` is not used)."""

    jobs: int = 1
    scheduler: str | None = None

    @property
    def parallel(self) -> bool:
        return self.jobs > 1 or self.scheduler is not None


def as_farm(jobs: int | Farm | None, scheduler: str | None = None) -> Farm:
    """``jobs`` as a :class:`Farm` (a number of processes, None: :func:`default_jobs`; a Farm
    as it is); ``scheduler``: a Dask cluster's address instead."""
    if isinstance(jobs, Farm):
        return jobs if scheduler is None else Farm(jobs.jobs, scheduler)
    return Farm(check_jobs(jobs), scheduler)


@dataclass(frozen=True)
class _Call(Generic[S, T, R]):
    fn: Callable[[S, T], R]
    state: S


#: The task function and its state in a local worker process (set by :func:`_start`).
_LOCAL: list[Any] = []


def _start(call: _Call[Any, Any, Any]) -> None:
    _LOCAL[:] = [call]


def _run_local(task: Any) -> Any:
    call = _LOCAL[0]
    return call.fn(call.state, task)


def _run_remote(fn: Callable[[Any, Any], Any], state: Any, task: Any) -> Any:
    return fn(state, task)


def farm_map(
    fn: Callable[[S, T], R],
    state: S,
    tasks: Sequence[T],
    farm: Farm,
    poll: Callable[[], None] | None = None,
) -> Iterator[R]:
    """``fn(state, task)`` of every task, yielded in task order. Workers take the next task as
    they finish one (many small tasks balance the load); ``state`` reaches each worker once
    (inherited by a fork, or scattered to the cluster). ``poll`` is called while waiting (a
    deadline's check: what it raises ends the map and stops the workers). ``fn`` must be a
    module-level function; it may keep what it derives from ``state`` per worker
    (:func:`worker_cache`)."""
    if farm.scheduler is not None:
        yield from _dask_map(fn, state, tasks, farm.scheduler, poll)
    elif farm.jobs <= 1 or len(tasks) <= 1:
        for task in tasks:
            if poll is not None:
                poll()
            _POLL.fn = poll
            try:
                out = fn(state, task)
            finally:
                _POLL.fn = None
            yield out
    else:
        yield from _pool_map(fn, state, tasks, farm.jobs, poll)


def _pool_map(
    fn: Callable[[S, T], R],
    state: S,
    tasks: Sequence[T],
    jobs: int,
    poll: Callable[[], None] | None,
) -> Iterator[R]:
    pool = fork_pool(min(jobs, len(tasks)), _start, (_Call(fn, state),))
    try:
        results = pool.imap(_run_local, tasks, chunksize=1)
        for _ in range(len(tasks)):
            while True:
                try:
                    out: R = results.next(POLL_SECONDS)
                    break
                except PoolTimeout:
                    if poll is not None:
                        poll()
            yield out
    finally:
        pool.terminate()
        pool.join()


def _dask_map(
    fn: Callable[[S, T], R],
    state: S,
    tasks: Sequence[T],
    address: str,
    poll: Callable[[], None] | None,
) -> Iterator[R]:
    distributed = dask_distributed()
    with distributed.Client(address, set_as_default=False) as client:
        shared = client.scatter(state, broadcast=True, hash=False)
        futures = [client.submit(_run_remote, fn, shared, t, pure=False) for t in tasks]
        try:
            for fut in futures:
                while not fut.done():
                    if poll is not None:
                        poll()
                    time.sleep(POLL_SECONDS)
                yield fut.result()
        finally:
            client.cancel(futures)


def dask_distributed() -> Any:
    """The ``distributed`` package (the ``cluster`` extra), untyped: its annotations are partial."""
    try:
        return importlib.import_module("distributed")
    except ImportError:
        raise RuntimeError(
            "--scheduler needs the cluster extra: pip install 'chaingeo[cluster]'"
        ) from None


_CACHE = threading.local()
_POLL = threading.local()


def poll_here() -> None:
    """The caller's deadline check when a task runs in the caller's own process (a no-op on a
    worker: there the caller stops the workers itself)."""
    poll: Callable[[], None] | None = getattr(_POLL, "fn", None)
    if poll is not None:
        poll()


def worker_cache(state: object, build: Callable[[], R]) -> R:
    """What ``build`` derives from ``state``, built once per worker thread and state (Dask's
    threads share scattered objects; the derived checks keep per-call scratch)."""
    cache: dict[int, tuple[object, Any]] = getattr(_CACHE, "d", None) or {}
    _CACHE.d = cache
    hit = cache.get(id(state))
    if hit is None or hit[0] is not state:
        cache.clear()  # one state at a time: the previous search is over
        hit = cache[id(state)] = (state, build())
    out: R = hit[1]
    return out
