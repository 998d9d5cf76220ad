"""BurrTools' assemblies and their verdicts, the assembler's search tree cut into subtrees that
worker processes (or a Dask cluster) search and judge on their own.

Counting solutions asks one question of every assembly (does BurrTools' disassembler take it
apart?), and each answer depends on that assembly alone. A small problem (its search ends within
:data:`PROBE_NODES` nodes and :data:`PROBE_COVERS` covers) is enumerated and judged in the calling
process, in the search's order. A larger one is cut into subtrees
(:func:`chaingeo.solvers.cover.parallel.split_widest`, about :data:`PARTS`: many more than
workers, so that a worker that finishes early takes the next one); each worker enumerates its
subtree, keeps each class once (its canonical key) and judges it. The answers are merged in
subtree order, a class kept where it is first met, so the assemblies, their order and the figures
are the same bytes whatever the number of workers (one: the same subtrees in this process).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Generator, Iterable
from dataclasses import dataclass
from typing import Final, Protocol

import numpy as np

from chaingeo.core.arrays import I16, I32
from chaingeo.solvers.cover.constrained import Packing, canonical_keys
from chaingeo.solvers.cover.parallel import split_widest
from chaingeo.solvers.cover.problem import CoverProblem
from chaingeo.solvers.cover.search import CoverLimitError, CoverSearch
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.jobs import Farm, check_jobs, default_jobs, farm_map, poll_here, worker_cache

__all__ = ["Farm", "check_jobs", "default_jobs", "split_classes", "verdicts"]


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

#: A search that ends within these nodes and covers runs in the calling process, in its own
#: order (the cut depends on the problem only, never on the number of workers).
PROBE_NODES: Final = 20_000
PROBE_COVERS: Final = 2048
#: Subtrees a large search is cut into (the widest first).
PARTS: Final = 64
#: Verdicts between two looks at the deadline when a subtree is judged in this process.
POLL_EVERY: Final = 256

Verdict = tuple[I32, int, str | None]
Checks = tuple[StuckTest | None, VerdictSource | None]
#: How a worker builds its checks of the packing
#: (:class:`chaingeo.solvers.assembly.btcount.WorkerChecks`).
WorkerFactory = Callable[[], Checks]


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
    deadline: Deadline | None,
) -> Generator[Verdict, None, None]:
    """Every assembly of ``classes`` with its verdict, in order, in this process; the deadline
    is checked between verdicts."""
    for rows in classes:
        if deadline is not None:
            deadline.check()
        yield judge(rows, stuck, on_rows)


@dataclass(frozen=True)
class ClassSearch:
    """What a worker needs to enumerate and judge a subtree (picklable, for Dask): the cover
    problem, the symmetry maps whose least image names a class (rotations, and reflections
    when mirror images are one), the hole cap to apply (None: none, or in the rows) and how to
    build the checks."""

    problem: CoverProblem
    maps: I32
    max_holes: int | None
    row_variable: I32
    checks: WorkerFactory


@dataclass(frozen=True)
class Subtree:
    """A subtree's classes, each once, in its search's order: canonical keys, sorted rows (-1
    padded), verdict codes and level strings."""

    keys: I32
    rows: I32
    codes: I16
    levels: tuple[str | None, ...]
    cpu: float = 0.0  # CPU seconds the worker spent on it
    worker: int = 0  # the worker's process id


def large(problem: CoverProblem, rows: I32) -> bool:
    """Whether the search over ``rows`` is cut into subtrees (see the module's docstring)."""
    search = CoverSearch(problem, rows, node_limit=PROBE_NODES)
    try:
        search.count()
    except CoverLimitError:
        return True
    return search.found > PROBE_COVERS


def split_classes(
    plan: ClassSearch, rows: I32, farm: Farm, deadline: Deadline | None
) -> Generator[Verdict, None, None]:
    """Every class of the search over ``rows`` once, with its verdict, its subtrees searched on
    ``farm`` and merged in subtree order (a class where it is first met). The deadline is
    checked while waiting; its error ends the stream and stops the workers."""
    parts = split_widest(plan.problem, rows, "auto", PARTS)
    poll = None if deadline is None else deadline.check
    seen: set[bytes] = set()
    for sub in farm_map(subtree_classes, plan, parts, farm, poll):
        if deadline is not None:
            cpu = deadline.progress.workers
            cpu[sub.worker] = cpu.get(sub.worker, 0.0) + sub.cpu
        if not len(sub.codes):
            continue
        width = 4 * sub.keys.shape[1]
        keys: list[bytes] = np.ascontiguousarray(sub.keys).view(f"V{width}").ravel().tolist()
        for i, key in enumerate(keys):
            if key in seen:
                continue
            seen.add(key)
            r = sub.rows[i]
            yield r[r >= 0], int(sub.codes[i]), sub.levels[i]


def subtree_classes(plan: ClassSearch, rows: I32) -> Subtree:
    """The classes of one subtree, each once, judged (a worker's task)."""
    start = time.process_time()
    blocks = list(CoverSearch(plan.problem, rows).batches(4096))
    if not blocks:
        empty = np.zeros((0, 1), dtype=np.int32)
        return Subtree(empty, empty, np.zeros(0, dtype=np.int16), (), 0.0, os.getpid())
    block = np.concatenate(blocks)
    if plan.max_holes is not None:
        n_var = len(plan.problem.optional)
        covered = np.where(block >= 0, plan.row_variable[np.maximum(block, 0)], 0)
        block = block[n_var - covered.sum(axis=1) <= plan.max_holes]
    keys = canonical_keys(plan.maps, block)
    _, first = np.unique(keys, axis=0, return_index=True)
    first.sort()
    keys = keys[first]
    big = np.iinfo(np.int32).max
    rows_out = np.sort(np.where(block[first] < 0, big, block[first]), axis=1)
    rows_out[rows_out == big] = -1
    stuck, on_rows = worker_cache(plan, plan.checks)
    codes = np.zeros(len(first), dtype=np.int16)
    levels: list[str | None] = []
    for i, r in enumerate(rows_out):
        if i % POLL_EVERY == 0:
            poll_here()
        _, codes[i], level = judge(r[r >= 0], stuck, on_rows)
        levels.append(level)
    cpu = time.process_time() - start
    return Subtree(keys, rows_out, codes, tuple(levels), cpu, os.getpid())


def class_plan(packing: Packing, maps: I32, checks: WorkerFactory) -> ClassSearch:
    """The :class:`ClassSearch` of a packing, classes named by ``maps``."""
    max_holes = packing.spec.max_holes if packing.hole_type < 0 else None  # else in the rows
    variable = np.asarray(packing.row_variable, dtype=np.int32)
    return ClassSearch(packing.problem, maps, max_holes, variable, checks)
