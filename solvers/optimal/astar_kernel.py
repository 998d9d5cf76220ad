"""The numba side of :mod:`chaingeo.solvers.optimal.astar`: heuristic, heap, expansion, and the
resumable loop.

A whole state is one ``int16`` row of ``4 n``: ``row[i]`` is the label of piece ``i``'s part
(its smallest piece index), ``row[n + 3 i + t]`` its offset relative to that piece. The loop
(:func:`run_astar`) keeps everything in arrays owned by :class:`AStarRun` and returns a status when
a buffer is full, a pattern-database entry is missing, a batch is done (so Python can check
the deadline) or the search ends; the next call resumes where it stopped (a node whose
expansion was cut short is expanded again from scratch; its children already stored are found
again with the same ``g`` and change nothing).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from chaingeo.core.arrays import I16, I32, I64, U8
from chaingeo.core.kinematics import SearchLimitError
from chaingeo.kernels.jit import entry, njit
from chaingeo.solvers.motion import kinematics_kernel as mv
from chaingeo.solvers.optimal.pattern_db import DEAD, KEY_WIDTH, lookup

if TYPE_CHECKING:
    from chaingeo.solvers.deadline import Deadline
    from chaingeo.solvers.motion.partsearch import PieceTable
    from chaingeo.solvers.optimal.pattern_db import PatternDB


@dataclass(frozen=True)
class AStarLimits:
    """Caps; each raises :class:`SearchLimitError` naming itself. ``max_states``: whole states
    stored by A*; ``max_expansions``: states expanded; ``pdb_states``: pattern database
    entries; ``component_states``: states of one sub-puzzle search; ``seconds``: wall clock."""

    max_states: int = 4_000_000
    max_expansions: int | None = None
    pdb_states: int = 20_000_000
    component_states: int = 4_000_000
    seconds: float | None = 300.0
    group_limit: int = 4096


FOUND, EXHAUSTED, NEED_STATES, NEED_HEAP, NEED_PDB, NEED_MOVES, YIELD, LIMIT, GROUPS = range(9)
# Registers shared with Python.
R_CUR, R_STATES, R_HEAP, R_EXPANDED, R_REOPENED, R_BOUND, R_GOAL = range(7)
N_REGS = 7
_GBITS = 20  # heap key: f << 20 | (2^20 - 1 - g): smaller f first, then larger g


class PDBView(NamedTuple):
    """A pattern database as the kernel reads it (:class:`PatternDB`'s arrays of the moment),
    with the key scratch and where a missing entry's key is written."""

    fam: I64
    n_fam: int
    keys: I16
    vals: I32
    hash: I64
    key: I16
    miss: I16


def pdb_view(pdb: PatternDB, miss: I16) -> PDBView:
    """The view of ``pdb`` now (its arrays are replaced as it grows)."""
    key = np.zeros(KEY_WIDTH, dtype=np.int16)
    return PDBView(pdb.fam, pdb.n_family, pdb.keys, pdb.vals, pdb.hash, key, miss)


class Nodes(NamedTuple):
    """The stored states (:class:`AStarRun`'s arrays): ``rows`` and their hash ``table``; per node
    ``g``, ``h``, the active part's ``h``, ``f``, the parent and the move from it (group mask,
    direction, ``k``; 0 for a removal), and whether it is closed."""

    rows: I16
    gv: I32
    hv: I32
    hact: I32
    fv: I32
    parent: I64
    mmask: I64
    mdir: I64
    mk: I64
    closed: U8
    table: I64


class Heap(NamedTuple):
    """The open list: a binary heap of keys (:func:`_heap_key`) and their nodes."""

    key: I64
    node: I64


#: The pieces' voxels and boxes, the group caps and the buffers of
#: :func:`chaingeo.solvers.motion.kinematics_kernel.node_moves` (the bundle every search kernel
#: takes).
Pieces = mv.Pieces


@njit(cache=True)
def part_h(row: I16, n: int, label: int, size: int, pdb: PDBView) -> int:
    """The term of one part (module docstring of :mod:`chaingeo.solvers.optimal.astar`); -1 when a
    pattern database entry is missing (its key is written to ``pdb.miss``), ``DEAD`` when some
    subset can never come apart."""
    fam, n_fam, keys, vals, table, key, miss = pdb
    return _part_h(row, n, label, size, fam, n_fam, keys, vals, table, key, miss)


@njit(cache=True)
def _part_h(
    row: I16, n: int, label: int, size: int, fam: I64, n_fam: int, keys: I16, vals: I32,
    table: I64, key: I16, miss: I16,
) -> int:  # fmt: skip
    """:func:`part_h` on :class:`PDBView`'s fields. The expansion calls it per child with the
    fields taken out once per node: a bundle passed per call and unpacked in the callee costs a
    reference count per array per call (with :func:`_store`'s, 9% of a small A* search)."""
    if size < 2:
        return 0
    h = size - 1
    for f in range(n_fam):
        a = fam[f, 0]
        b = fam[f, 1]
        c = fam[f, 2]
        if row[a] != label or row[b] != label:
            continue
        m = 2
        if c >= 0:
            if row[c] != label:
                continue
            m = 3
        key[0] = f
        for t in range(3):
            key[1 + t] = row[n + 3 * b + t] - row[n + 3 * a + t]
            key[4 + t] = row[n + 3 * c + t] - row[n + 3 * a + t] if m == 3 else 0
        idx = lookup(keys, table, key)
        if idx < 0:
            for t in range(KEY_WIDTH):
                miss[t] = key[t]
            return -1
        g = vals[idx]
        if g >= DEAD:
            return DEAD
        v = g + size - m
        if v > h:
            h = v
    return h


@njit(cache=True)
def _push(hkey: I64, hnode: I64, size: int, key: int, node: int) -> int:
    i = size
    hkey[i] = key
    hnode[i] = node
    while i > 0:
        p = (i - 1) // 2
        if hkey[p] < hkey[i] or (hkey[p] == hkey[i] and hnode[p] <= hnode[i]):
            break
        hkey[p], hkey[i] = hkey[i], hkey[p]
        hnode[p], hnode[i] = hnode[i], hnode[p]
        i = p
    return size + 1


@njit(cache=True)
def _pop(hkey: I64, hnode: I64, size: int) -> int:
    size -= 1
    hkey[0] = hkey[size]
    hnode[0] = hnode[size]
    i = 0
    while True:
        lft = 2 * i + 1
        if lft >= size:
            break
        c = lft
        r = lft + 1
        if r < size and (hkey[r] < hkey[lft] or (hkey[r] == hkey[lft] and hnode[r] < hnode[lft])):
            c = r
        if hkey[i] < hkey[c] or (hkey[i] == hkey[c] and hnode[i] <= hnode[c]):
            break
        hkey[c], hkey[i] = hkey[i], hkey[c]
        hnode[c], hnode[i] = hnode[i], hnode[c]
        i = c
    return size


@njit(cache=True)
def _heap_key(g: int, h: int) -> int:
    return ((g + h) << _GBITS) | ((1 << _GBITS) - 1 - g)


@njit(cache=True)
def _next_node(regs: I64, nodes: Nodes, heap: Heap, max_expansions: int) -> int:
    """Pop the open list until a current entry: ``R_CUR`` set and -1, or a status (the goal,
    an empty list, the expansion cap)."""
    while True:
        if regs[R_HEAP] == 0:
            return EXHAUSTED
        hk = heap.key[0]
        node = heap.node[0]
        regs[R_HEAP] = _pop(heap.key, heap.node, regs[R_HEAP])
        g = (1 << _GBITS) - 1 - (hk & ((1 << _GBITS) - 1))
        f = hk >> _GBITS
        if g != nodes.gv[node] or f != nodes.fv[node]:
            continue  # stale heap entry
        if f > regs[R_BOUND]:
            regs[R_BOUND] = f
        if nodes.hv[node] == 0:
            regs[R_GOAL] = node
            return FOUND
        if max_expansions >= 0 and regs[R_EXPANDED] >= max_expansions:
            regs[R_HEAP] = _push(heap.key, heap.node, regs[R_HEAP], hk, node)
            return LIMIT
        regs[R_CUR] = node
        return -1


@njit(cache=True)
def _active_part(row: I16, n: int, cnt: I64, members: I64) -> tuple[int, int]:
    """``(label, size)`` of the first part of two or more pieces, its pieces in ``members``;
    ``cnt``: every part's size."""
    cnt[:] = 0
    for i in range(n):
        cnt[row[i]] += 1
    act = -1
    for i in range(n):
        if cnt[i] >= 2:
            act = i
            break
    m = 0
    for i in range(n):
        if row[i] == act:
            members[m] = i
            m += 1
    return act, m


@njit(cache=True)
def _part_moves(row: I16, n: int, members: I64, m: int, pieces: Pieces) -> int:
    """:func:`chaingeo.solvers.motion.kinematics_kernel.node_moves` of the part ``members[:m]`` at
    its
    offsets in ``row``: the number of moves written to ``pieces.moves`` (or its -1, -2)."""
    nvox = 0
    for p in range(m):
        q = members[p]
        nvox += pieces.starts[q + 1] - pieces.starts[q]
    vox = np.empty((3, nvox, 3), dtype=np.int64)
    starts = np.empty(m + 1, dtype=np.int64)
    lo = np.empty((m, 3), dtype=np.int64)
    hi = np.empty((m, 3), dtype=np.int64)
    off = np.empty((m, 3), dtype=np.int64)
    gaps = np.empty((3, m, m), dtype=np.int64)
    pos = 0
    for p in range(m):
        q = members[p]
        starts[p] = pos
        for v in range(pieces.starts[q], pieces.starts[q + 1]):
            for a in range(3):
                for t in range(3):
                    vox[a, pos, t] = pieces.vox[a, v, t]
            pos += 1
        for t in range(3):
            lo[p, t] = pieces.lo[q, t]
            hi[p, t] = pieces.hi[q, t]
            off[p, t] = row[n + 3 * q + t]
    starts[m] = pos
    return mv.node_moves(
        vox, starts, lo, hi, off, pieces.max_group, pieces.group_limit, False, gaps,
        pieces.groups, pieces.moves,
    )  # fmt: skip


@njit(cache=True)
def _split(row: I16, child: I16, n: int, members: I64, m: int, gmask: int) -> tuple[int, int, int]:
    """Write to ``child`` the removal of ``gmask`` from the part ``members[:m]`` of ``row``: two
    parts re-anchored at their smallest pieces; returns ``(label a, label b, size of a)``."""
    la = -1
    lb = -1
    for p in range(m):
        q = members[p]
        if (gmask >> q) & 1:
            if la < 0:
                la = q
        elif lb < 0:
            lb = q
    sa = 0
    for p in range(m):
        q = members[p]
        lab = la if (gmask >> q) & 1 else lb
        sa += 1 if lab == la else 0
        child[q] = lab
        for t in range(3):
            child[n + 3 * q + t] = row[n + 3 * q + t] - row[n + 3 * lab + t]
    return la, lb, sa


@njit(cache=True)
def _split_h(
    child: I16, n: int, cnt: I64, act: int, la: int, lb: int, sa: int, sb: int, pdb: PDBView
) -> tuple[int, int]:
    """``(h of both new parts, h of the child's active part)`` after :func:`_split` of the part
    ``act``; ``(-1, 0)`` on a missing entry, ``(DEAD, 0)`` when a part never comes apart."""
    fam, n_fam, keys, vals, table, key, miss = pdb
    ha = _part_h(child, n, la, sa, fam, n_fam, keys, vals, table, key, miss)
    if ha < 0:
        return -1, 0
    hb = _part_h(child, n, lb, sb, fam, n_fam, keys, vals, table, key, miss)
    if hb < 0:
        return -1, 0
    if ha >= DEAD or hb >= DEAD:
        return DEAD, 0
    nact = -1
    for i in range(n):
        c = cnt[i]
        if i == act:
            c = 0
        if i == la:
            c = sa
        if i == lb:
            c = sb
        if c >= 2:
            nact = i
            break
    if nact < 0:
        return ha + hb, 0
    if nact == la:
        return ha + hb, ha
    if nact == lb:
        return ha + hb, hb
    hc = _part_h(child, n, nact, cnt[nact], fam, n_fam, keys, vals, table, key, miss)
    if hc < 0:
        return -1, 0
    return ha + hb, hc


@njit(cache=True)
def _store(
    regs: I64, rows: I16, gv: I32, hv: I32, hact: I32, fv: I32, parent: I64, mmask: I64,
    mdir: I64, mk: I64, closed: U8, table: I64, hkey: I64, hnode: I64, child: I16, cur: int,
    hgf: tuple[int, int, int, int], move: tuple[int, int, int],
) -> int:  # fmt: skip
    """Store ``child`` of ``cur`` (``hgf``: its ``h``, active ``h``, ``g``, ``f``; ``move``:
    mask, direction, ``k``) unless known at a ``g`` as small; -1, or the buffer to grow. Called
    per child, it takes :class:`Nodes`' and :class:`Heap`'s arrays loose (see :func:`_part_h`)."""
    h, hc, g1, fc = hgf
    n_states = regs[R_STATES]
    if n_states >= rows.shape[0] or 2 * (n_states + 1) > table.shape[0]:
        return NEED_STATES
    if regs[R_HEAP] + 1 >= hkey.shape[0]:
        return NEED_HEAP
    got = mv.find_or_insert(rows, n_states, table, child)
    if got < 0:
        got = -1 - got
        regs[R_STATES] = n_states + 1
        hv[got] = h
        hact[got] = hc
        closed[got] = 0
    elif g1 >= gv[got]:
        return -1
    elif closed[got]:
        closed[got] = 0
        regs[R_REOPENED] += 1
    gv[got] = g1
    fv[got] = fc
    parent[got] = cur
    mmask[got] = move[0]
    mdir[got] = move[1]
    mk[got] = move[2]
    regs[R_HEAP] = _push(hkey, hnode, regs[R_HEAP], _heap_key(g1, hv[got]), got)
    return -1


@njit(cache=True)
def _expand(
    regs: I64, nodes: Nodes, heap: Heap, pieces: Pieces, pdb: PDBView,
    work: tuple[I16, I64, I64],
) -> int:  # fmt: skip
    """Expand ``R_CUR``, its active part only, storing the children with ``f`` equal to its
    ``fv`` (a partial expansion): -1 when done, else a status. ``work``: scratch (a child row,
    part sizes, the active part's pieces)."""
    child, cnt, members = work
    # the per-child helpers take arrays: taken out of the bundles once per node (see _part_h)
    rows, gv, hv, hact, fv, parent, mmask, mdir, mk, closed, table = nodes
    hkey, hnode = heap
    fam, n_fam, keys, vals, ptable, key, miss = pdb
    cur = regs[R_CUR]
    row = rows[cur]
    n = pieces.lo.shape[0]
    act, m = _active_part(row, n, cnt, members)
    nrows = _part_moves(row, n, members, m, pieces)
    if nrows == -2:
        return GROUPS
    if nrows == -1:
        return NEED_MOVES
    moves = pieces.moves
    g1 = gv[cur] + 1
    hbase = hv[cur] - hact[cur]
    big_f = fv[cur]  # this (partial) expansion stores the children with f == big_f
    first = big_f == gv[cur] + hv[cur]
    nxt = DEAD
    for r in range(nrows):
        lmask = moves[r, 0]
        d = moves[r, 1]
        kmax = moves[r, 2]
        gmask = 0
        for p in range(m):
            if (lmask >> p) & 1:
                gmask |= 1 << members[p]
        last = kmax + 1 if moves[r, 3] else kmax  # k = kmax + 1 stands for the removal
        for k in range(1, last + 1):
            if k <= kmax:
                mv.shift_child(row, child, n, members, m, gmask, d, k)
                hc = _part_h(child, n, act, m, fam, n_fam, keys, vals, ptable, key, miss)
                if hc < 0:
                    return NEED_PDB
                if hc >= DEAD:
                    continue
                h = hbase + hc
                kk = k
            else:  # the removal: two parts, re-anchored at their smallest pieces
                for t in range(child.shape[0]):
                    child[t] = row[t]
                la, lb, sa = _split(row, child, n, members, m, gmask)
                hab, hc = _split_h(child, n, cnt, act, la, lb, sa, m - sa, pdb)
                if hab < 0:
                    return NEED_PDB
                if hab >= DEAD:
                    continue
                h = hbase + hab
                kk = 0
            fc = g1 + h
            if fc > big_f:  # left for a later expansion of cur
                nxt = min(nxt, fc)
                continue
            if fc < big_f and not first:
                continue  # stored by an earlier expansion of cur
            status = _store(
                regs, rows, gv, hv, hact, fv, parent, mmask, mdir, mk, closed, table, hkey, hnode,
                child, cur, (h, hc, g1, fc), (gmask, d, kk),
            )  # fmt: skip
            if status >= 0:
                return status
    if nxt < DEAD:  # children with a larger f remain: come back at the next f
        if regs[R_HEAP] + 1 >= hkey.shape[0]:
            return NEED_HEAP
        fv[cur] = nxt
        regs[R_HEAP] = _push(hkey, hnode, regs[R_HEAP], _heap_key(gv[cur], nxt - gv[cur]), cur)
    else:
        fv[cur] = -1
    return -1


@njit(cache=True)
def run_astar(
    regs: I64, nodes: Nodes, heap: Heap, pieces: Pieces, pdb: PDBView, max_expansions: int,
    batch: int,
) -> int:  # fmt: skip
    """A* from the stored states until a status (module docstring); see :class:`AStarRun`."""
    n = pieces.lo.shape[0]
    work = (
        np.empty(nodes.rows.shape[1], dtype=np.int16),
        np.zeros(n, dtype=np.int64),
        np.empty(n, dtype=np.int64),
    )
    done = 0
    while True:
        if regs[R_CUR] < 0:
            if done >= batch:
                return YIELD
            status = _next_node(regs, nodes, heap, max_expansions)
            if status >= 0:
                return status
        status = _expand(regs, nodes, heap, pieces, pdb, work)
        if status >= 0:
            return status
        nodes.closed[regs[R_CUR]] = 1
        regs[R_EXPANDED] += 1
        regs[R_CUR] = -1
        done += 1


class AStarRun:
    """One A* search's arrays, and the Python loop that serves the kernel's requests."""

    def __init__(
        self,
        table: PieceTable,
        pdb: PatternDB,
        max_group: int,
        limits: AStarLimits,
        deadline: Deadline,
    ) -> None:
        n = len(table.names)
        self.n = n
        self.pdb = pdb
        self.max_group = max_group
        self.limits = limits
        self.deadline = deadline
        self.gvox, self.gstarts, self.glo, self.ghi = table.part_arrays(range(n))
        cap = max(2, min(4096, limits.max_states))
        self.rows = np.zeros((cap, 4 * n), dtype=np.int16)
        self.rows[0, :n] = 0  # the start: one part labelled 0, every offset zero
        self.gv = np.zeros(cap, dtype=np.int32)
        self.hv = np.zeros(cap, dtype=np.int32)
        self.hact = np.zeros(cap, dtype=np.int32)
        self.fv = np.zeros(cap, dtype=np.int32)
        self.parent = np.full(cap, -1, dtype=np.int64)
        self.mmask = np.zeros(cap, dtype=np.int64)
        self.mdir = np.zeros(cap, dtype=np.int64)
        self.mk = np.zeros(cap, dtype=np.int64)
        self.closed = np.zeros(cap, dtype=np.uint8)
        self.table = np.full(1 << (4 * cap - 1).bit_length(), -1, dtype=np.int64)
        self.hkey = np.zeros(4 * cap, dtype=np.int64)
        self.hnode = np.zeros(4 * cap, dtype=np.int64)
        self.moves_buf = np.zeros((1024, 4), dtype=np.int64)
        self.groups_buf = np.zeros(min(limits.group_limit, 1 << 16) + 1, dtype=np.uint64)
        self.miss = np.zeros(KEY_WIDTH, dtype=np.int16)
        self.regs = np.zeros(N_REGS, dtype=np.int64)
        self.start_h = 0

    # -- registers as attributes -------------------------------------------------------------
    @property
    def n_states(self) -> int:
        return int(self.regs[R_STATES])

    @property
    def expanded(self) -> int:
        return int(self.regs[R_EXPANDED])

    @property
    def reopened(self) -> int:
        return int(self.regs[R_REOPENED])

    @property
    def bound(self) -> int:
        return int(self.regs[R_BOUND])

    def _start(self) -> bool:
        """Store the start state with its ``h``; False when it can never come apart."""
        mv.find_or_insert(self.rows, 0, self.table, self.rows[0].copy())
        while True:
            h = part_h(self.rows[0], self.n, 0, self.n, pdb_view(self.pdb, self.miss))
            if h >= 0:
                break
            self.pdb.ensure(self.miss.tolist())
        if h >= DEAD:
            return False
        self.hv[0] = self.hact[0] = self.fv[0] = self.start_h = h
        self.regs[R_STATES] = 1
        self.regs[R_HEAP] = _push(self.hkey, self.hnode, 0, _heap_key(0, h), 0)
        self.regs[R_CUR] = -1
        self.regs[R_BOUND] = h
        return True

    def _grow_states(self) -> None:
        cap = self.rows.shape[0]
        if cap >= self.limits.max_states:
            raise SearchLimitError(
                f"A* state cap of {self.limits.max_states} stored states reached after "
                f"{self.expanded} expansions (lower bound {self.bound}); "
                "raise AStarLimits(max_states=...)"
            )
        new = min(2 * cap, self.limits.max_states)
        extra = new - cap
        self.rows = np.concatenate([self.rows, np.zeros((extra, self.rows.shape[1]), np.int16)])
        for name in ("gv", "hv", "hact", "fv"):
            setattr(self, name, np.concatenate([getattr(self, name), np.zeros(extra, np.int32)]))
        self.parent = np.concatenate([self.parent, np.full(extra, -1, np.int64)])
        for name in ("mmask", "mdir", "mk"):
            setattr(self, name, np.concatenate([getattr(self, name), np.zeros(extra, np.int64)]))
        self.closed = np.concatenate([self.closed, np.zeros(extra, np.uint8)])
        if self.table.shape[0] < 4 * new:
            size = 1 << (4 * new - 1).bit_length()
            self.table = np.full(size, -1, dtype=np.int64)
            mv.rebuild_table(self.rows, self.n_states, self.table)

    def _nodes(self) -> Nodes:
        return Nodes(
            self.rows, self.gv, self.hv, self.hact, self.fv, self.parent, self.mmask, self.mdir,
            self.mk, self.closed, self.table,
        )  # fmt: skip

    def _pieces(self) -> Pieces:
        return Pieces(
            self.gvox, self.gstarts, self.glo, self.ghi, self.max_group,
            self.limits.group_limit, self.moves_buf, self.groups_buf,
        )  # fmt: skip

    def search(self) -> int:
        """Run to the end: the goal node, or -1 when the puzzle never comes apart."""
        if not self._start():
            return -1
        pdb = self.pdb
        max_exp = -1 if self.limits.max_expansions is None else self.limits.max_expansions
        bundles: tuple[Nodes, Heap, Pieces] | None = None
        view: PDBView | None = None
        kernel = None
        while True:
            self.deadline.check()
            if bundles is None:  # the arrays were replaced (grown)
                bundles = (self._nodes(), Heap(self.hkey, self.hnode), self._pieces())
            if view is None or view.keys is not pdb.keys or view.hash is not pdb.hash:
                view = pdb_view(pdb, self.miss)
            elif view.vals is not pdb.vals:
                view = view._replace(vals=pdb.vals)
            args = (self.regs, *bundles, view, max_exp, 20000)
            if kernel is None:  # one typing per search: the bundles keep their types (jit.entry)
                kernel = entry(run_astar, *args)
            status = kernel(*args)
            if status == FOUND:
                return int(self.regs[R_GOAL])
            if status == EXHAUSTED:
                return -1
            if status in (NEED_STATES, NEED_HEAP, NEED_MOVES):
                bundles = None
            if status == NEED_STATES:
                self._grow_states()
            elif status == NEED_HEAP:
                self.hkey = np.concatenate([self.hkey, np.zeros_like(self.hkey)])
                self.hnode = np.concatenate([self.hnode, np.zeros_like(self.hnode)])
            elif status == NEED_PDB:
                pdb.ensure(self.miss.tolist())
            elif status == NEED_MOVES:
                self.moves_buf = np.zeros((2 * self.moves_buf.shape[0], 4), dtype=np.int64)
            elif status == LIMIT:
                raise SearchLimitError(
                    f"A* expansion cap of {self.limits.max_expansions} reached (lower bound "
                    f"{self.bound}); raise AStarLimits(max_expansions=...)"
                )
            elif status == GROUPS:
                raise SearchLimitError(
                    f"more than {self.limits.group_limit} movable groups along one direction "
                    "in one state; raise AStarLimits(group_limit=...)"
                )
