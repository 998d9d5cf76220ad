"""A resumable exact-cover search over either engine, with counters and limits.

:class:`CoverSearch` owns the mutable state of one search (the numba kernels keep nothing
between calls), so a search can hand out solutions in batches, stop at a node limit, and be
resumed; engines are interchangeable behind it.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Literal

import numpy as np

from chaingeo.core.kinematics import SearchLimitError
from solvers import kernels
from solvers.bitboard import MAX_CELLS, BitboardArrays, bitboard_run
from solvers.dlx import DLXArrays, dlx_run
from solvers.placements import Int32Array
from solvers.problem import CoverError, CoverProblem

Engine = Literal["auto", "dlx", "bitboard"]
NO_LIMIT = np.iinfo(np.int64).max


@dataclass(frozen=True)
class CoverStats:
    """Search effort: rows placed (``nodes``), engine work units (``updates``), wall time."""

    nodes: int = 0
    updates: int = 0
    seconds: float = 0.0
    engine: str = ""

    def __add__(self, other: CoverStats) -> CoverStats:
        return CoverStats(
            self.nodes + other.nodes,
            self.updates + other.updates,
            self.seconds + other.seconds,
            self.engine or other.engine,
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


def choose_engine(problem: CoverProblem, engine: Engine) -> Literal["dlx", "bitboard"]:
    if engine == "auto":
        return "bitboard" if problem.n_cells <= MAX_CELLS else "dlx"
    if engine == "bitboard" and problem.n_cells > MAX_CELLS:
        raise CoverError(
            f"engine: bitboard needs at most {MAX_CELLS} cells, target has {problem.n_cells}"
        )
    if engine not in ("dlx", "bitboard"):
        raise CoverError(f"engine: expected auto, dlx or bitboard, got {engine!r}")
    return engine


def _arrays(problem: CoverProblem, rows: Int32Array, engine: str) -> DLXArrays | BitboardArrays:
    key = (engine, rows.tobytes())
    hit = problem._cache.get(key)
    if hit is None:
        hit = DLXArrays(problem, rows) if engine == "dlx" else BitboardArrays(problem, rows)
        if len(problem._cache) > 32:
            problem._cache.clear()
        problem._cache[key] = hit
    assert isinstance(hit, DLXArrays | BitboardArrays)
    return hit


class CoverSearch:
    """One depth-first search over ``rows`` of ``problem`` (all rows by default).

    ``rng`` (a :class:`numpy.random.Generator`) shuffles the branches at every node, which gives
    the solutions in a seeded random order; without it the order is fixed by the row order.
    """

    def __init__(
        self,
        problem: CoverProblem,
        rows: Int32Array | None = None,
        *,
        engine: Engine = "auto",
        rng: np.random.Generator | None = None,
        node_limit: int | None = None,
    ) -> None:
        if node_limit is not None and node_limit < 0:
            raise CoverError(f"node_limit: must be >= 0, got {node_limit}")
        self.problem = problem
        self.engine = choose_engine(problem, engine)
        if rows is None:
            rows = np.arange(problem.n_rows, dtype=np.int32)
        self.rows = np.ascontiguousarray(rows, dtype=np.int32)
        self.node_limit = NO_LIMIT if node_limit is None else int(node_limit)
        self._arr = _arrays(problem, self.rows, self.engine)
        depth = self._arr.max_depth + 1
        width = max(self._arr.max_col, 1)
        self._regs = kernels.new_regs()
        self._rng = np.zeros(1, dtype=np.uint64)
        self._shuffle = rng is not None
        if rng is not None:
            self._rng[0] = np.uint64(int(rng.integers(0, 2**63)))
        self._buf = np.zeros((depth, width if self.engine == "dlx" else 1), np.int32)
        self._nbuf = np.zeros(depth, dtype=np.int64)
        self._pos = np.zeros(depth, dtype=np.int64)
        self._aux = np.zeros(depth, dtype=np.int64)  # column (dlx) or candidate base (bitboard)
        self._chosen = np.zeros(depth, dtype=np.int32)
        self._depth = depth
        self._seconds = 0.0
        self._perm = np.zeros(depth * width if self._shuffle else depth, dtype=np.int32)
        if isinstance(self._arr, DLXArrays):
            self._links = self._arr.fresh()
            self._cnt = np.zeros(len(self._arr.kind), dtype=np.int32)
        else:
            self._occ = np.zeros(depth + 1, dtype=np.uint64)
            self._cnt = np.zeros(len(problem.types), dtype=np.int32)

    @property
    def stats(self) -> CoverStats:
        r = self._regs
        return CoverStats(
            int(r[kernels.REG_NODES]), int(r[kernels.REG_UPDATES]), self._seconds, self.engine
        )

    @property
    def found(self) -> int:
        """Solutions found so far."""
        return int(self._regs[kernels.REG_SOLUTIONS])

    @property
    def done(self) -> bool:
        return int(self._regs[kernels.REG_STATUS]) == kernels.DONE

    def _call(self, max_store: int, stop_after: int) -> Int32Array:
        out = np.zeros((max(max_store, 1), self._depth), dtype=np.int32)
        t0 = time.perf_counter()
        a = self._arr
        if isinstance(a, DLXArrays):
            L, R, U, D, C, RW, S = self._links
            n = dlx_run(
                L, R, U, D, C, RW, S, a.kind, a.lo, a.hi, self._cnt, a.counters,
                self._buf, self._nbuf, self._pos, self._aux, self._chosen,
                self._regs, self._rng, self._shuffle,
                out, max_store, stop_after, self.node_limit,
            )  # fmt: skip
        else:
            n = bitboard_run(
                a.mask, a.rtype, a.rid, a.cand_ptr, a.cand, a.skip,
                a.type_ptr, a.exact1, a.mrv_depth, a.primary,
                a.lo, a.hi, self._cnt, a.counters, a.table,
                a.nb, a.region_gcd, a.region_min,
                self._occ, self._perm, self._nbuf, self._pos, self._aux, self._chosen,
                self._regs, self._rng, self._shuffle,
                out, max_store, stop_after, self.node_limit,
            )  # fmt: skip
        self._seconds += time.perf_counter() - t0
        return out[:n]

    @property
    def limited(self) -> bool:
        return int(self._regs[kernels.REG_STATUS]) == kernels.LIMIT

    def _raise_limit(self) -> None:
        raise CoverLimitError(self.node_limit, self.found, self.stats)

    def count(self) -> int:
        """Run to the end and return the number of solutions found in total."""
        while not self.done:
            self._call(0, 0)
            if self.limited:
                self._raise_limit()
        return self.found

    def batches(self, size: int = 1024) -> Iterator[Int32Array]:
        """Solutions as arrays of row ids (``-1`` padded), at most ``size`` per batch.

        At the node limit the solutions found so far are yielded, then
        :class:`CoverLimitError` is raised.
        """
        while not self.done:
            block = self._call(size, 0)
            if len(block):
                yield block
            if self.limited:
                self._raise_limit()
