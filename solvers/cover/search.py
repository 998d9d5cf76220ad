"""A resumable exact-cover search over either engine, with counters and limits.

:class:`CoverSearch` owns the mutable state of one search (the numba kernels keep nothing
between calls), so a search can hand out solutions in batches, stop at a node limit, and be
resumed; engines are interchangeable behind it.

*Deadline*: a kernel cannot read the clock, so with a :class:`chaingeo.solvers.deadline.Deadline`
the search runs in *slices*: each kernel call gets a node budget (its node limit is the nodes so far
plus the budget; every kernel stops at a node boundary and resumes exactly there), and the
deadline is checked before every slice. The budget adapts so that a slice takes about
:data:`SLICE_SECONDS` (doubled while slices are quicker than half of it, halved when slower than
twice it), starting from :data:`FIRST_SLICE` nodes: a kernel call costs ~4 us, so the clock
costs well under 0.1 % and the search stops within a few slices of the deadline. Solutions and
their order do not depend on the slicing. Without a deadline (or one of ``None`` seconds) the
kernel runs in one call, as before.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Literal

import numpy as np

from chaingeo.core.arrays import I32
from chaingeo.core.kinematics import SearchLimitError
from chaingeo.solvers.cover import kernels
from chaingeo.solvers.cover.bitboard import MAX_CELLS, BitboardArrays, bitboard_run
from chaingeo.solvers.cover.bitmrv import MRVArrays, mrv_run
from chaingeo.solvers.cover.boxmrv import BoxArrays, box_run
from chaingeo.solvers.cover.dlx import DLXArrays, dlx_run
from chaingeo.solvers.cover.problem import CoverError, CoverProblem
from chaingeo.solvers.deadline import Deadline

Engine = Literal["auto", "dlx", "bitboard", "bitboard-first", "bitboard-mrv"]
Kernel = Literal["dlx", "bitboard-first", "bitboard-mrv"]
ENGINES: tuple[str, ...] = ("auto", "dlx", "bitboard", "bitboard-first", "bitboard-mrv")
NO_LIMIT = np.iinfo(np.int64).max
#: Wall time one slice of a search under a deadline aims at, and the node budget of its first
#: slice (one node of a wide MRV search over a large problem may take ~0.1 ms).
SLICE_SECONDS = 0.01
FIRST_SLICE = 256
MAX_SLICE = 1 << 40


@dataclass(frozen=True)
class CoverStats:
    """Search effort: rows placed (``nodes``), engine work units (``updates``), wall time."""

    nodes: int = 0
    updates: int = 0
    seconds: float = 0.0
    engine: str = ""
    kernel: str = ""  # the kernel that ran: dlx, bitboard-first or bitboard-mrv

    def __add__(self, other: CoverStats) -> CoverStats:
        return CoverStats(
            self.nodes + other.nodes,
            self.updates + other.updates,
            self.seconds + other.seconds,
            self.engine or other.engine,
            self.kernel or other.kernel,
        )


class CoverLimitError(SearchLimitError):
    """The node limit was reached; ``solutions`` found so far and ``stats`` are attached."""

    def __init__(self, limit: int, solutions: int, stats: CoverStats) -> None:
        super().__init__(
            f"exact-cover search stopped at its node limit of {limit} after {solutions} "
            "solution(s); raise node_limit (or pass None) to search further"
        )
        self.limit = limit
        self.solutions = solutions
        self.stats = stats


def auto_kernel(problem: CoverProblem) -> Kernel:
    """The kernel of ``engine="auto"`` (and ``"bitboard"``): the first empty cell in scan order
    for one-layer targets of at most 64 cells, the most constrained cell (MRV) otherwise.

    In a layer the first empty cell sits on the edge of the filled part, so it already has few
    fits, and it is found with one bit scan; in thicker targets that cell has many fits and MRV
    cuts the tree 13-fold (46.4 M to 3.4 M nodes on the 2x5x6 solid pentominoes). Since the
    one-word MRV kernel reads its rows in order (:mod:`chaingeo.solvers.cover.boxmrv`) it wins
    the unreduced planar counts too, but not the symmetry-reduced ones that ``chain cover``
    runs. Measured CPU seconds on a loaded machine, first / MRV: Soma 0.045 / 0.039 reduced,
    0.083 / 0.066 raw; 2x5x6 0.79 / 0.30 reduced, 14.5 / 1.8 raw; pentominoes 6x10 0.25 /
    0.36 reduced, 1.92 / 1.38 raw; 5x12 0.16 / 0.25 reduced, 1.08 / 0.68 raw.
    """
    flat = min(problem.target.extent) == 1
    return "bitboard-first" if flat and problem.n_cells <= MAX_CELLS else "bitboard-mrv"


def choose_kernel(problem: CoverProblem, engine: Engine) -> Kernel:
    """The kernel an engine name runs on ``problem`` (``auto`` and ``bitboard``: the
    bit-board, with the branching of :func:`auto_kernel`)."""
    if engine not in ENGINES:
        raise CoverError(f"engine: expected one of {', '.join(ENGINES)}, got {engine!r}")
    if engine == "bitboard-first" and problem.n_cells > MAX_CELLS:
        raise CoverError(
            f"engine: bitboard-first needs at most {MAX_CELLS} cells, target has {problem.n_cells}"
        )
    if engine == "dlx":
        return "dlx"
    if engine in ("bitboard-first", "bitboard-mrv"):
        return engine
    return auto_kernel(problem)


def choose_engine(problem: CoverProblem, engine: Engine) -> Literal["dlx", "bitboard"]:
    """The engine family (``dlx`` or ``bitboard``) an engine name runs on ``problem``."""
    return "dlx" if choose_kernel(problem, engine) == "dlx" else "bitboard"


Arrays = DLXArrays | BitboardArrays | MRVArrays | BoxArrays


def _arrays(problem: CoverProblem, rows: I32, kernel: Kernel) -> Arrays:
    key = (kernel, rows.tobytes())
    hit = problem._cache.get(key)
    if hit is None:
        if kernel == "dlx":
            hit = DLXArrays(problem, rows)
        elif kernel == "bitboard-first":
            hit = BitboardArrays(problem, rows)
        elif problem.n_cells <= MAX_CELLS:
            hit = BoxArrays(problem, rows)
        else:
            hit = MRVArrays(problem, rows)
        if len(problem._cache) > 32:
            problem._cache.clear()
        problem._cache[key] = hit
    assert isinstance(hit, DLXArrays | BitboardArrays | MRVArrays | BoxArrays)
    return hit


class CoverSearch:
    """One depth-first search over ``rows`` of ``problem`` (all rows by default).

    ``rng`` (a :class:`numpy.random.Generator`) shuffles the branches at every node, which gives
    the solutions in a seeded random order; without it the order is fixed by the row order.
    ``deadline``: past it, :meth:`count` and :meth:`batches` raise its :class:`SearchLimitError`
    (``batches`` first yields the solutions found so far); the search can then be resumed
    under a new :attr:`deadline`. ``slice_nodes`` fixes the node budget of a slice (tests).
    """

    def __init__(
        self,
        problem: CoverProblem,
        rows: I32 | None = None,
        *,
        engine: Engine = "auto",
        rng: np.random.Generator | None = None,
        node_limit: int | None = None,
        deadline: Deadline | None = None,
        slice_nodes: int | None = None,
    ) -> None:
        if node_limit is not None and node_limit < 0:
            raise CoverError(f"node_limit: must be >= 0, got {node_limit}")
        if slice_nodes is not None and slice_nodes < 1:
            raise CoverError(f"slice_nodes: must be >= 1, got {slice_nodes}")
        self.deadline = deadline
        self._fixed_slice = slice_nodes
        self._slice = FIRST_SLICE if slice_nodes is None else int(slice_nodes)
        self._expired = False
        self.problem = problem
        self.kernel = choose_kernel(problem, engine)
        self.engine = "dlx" if self.kernel == "dlx" else "bitboard"
        if rows is None:
            rows = np.arange(problem.n_rows, dtype=np.int32)
        self.rows = np.ascontiguousarray(rows, dtype=np.int32)
        self.node_limit = NO_LIMIT if node_limit is None else int(node_limit)
        self._arr = _arrays(problem, self.rows, self.kernel)
        depth = self._arr.max_depth + 1
        width = max(self._arr.max_col, 1)
        self._regs = kernels.new_regs()
        self._rng = np.zeros(1, dtype=np.uint64)
        self._shuffle = rng is not None
        if rng is not None:
            self._rng[0] = np.uint64(int(rng.integers(0, 2**63)))
        self._buf = np.zeros((depth, width if self.kernel != "bitboard-first" else 1), np.int32)
        self._nbuf = np.zeros(depth, dtype=np.int64)
        self._pos = np.zeros(depth, dtype=np.int64)
        self._aux = np.zeros(depth, dtype=np.int64)  # column (dlx) or candidate base (bitboard)
        self._chosen = np.zeros(depth, dtype=np.int32)
        self._depth = depth
        self._seconds = 0.0
        self._perm = np.zeros(depth * width if self._shuffle else depth, dtype=np.int32)
        a = self._arr
        if isinstance(a, DLXArrays):
            self._links = a.fresh()
            self._cnt = np.zeros(len(a.kind), dtype=np.int32)
        elif isinstance(a, BitboardArrays):
            self._occ = np.zeros(depth + 1, dtype=np.uint64)
            self._cnt = np.zeros(len(problem.types), dtype=np.int32)
        elif isinstance(a, BoxArrays):
            self._box = a.stack(depth, len(problem.types))
        else:
            self._stack = a.stack(depth, len(problem.types))
            self._wide = a.wide(depth)

    @property
    def stats(self) -> CoverStats:
        r = self._regs
        return CoverStats(
            int(r[kernels.REG_NODES]),
            int(r[kernels.REG_UPDATES]),
            self._seconds,
            self.engine,
            self.kernel,
        )

    @property
    def found(self) -> int:
        """Solutions found so far."""
        return int(self._regs[kernels.REG_SOLUTIONS])

    @property
    def done(self) -> bool:
        return int(self._regs[kernels.REG_STATUS]) == kernels.DONE

    def _kernel(self, out: I32, max_store: int, stop_after: int, node_limit: int) -> int:
        """One call of the search's kernel up to ``node_limit`` nodes in total; solutions go to
        ``out`` (see :func:`chaingeo.solvers.cover.kernels.depth_first`)."""
        a = self._arr
        ctl = kernels.Control(
            self._regs, self._rng, self._shuffle, out, max_store, stop_after, node_limit
        )
        if isinstance(a, DLXArrays):
            lv = kernels.Levels(
                self._cnt, self._buf, self._nbuf, self._pos, self._aux, self._chosen
            )
            return dlx_run(self._links, a.columns, lv, ctl)
        if isinstance(a, BitboardArrays):
            lv = kernels.Levels(
                self._cnt, self._perm, self._nbuf, self._pos, self._aux, self._chosen
            )
            return bitboard_run(a.rows, self._occ, lv, ctl)
        if isinstance(a, BoxArrays):
            return box_run(a.rows, self._box, ctl)
        return mrv_run(a.rows, self._stack, ctl, self._wide)

    def _call(self, max_store: int, stop_after: int) -> I32:
        out = np.zeros((max(max_store, 1), self._depth), dtype=np.int32)
        t0 = time.perf_counter()
        self._expired = False
        if self.deadline is None or not self.deadline.bounded:
            n = self._kernel(out, max_store, stop_after, self.node_limit)
        else:
            n = self._sliced(self.deadline, out, max_store, stop_after)
        self._seconds += time.perf_counter() - t0
        return out[:n]

    def _sliced(self, deadline: Deadline, out: I32, max_store: int, stop_after: int) -> int:
        """:meth:`_kernel` in slices of :attr:`_slice` nodes, the deadline checked before each:
        returns the solutions stored, with :attr:`_expired` set when the deadline passed."""
        regs = self._regs
        n = 0
        found = self.found
        while True:
            if deadline.expired():
                self._expired = True
                return n
            cap = min(self.node_limit, int(regs[kernels.REG_NODES]) + self._slice)
            store = max_store - n if max_store > 0 else 0
            after = stop_after - (self.found - found) if stop_after > 0 else 0
            t0 = time.perf_counter()
            n += self._kernel(out[n:], store, after, cap)
            if int(regs[kernels.REG_STATUS]) != kernels.LIMIT or cap == self.node_limit:
                return n  # done, the batch is full, or the search's own node limit
            if self._fixed_slice is None:  # a whole slice was spent: adapt its budget
                dt = time.perf_counter() - t0
                if dt < SLICE_SECONDS / 2:
                    self._slice = min(2 * self._slice, MAX_SLICE)
                elif dt > 2 * SLICE_SECONDS:
                    self._slice = max(self._slice // 2, 1)

    def _time_error(self) -> SearchLimitError:
        assert self.deadline is not None
        return self.deadline.error(
            f"the exact-cover search ({self.stats.nodes} nodes, {self.found} solutions so far)"
        )

    @property
    def limited(self) -> bool:
        """Whether the search stopped at its node limit (not at the end of a slice)."""
        r = self._regs
        return int(r[kernels.REG_STATUS]) == kernels.LIMIT and int(r[kernels.REG_NODES]) >= (
            self.node_limit
        )

    def _raise_limit(self) -> None:
        raise CoverLimitError(self.node_limit, self.found, self.stats)

    def count(self) -> int:
        """Run to the end and return the number of solutions found in total."""
        while not self.done:
            self._call(0, 0)
            if self._expired:
                raise self._time_error()
            if self.limited:
                self._raise_limit()
        return self.found

    def batches(self, size: int = 1024) -> Iterator[I32]:
        """Solutions as arrays of row ids (``-1`` padded), at most ``size`` per batch.

        At the node limit the solutions found so far are yielded, then
        :class:`CoverLimitError` is raised; past the deadline likewise, then the deadline's
        :class:`SearchLimitError` (it names ``seconds``).
        """
        while not self.done:
            block = self._call(size, 0)
            if len(block):
                yield block
            if self._expired:
                raise self._time_error()
            if self.limited:
                self._raise_limit()
