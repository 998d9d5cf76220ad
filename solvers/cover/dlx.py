"""Dancing-links Algorithm X on flat int32 arrays (any target size).

Columns (items): one per piece type, then one per target cell. Kinds:

- *primary* (covered exactly once): mandatory cells and types used exactly once;
- *secondary* (at most once): optional cells and types used 0..1 times;
- *counter*: types with any other range ``[lo, hi]``; choosing a row increments the count, the
  column is covered (its remaining rows removed) when the count reaches ``hi``, and a full cover
  is a solution only if every count is at least ``lo``. Counters are never branched on, so each
  solution (a set of rows) is still found exactly once.

The search branches on the primary column with fewest rows (MRV, first in column order on
ties; type columns come first). ``nodes`` counts rows chosen, ``updates`` counts link removals
(Knuth's measure). Rows whose cells are all optional are dropped (they cannot be reached by
branching on mandatory cells).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from chaingeo.core.arrays import I32
from chaingeo.kernels.jit import njit
from chaingeo.solvers.cover import kernels as kn
from chaingeo.solvers.cover.problem import CoverProblem

PRIMARY, SECONDARY, COUNTER = 0, 1, 2


# Node layout (as in Knuth's dlx1): nodes 0..n_cols are the column headers; then each row's
# nodes lie contiguously, with a *spacer* before every row and after the last one. A spacer
# has ``TOP <= 0``; its ``U`` is the first node of the row before it and its ``D`` the last
# node of the row after it, so a row is walked by ``q += 1`` (or ``q -= 1``) with one jump at
# the spacer and no left/right links. Only the primary column headers are linked
# horizontally (``HL``/``HR``). Every kernel is compiled without bounds checks (numba's
# default, spelled out): the wrapper builds the arrays consistently.


@njit(cache=True, boundscheck=False)
def _cover(c: int, HL: Any, HR: Any, U: Any, D: Any, TOP: Any, S: Any) -> int:
    HL[HR[c]] = HL[c]
    HR[HL[c]] = HR[c]
    upd = 0
    i = D[c]
    while i != c:
        q = i + 1
        while q != i:
            x = TOP[q]
            if x <= 0:
                q = U[q]
                continue
            u = U[q]
            d = D[q]
            D[u] = d
            U[d] = u
            S[x] -= 1
            upd += 1
            q += 1
        i = D[i]
    return upd


@njit(cache=True, boundscheck=False)
def _uncover(c: int, HL: Any, HR: Any, U: Any, D: Any, TOP: Any, S: Any) -> None:
    i = U[c]
    while i != c:
        q = i - 1
        while q != i:
            x = TOP[q]
            if x <= 0:
                q = D[q]
                continue
            S[x] += 1
            U[D[q]] = q
            D[U[q]] = q
            q -= 1
        i = U[i]
    HL[HR[c]] = c
    HR[HL[c]] = c


@njit(cache=True, boundscheck=False)
def _select(
    r: int, HL: Any, HR: Any, U: Any, D: Any, TOP: Any, S: Any, kind: Any, hi: Any, cnt: Any
) -> int:
    upd = 0
    j = r + 1
    while j != r:
        c = TOP[j]
        if c <= 0:
            j = U[j]
            continue
        if kind[c] == COUNTER:
            cnt[c] += 1
            if cnt[c] == hi[c]:
                upd += _cover(c, HL, HR, U, D, TOP, S)
        else:
            upd += _cover(c, HL, HR, U, D, TOP, S)
        j += 1
    return upd


@njit(cache=True, boundscheck=False)
def _unselect(
    r: int, HL: Any, HR: Any, U: Any, D: Any, TOP: Any, S: Any, kind: Any, hi: Any, cnt: Any
) -> None:
    j = r - 1
    while j != r:
        c = TOP[j]
        if c <= 0:
            j = D[j]
            continue
        if kind[c] == COUNTER:
            if cnt[c] == hi[c]:
                _uncover(c, HL, HR, U, D, TOP, S)
            cnt[c] -= 1
        else:
            _uncover(c, HL, HR, U, D, TOP, S)
        j -= 1


@njit(cache=True, boundscheck=False)
def _choose(HR: Any, S: Any) -> int:
    best = 0
    best_size = 1 << 30
    c = HR[0]
    while c != 0:
        if S[c] < best_size:
            best = c
            best_size = S[c]
            if best_size <= 1:
                break
        c = HR[c]
    return best


class Links(NamedTuple):
    """The linked-list matrix (node layout above); ``HL``, ``HR``, ``U``, ``D``, ``S`` change
    during a search (:meth:`DLXArrays.fresh` copies them)."""

    HL: I32
    HR: I32
    U: I32
    D: I32
    TOP: I32
    RW: I32
    S: I32


class Columns(NamedTuple):
    """Per column: its kind (primary, secondary, counter) and count range; the counters
    that have a lower bound."""

    kind: I32
    lo: I32
    hi: I32
    counters: I32


@njit(cache=True, boundscheck=False, _nrt=False)
def dlx_run(links: Links, cols: Columns, lv: kn.Levels, ctl: kn.Control) -> int:
    """Run (or resume) the search (:func:`chaingeo.solvers.cover.kernels.depth_first` with the
    steps below); a level's branches are the rows of its column ``lv.aux[k]``."""
    return kn.depth_first(_root, _peek, _place, _back, (links, cols), lv, lv.chosen, links.RW, ctl)


