"""How many worker processes a parallel search uses: the machine's cores unless told."""

from __future__ import annotations

import os


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
