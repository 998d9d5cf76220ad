"""How many worker processes a parallel search uses: the machine's cores unless told."""

from __future__ import annotations

import multiprocessing as mp
import os
import warnings
from collections.abc import Callable
from multiprocessing.pool import Pool
from typing import Any


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
