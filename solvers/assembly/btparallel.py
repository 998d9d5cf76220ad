"""BurrTools' verdicts on a stream of assemblies, on worker processes, in the stream's order.

Counting solutions asks one question of every assembly (does BurrTools' disassembler take it
apart?), and each answer depends on that assembly alone. So the enumeration stays one search in
the calling process, in its fixed order, and the questions go out in batches to ``jobs`` worker
processes (each holds its own :class:`chaingeo.solvers.assembly.btcount.RowVerdicts`); answers
come back and are handed on in the order the assemblies were found. The figures are therefore
the same bytes whatever ``jobs`` is: only the wall time changes.

The first :data:`SERIAL_ASSEMBLIES` assemblies are always answered in the calling process: a
small problem is done before a worker would have started. Workers are forked (they inherit the
compiled kernels); where fork is unavailable they are spawned.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Generator, Iterable, Iterator
from multiprocessing.pool import AsyncResult, Pool
from typing import Final, Protocol

from chaingeo.core.arrays import I32
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.jobs import check_jobs, default_jobs, fork_pool

__all__ = ["check_jobs", "default_jobs", "verdicts"]


class StuckTest(Protocol):
    """Whether nothing can move in an assembly (its rows)."""

    def __call__(self, rows: I32) -> bool: ...


class VerdictSource(Protocol):
    """BurrTools' verdict on an assembly (None: not decided here) and its level string."""

    level: str | None

    def verdict(self, rows: I32) -> bool | None: ...


#: What is known of one assembly: nothing can move, BurrTools' disassembler does not take it
#: apart, it does, or the fast path cannot say (the general path decides).
STUCK: Final = 0
NO: Final = 1
YES: Final = 2
UNKNOWN: Final = 3

#: Assemblies answered in the calling process before any worker starts.
SERIAL_ASSEMBLIES: Final = 2048
#: Assemblies sent to a worker at a time, and batches in flight per worker.
BATCH: Final = 512
IN_FLIGHT: Final = 3
#: Seconds between two looks at the deadline while waiting for a worker.
POLL_SECONDS: Final = 0.05

Verdict = tuple[I32, int, str | None]
#: How a worker builds its checks of the packing
#: (:class:`chaingeo.solvers.assembly.btcount.WorkerChecks`).
WorkerFactory = Callable[[], tuple[StuckTest, VerdictSource]]


def judge(rows: I32, stuck: StuckTest | None, on_rows: VerdictSource | None) -> Verdict:
    """One assembly's verdict in this process (``stuck`` None: piece groups, where a part may
    be done without moving)."""
    if stuck is not None and stuck(rows):
        return rows, STUCK, None
    if on_rows is None:
        return rows, UNKNOWN, None
    v = on_rows.verdict(rows)
    return rows, (UNKNOWN if v is None else YES if v else NO), on_rows.level


def verdicts(
    classes: Iterable[I32],
    stuck: StuckTest | None,
    on_rows: VerdictSource | None,
    *,
    jobs: int,
    deadline: Deadline | None,
    worker: WorkerFactory | None = None,
) -> Generator[Verdict, None, None]:
    """Every assembly of ``classes`` with its verdict, in order: in this process, and with
    ``jobs`` > 1 and ``worker`` (how a worker builds its checks) past the first
    :data:`SERIAL_ASSEMBLIES` on worker processes. The deadline is checked between verdicts and
    while waiting; a worker's error is raised here."""
    it = iter(classes)
    for i, rows in enumerate(it):
        if deadline is not None:
            deadline.check()
        yield judge(rows, stuck, on_rows)
        if i + 1 >= SERIAL_ASSEMBLIES and jobs > 1 and worker is not None:
            yield from _on_workers(it, jobs, deadline, worker)
            return


def _on_workers(
    it: Iterator[I32],
    jobs: int,
    deadline: Deadline | None,
    worker: WorkerFactory,
) -> Generator[Verdict, None, None]:
    """The rest of ``it`` on ``jobs`` worker processes, answers in order."""
    pool = _pool(jobs, worker)
    pending: deque[tuple[list[I32], AsyncResult[list[tuple[int, str | None]]]]] = deque()
    try:
        done = False
        while not done or pending:
            while not done and len(pending) < IN_FLIGHT * jobs:
                batch = _take(it, BATCH)
                done = len(batch) < BATCH
                if batch:
                    pending.append((batch, pool.apply_async(_answer, (batch,))))
            if not pending:
                break
            batch, result = pending.popleft()
            while not result.ready():
                if deadline is not None:
                    deadline.check()
                result.wait(POLL_SECONDS)
            for rows, (code, level) in zip(batch, result.get(), strict=True):
                yield rows, code, level
    finally:
        pool.terminate()
        pool.join()


def _take(it: Iterator[I32], n: int) -> list[I32]:
    out: list[I32] = []
    for rows in it:
        out.append(rows)
        if len(out) == n:
            break
    return out


def _pool(jobs: int, worker: WorkerFactory) -> Pool:
    """``jobs`` processes, each with the checks ``worker`` builds (forked where possible: the
    compiled kernels and the packing come along)."""
    return fork_pool(jobs, _start, (worker,))


_CHECKS: list[tuple[StuckTest, VerdictSource]] = []


def _start(worker: WorkerFactory) -> None:
    _CHECKS[:] = [worker()]


def _answer(batch: list[I32]) -> list[tuple[int, str | None]]:
    stuck, on_rows = _CHECKS[0]
    return [judge(rows, stuck, on_rows)[1:] for rows in batch]