@njit(cache=True, boundscheck=False, inline="always")
def _root(problem: Any, lv: kn.Levels, rng: Any, shuffle: bool) -> int:
    return _open(problem[0], lv, 0, _choose(problem[0].HR, problem[0].S), rng, shuffle)


@njit(cache=True, boundscheck=False, inline="always")
def _open(links: Links, lv: kn.Levels, k: int, c: int, rng: Any, shuffle: bool) -> int:
    """Level ``k`` branches on column ``c``'s rows (covered first); returns the link updates."""
    HL, HR, U, D, TOP, _, S = links
    upd = _cover(c, HL, HR, U, D, TOP, S)
    n = 0
    i = D[c]
    while i != c:
        lv.buf[k, n] = i
        n += 1
        i = D[i]
    kn.open_level(lv.buf, lv.nbuf, lv.pos, k, n, rng, shuffle)
    lv.aux[k] = c
    return upd


@njit(cache=True, boundscheck=False, inline="always")
def _peek(problem: Any, lv: kn.Levels, k: int, shuffle: bool) -> kn.Step:
    return kn.next_listed(lv.buf, lv.nbuf, lv.pos, k)


@njit(cache=True, boundscheck=False, inline="always")
def _place(problem: Any, lv: kn.Levels, k: int, r: int, rng: Any, shuffle: bool) -> kn.Step:
    """Select row ``r`` on level ``k``: a cover, a dead end, or level ``k + 1``."""
    (HL, HR, U, D, TOP, _, S), (kind, lo, hi, counters) = problem
    lv.pos[k] += 1
    upd = _select(r, HL, HR, U, D, TOP, S, kind, hi, lv.cnt)
    lv.chosen[k] = r
    c = _choose(HR, S)
    if c == 0 or S[c] == 0:
        ok = c == 0 and kn.counts_met(counters, lv.cnt, lo, -1)
        _unselect(r, HL, HR, U, D, TOP, S, kind, hi, lv.cnt)
        return (kn.COVER if ok else kn.DEAD), upd
    return kn.DOWN, upd + _open(problem[0], lv, k + 1, c, rng, shuffle)


@njit(cache=True, boundscheck=False, inline="always")
def _back(problem: Any, lv: kn.Levels, k: int) -> None:
    """Leave level ``k``: its column, then the row selected on level ``k - 1``."""
    (HL, HR, U, D, TOP, _, S), (kind, _, hi, _) = problem
    _uncover(lv.aux[k], HL, HR, U, D, TOP, S)
    if k > 0:
        _unselect(lv.chosen[k - 1], HL, HR, U, D, TOP, S, kind, hi, lv.cnt)


class DLXArrays:
    """The linked-list matrix of a problem restricted to a subset of its rows."""

    def __init__(self, problem: CoverProblem, rows: I32) -> None:
        T = len(problem.types)
        n_cells = problem.n_cells
        n_cols = T + n_cells
        kind = np.zeros(n_cols + 1, dtype=np.int32)
        lo = np.zeros(n_cols + 1, dtype=np.int32)
        hi = np.zeros(n_cols + 1, dtype=np.int32)
        for t, ty in enumerate(problem.types):
            h = t + 1
            lo[h], hi[h] = ty.lo, ty.hi
            if ty.lo == 1 and ty.hi == 1:
                kind[h] = PRIMARY
            elif ty.lo == 0 and ty.hi == 1:
                kind[h] = SECONDARY
            else:
                kind[h] = COUNTER
        optional = np.zeros(n_cells, dtype=bool)
        if problem.optional:
            optional[sorted(problem.optional)] = True
        kind[T + 1 :][optional] = SECONDARY
        kind[0] = -1
        # Drop rows lying entirely on optional cells.
        rows = np.asarray(rows, dtype=np.int32)
        ptr, flat = problem.row_ptr, problem.flat_cells
        if optional.any():
            keep = [not optional[flat[ptr[r] : ptr[r + 1]]].all() for r in rows]
            rows = rows[np.asarray(keep, dtype=bool)]
        sizes = (ptr[rows + 1] - ptr[rows]).astype(np.int64) + 1  # the type node + cells
        # Row i's nodes are first[i] : first[i] + sizes[i]; spacer i sits just before them.
        first = np.zeros(len(rows) + 1, dtype=np.int64)
        np.cumsum(sizes + 1, out=first[1:])
        first += n_cols + 2
        n_nodes = int(first[-1])  # the final spacer is n_nodes - 1
        TOP = np.zeros(n_nodes, dtype=np.int32)
        RW = np.full(n_nodes, -1, dtype=np.int32)
        U = np.arange(n_nodes, dtype=np.int32)
        D = np.arange(n_nodes, dtype=np.int32)
        TOP[: n_cols + 1] = np.arange(n_cols + 1, dtype=np.int32)
        for i, r in enumerate(rows):
            a = int(first[i])
            b = a + int(sizes[i])
            TOP[a] = problem.row_type[r] + 1
            TOP[a + 1 : b] = flat[ptr[r] : ptr[r + 1]] + T + 1
            RW[a:b] = r
            D[a - 1] = b - 1  # spacer before the row: its last node
            U[b] = a  # spacer after the row: its first node
        # Vertical lists: every column is header, then its nodes in row order, circular.
        is_node = np.zeros(n_nodes, dtype=bool)
        is_node[n_cols + 1 :] = TOP[n_cols + 1 :] > 0
        data = np.flatnonzero(is_node).astype(np.int32)
        order = data[np.argsort(TOP[data], kind="stable")]
        S = np.bincount(TOP[data], minlength=n_cols + 1).astype(np.int32)
        starts = np.searchsorted(TOP[order], np.arange(1, n_cols + 1))
        for h in range(1, n_cols + 1):
            seq = order[starts[h - 1] : starts[h - 1] + S[h]]
            chain = np.concatenate(([h], seq)).astype(np.int32)
            D[chain] = np.roll(chain, -1)
            U[chain] = np.roll(chain, 1)
        # Header list: primary columns only, in column order.
        HL = np.arange(n_cols + 1, dtype=np.int32)
        HR = np.arange(n_cols + 1, dtype=np.int32)
        prim = [0] + [h for h in range(1, n_cols + 1) if kind[h] == PRIMARY]
        pa = np.asarray(prim, dtype=np.int32)
        HR[pa] = np.roll(pa, -1)
        HL[pa] = np.roll(pa, 1)
        self.arrays = Links(HL, HR, U, D, TOP, RW, S)
        self.kind, self.lo, self.hi = kind, lo, hi
        self.counters = np.asarray(
            [h for h in range(1, n_cols + 1) if kind[h] == COUNTER and lo[h] > 0], dtype=np.int32
        )
        self.columns = Columns(kind, lo, hi, self.counters)
        self.max_depth = min(int(np.count_nonzero(kind == PRIMARY)), int(hi[1 : T + 1].sum()))
        self.max_col = int(S[1:].max()) if n_cols else 0
        self.has_primary = len(prim) > 1

    def fresh(self) -> Links:
        """Copies of the mutable arrays for one independent search."""
        HL, HR, U, D, TOP, RW, S = self.arrays
        return Links(HL.copy(), HR.copy(), U.copy(), D.copy(), TOP, RW, S.copy())
