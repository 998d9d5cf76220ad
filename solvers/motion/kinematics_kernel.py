"""Movement analysis on flat integer arrays (numba): who blocks whom, which groups move, how far.
The reference it must equal is :mod:`chaingeo.core.kinematics`.

Cutler's / BurrTools' method: for each axis ``a`` and each ordered pair of pieces ``(i, j)`` the
gap ``g[a, i, j]`` is how far ``i`` can travel along ``+a`` while ``j`` stays put (``INF``: never
meets it). A group ``G`` can travel ``min g[a, i, j]`` over ``i in G, j not in G``, so every
legal move follows from these matrices: the groups that can step at all are the sets closed
under "is blocked by" (``g == 0``), enumerated here one by one without trying every subset.
Moving ``G`` along ``+a`` and moving the rest along ``-a`` give the same relative state.

Pieces are the voxels of one *part* (a sub-puzzle) in their assembled position; a state is one
``int16`` row of ``3 n`` offsets, piece 0 always at the origin. Directions are indexed as in
:data:`chaingeo.core.kinematics.DIRECTIONS`: ``2 a`` is ``+a`` and ``2 a + 1`` is ``-a``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from chaingeo.core.arrays import I16, I32, I64, U64
from chaingeo.kernels.jit import njit

#: "Never meets": larger than any real gap.
INF = 1 << 40
#: Most pieces one part may hold (groups are 64-bit masks).
MAX_PIECES = 63


class Pieces(NamedTuple):
    """A part's pieces as :func:`node_moves` reads them (voxels sorted per axis, where each
    piece's rows start, boxes: :meth:`chaingeo.solvers.motion.partsearch.PieceTable.part_arrays`),
    the group caps (``max_group`` -1: any), and the buffers it writes (move rows, groups)."""

    vox: I64
    starts: I64
    lo: I64
    hi: I64
    max_group: int
    group_limit: int
    moves: I64
    groups: U64


@njit(cache=True)
def _pair_gap(
    vox: I64, starts: I64, lo: I64, hi: I64, a: int, i: int, j: int, rel: I64
) -> tuple[int, int]:  # fmt: skip
    """``(g[a, i, j], g[a, j, i])`` of pieces ``i`` and ``j`` (rows of the table arrays), ``j``
    displaced by ``rel`` from ``i``: one merge of the two pieces' voxel runs along ``a``."""
    u = (a + 1) % 3
    v = (a + 2) % 3
    ru = rel[u]
    rv = rel[v]
    ra = rel[a]
    gij = INF
    gji = INF
    if (
        lo[j, u] + ru > hi[i, u]
        or hi[j, u] + ru < lo[i, u]
        or lo[j, v] + rv > hi[i, v]
        or hi[j, v] + rv < lo[i, v]
    ):
        return gij, gji
    p = starts[i]
    pe = starts[i + 1]
    q = starts[j]
    qe = starts[j + 1]
    while p < pe and q < qe:
        iu = vox[a, p, u]
        iv = vox[a, p, v]
        ju = vox[a, q, u] + ru
        jv = vox[a, q, v] + rv
        if iu < ju or (iu == ju and iv < jv):
            p += 1
            continue
        if iu > ju or (iu == ju and iv > jv):
            q += 1
            continue
        # The same line: walk both runs in order; an i-voxel followed by a j-voxel is a gap
        # for i moving +a, and the other way round for j.
        last_owner = -1
        last_val = 0
        while True:
            p_in = p < pe and vox[a, p, u] == iu and vox[a, p, v] == iv
            q_in = q < qe and vox[a, q, u] + ru == iu and vox[a, q, v] + rv == iv
            if not p_in and not q_in:
                break
            if p_in and (not q_in or vox[a, p, a] < vox[a, q, a] + ra):
                val = vox[a, p, a]
                owner = 0
                p += 1
            else:
                val = vox[a, q, a] + ra
                owner = 1
                q += 1
            if last_owner == 0 and owner == 1:
                gij = min(gij, val - last_val - 1)
            elif last_owner == 1 and owner == 0:
                gji = min(gji, val - last_val - 1)
            last_owner = owner
            last_val = val
    return gij, gji


@njit(cache=True)
def pair_gaps(vox: I64, starts: I64, lo: I64, hi: I64, off: I64, out: I64) -> None:
    """Fill ``out[a, i, j]``: how far piece ``i`` can move along ``+a`` with ``j`` fixed.

    ``vox[a]`` holds every piece's voxels sorted by (the two other axes, then ``a``), piece
    ``p`` in rows ``starts[p]:starts[p + 1]``; ``lo``/``hi`` are bounding boxes, ``off`` the
    offsets. One merge per pair and axis finds the nearest voxel of the other piece ahead.
    """
    n = starts.shape[0] - 1
    rel = np.empty(3, dtype=np.int64)
    for a in range(3):
        for i in range(n):
            out[a, i, i] = INF
        for i in range(n):
            for j in range(i + 1, n):
                for t in range(3):
                    rel[t] = off[j, t] - off[i, t]
                out[a, i, j], out[a, j, i] = _pair_gap(vox, starts, lo, hi, a, i, j, rel)


#: An offset no pair of pieces is ever at: marks an empty entry of a :func:`gap_memo`.
NO_OFFSET = -(1 << 50)


def gap_memo(n: int) -> tuple[I64, I64]:
    """An empty memo for :func:`memo_pair_gaps` over a table of ``n`` pieces."""
    return np.full((n, n, 3), NO_OFFSET, dtype=np.int64), np.zeros((3, n, n), dtype=np.int64)


@njit(cache=True)
def memo_pair_gaps(
    vox: I64, starts: I64, lo: I64, hi: I64, members: I64, off: I64, out: I64,
    memo_rel: I64, memo_gap: I64,
) -> None:  # fmt: skip
    """:func:`pair_gaps` of the part ``members`` (pieces of the whole table) at ``off``,
    remembering each pair's gaps at its last relative offset: a pair's gaps depend only on
    that offset, and most pairs keep theirs from one state to the next and from a part to the
    parts it splits into. ``memo_rel[p, q]`` (``p < q``, table pieces): the offset of ``q``
    from ``p`` whose gaps ``memo_gap[a, p, q]`` and ``memo_gap[a, q, p]`` hold."""
    k = members.shape[0]
    rel = np.empty(3, dtype=np.int64)
    for i in range(k):
        for a in range(3):
            out[a, i, i] = INF
        for j in range(i + 1, k):
            p, q, x, y = members[i], members[j], i, j
            if p > q:
                p, q, x, y = q, p, j, i
            hit = True
            for t in range(3):
                rel[t] = off[y, t] - off[x, t]
                hit = hit and memo_rel[p, q, t] == rel[t]
            if not hit:
                for a in range(3):
                    memo_gap[a, p, q], memo_gap[a, q, p] = _pair_gap(
                        vox, starts, lo, hi, a, p, q, rel
                    )
                for t in range(3):
                    memo_rel[p, q, t] = rel[t]
            for a in range(3):
                out[a, x, y] = memo_gap[a, p, q]
                out[a, y, x] = memo_gap[a, q, p]


@njit(cache=True)
def sort_axes(every: I64, starts: I64) -> I64:
    """The voxel order :func:`pair_gaps` merges in: ``out[a]`` holds every piece's voxels
    (piece ``p`` in rows ``starts[p]:starts[p + 1]`` of ``every``), each piece sorted by the
    two other axes, then ``a``. Coordinates must span less than 2**20 per axis."""
    m = every.shape[0]
    mn = np.empty(3, dtype=np.int64)
    span = 1
    for t in range(3):
        mn[t] = every[:, t].min()
        span = max(span, every[:, t].max() - mn[t] + 1)
    out = np.empty((3, m, 3), dtype=np.int64)
    key = np.empty(m, dtype=np.int64)
    for a in range(3):
        u = (a + 1) % 3
        w = (a + 2) % 3
        for r in range(m):
            key[r] = (
                ((every[r, u] - mn[u]) * span + every[r, w] - mn[w]) * span + every[r, a] - mn[a]
            )
        for p in range(starts.shape[0] - 1):
            first = starts[p]
            order = np.argsort(key[first : starts[p + 1]])
            for i in range(order.shape[0]):
                for t in range(3):
                    out[a, first + i, t] = every[first + order[i], t]
    return out


@njit(cache=True)
def closures(gaps: I64, a: int, n: int) -> U64:
    """``c[i]``: the pieces that must come along when ``i`` steps along ``+a`` (with ``i``)."""
    c = np.zeros(n, dtype=np.uint64)
    for i in range(n):
        m = np.uint64(1) << np.uint64(i)
        for j in range(n):
            if j != i and gaps[a, i, j] == 0:
                m |= np.uint64(1) << np.uint64(j)
        c[i] = m
    for k in range(n):  # Warshall on bit rows
        bk = np.uint64(1) << np.uint64(k)
        for i in range(n):
            if c[i] & bk:
                c[i] |= c[k]
    return c


@njit(cache=True)
def stuck(pos: I64, box: I64, row_ptr: I64, cells: I32, rows: I32) -> bool:
    """True when no group of the placed rows can take one step at all: a sure "cannot come
    apart", decided before any search is built (most of an assembler's assemblies are such).

    Row ``r`` covers target cells ``cells[row_ptr[r]:row_ptr[r + 1]]``, cell ``c`` at index
    ``pos[c]`` of the target's bounding box ``box`` (x major). Along each axis the smallest
    group that must come along with each piece (as :func:`closures`) must be every piece;
    then nothing moves along ``+a``, nor along ``-a`` (the rest would move along ``+a``)."""
    n = rows.shape[0]
    if n < 2 or n > MAX_PIECES:
        return False  # nothing to take apart, or a part the search refuses: let it decide
    grid = np.full(box[0] * box[1] * box[2], -1, dtype=np.int64)
    for k in range(n):
        for p in range(row_ptr[rows[k]], row_ptr[rows[k] + 1]):
            grid[pos[cells[p]]] = k
    full = (np.uint64(1) << np.uint64(n)) - np.uint64(1)
    c = np.empty(n, dtype=np.uint64)
    for a in range(3):
        stride = box[1] * box[2] if a == 0 else (box[2] if a == 1 else 1)
        for i in range(n):
            c[i] = np.uint64(1) << np.uint64(i)
        for q in range(grid.shape[0]):
            i = grid[q]
            if i >= 0 and (q // stride) % box[a] < box[a] - 1:
                j = grid[q + stride]
                if j >= 0:
                    c[i] |= np.uint64(1) << np.uint64(j)
        for k in range(n):  # Warshall on bit rows
            bk = np.uint64(1) << np.uint64(k)
            for i in range(n):
                if c[i] & bk:
                    c[i] |= c[k]
        for i in range(n):
            if c[i] != full:
                return False
    return True


@njit(cache=True)
def closed_groups(c: U64, n: int, limit: int, out: U64, max_group: int = -1) -> int:
    """Write every proper, non-empty set closed under ``c`` into ``out``; return the count, or
    -1 if there are more than ``limit`` (or more than ``out`` holds). With ``max_group >= 0``
    only sets that a move can carry are written: the set or the rest has at most
    ``max_group`` pieces (a branch whose chosen and excluded pieces both exceed it is cut, as
    every set it leads to contains the one and avoids the other).

    Depth first over pieces in index order: piece ``i`` is in (forced if a chosen closure
    holds it, allowed if its closure avoids every excluded piece) or out (if not forced), so
    each closed set is produced exactly once.
    """
    full = (np.uint64(1) << np.uint64(n)) - np.uint64(1)
    stack_i = np.empty(n + 2, dtype=np.int64)
    stack_s = np.empty(n + 2, dtype=np.uint64)
    stack_x = np.empty(n + 2, dtype=np.uint64)
    stack_b = np.empty(n + 2, dtype=np.int64)  # 0: try "in" next, 1: try "out" next, 2: done
    count = 0
    top = 0
    stack_i[0] = 0
    stack_s[0] = np.uint64(0)
    stack_x[0] = np.uint64(0)
    stack_b[0] = 0
    while top >= 0:
        i = stack_i[top]
        s = stack_s[top]
        x = stack_x[top]
        if max_group >= 0 and _popcount(s) > max_group and _popcount(x) > max_group:
            top -= 1
            continue
        if i == n:
            if s != np.uint64(0) and s != full:
                if count >= limit or count >= out.shape[0]:
                    return -1
                out[count] = s
                count += 1
            top -= 1
            continue
        bit = np.uint64(1) << np.uint64(i)
        b = stack_b[top]
        if b == 0:
            stack_b[top] = 1
            if s & bit:  # forced in: only one branch
                stack_b[top] = 2
                top += 1
                stack_i[top] = i + 1
                stack_s[top] = s
                stack_x[top] = x
                stack_b[top] = 0
            elif (c[i] & x) == np.uint64(0):
                top += 1
                stack_i[top] = i + 1
                stack_s[top] = s | c[i]
                stack_x[top] = x
                stack_b[top] = 0
        elif b == 1:
            stack_b[top] = 2
            top += 1
            stack_i[top] = i + 1
            stack_s[top] = s
            stack_x[top] = x | bit
            stack_b[top] = 0
        else:
            top -= 1
    return count


@njit(cache=True)
def _popcount(m: np.uint64) -> int:
    k = 0
    while m:
        m &= m - np.uint64(1)
        k += 1
    return k


@njit(cache=True)
def node_moves(
    vox: I64,
    starts: I64,
    lo: I64,
    hi: I64,
    off: I64,
    max_group: int,
    group_limit: int,
    both: bool,
    gaps: I64,
    groups: U64,
    out: I64,
) -> int:
    """List the legal moves of one state into ``out`` rows ``(mask, dir, kmax, removable)``.

    ``kmax`` is the longest finite move (``k = 1..kmax`` are all legal); ``removable`` = 1 when
    the group can also leave for good. With ``both`` every move is listed (a group along ``+a``
    and the rest along ``-a``); otherwise one of each such pair, the smaller group (ties: the
    group moving along ``+a``), which reaches the same relative state. Returns the row count,
    -1 if ``out`` is too small, -2 if some direction has more than ``group_limit`` groups.
    """
    n = starts.shape[0] - 1
    full = (np.uint64(1) << np.uint64(n)) - np.uint64(1)
    pair_gaps(vox, starts, lo, hi, off, gaps)
    rows = 0
    for a in range(3):
        c = closures(gaps, a, n)
        ng = closed_groups(c, n, group_limit, groups, max_group)
        if ng < 0:
            return -2
        for gi in range(ng):
            g = groups[gi]
            rest = full & ~g
            f = INF
            gmin = INF
            rmax = -INF
            for i in range(n):
                if g & (np.uint64(1) << np.uint64(i)):
                    gmin = min(gmin, lo[i, a] + off[i, a])
                    for j in range(n):
                        if not (g & (np.uint64(1) << np.uint64(j))):
                            f = min(f, gaps[a, i, j])
                else:
                    rmax = max(rmax, hi[i, a] + off[i, a])
            removable = 1 if f >= INF else 0
            kmax = rmax - gmin if removable else f  # clearance - 1 when it can leave
            if kmax < 0:
                kmax = 0
            size_g = _popcount(g)
            ok_g = max_group < 0 or size_g <= max_group
            ok_r = max_group < 0 or n - size_g <= max_group
            for side in range(2):
                if side == 0:
                    if not ok_g:
                        continue
                    if not both and ok_r and n - size_g < size_g:
                        continue
                    mask = g
                    d = 2 * a
                else:
                    if not ok_r:
                        continue
                    if not both and ok_g and size_g <= n - size_g:
                        continue
                    mask = rest
                    d = 2 * a + 1
                if kmax == 0 and removable == 0:
                    continue
                if rows >= out.shape[0]:
                    return -1
                out[rows, 0] = np.int64(mask)
                out[rows, 1] = d
                out[rows, 2] = kmax
                out[rows, 3] = removable
                rows += 1
    return rows


@njit(cache=True, inline="always")
def shift_child(
    row: I16, child: I16, base: int, pieces: I64 | None, m: int, mask: int | np.int64, d: int,
    k: int,
) -> None:  # fmt: skip
    """``child`` = ``row`` with the group ``mask`` (bits of the piece indices ``pieces[:m]``,
    or ``0..m-1`` when ``pieces`` is None; offsets at ``base + 3 piece``) moved ``k`` units
    along direction ``d``. The first piece never moves: when it belongs to the group, the
    others move the opposite way instead."""
    for t in range(child.shape[0]):  # a loop: slice assignment is slow on short rows
        child[t] = row[t]
    a = base + d // 2
    step = k if d % 2 == 0 else -k
    first = 0 if pieces is None else pieces[0]
    if (mask >> first) & 1:
        step = -step
        mask = ~mask
    for p in range(m):
        q = p if pieces is None else pieces[p]
        if (mask >> q) & 1:
            child[a + 3 * q] += step


@njit(cache=True)
def hash_row(row: I16) -> np.uint64:
    h = np.uint64(14695981039346656037)
    for v in row:
        h ^= np.uint64(np.int64(v) & 0xFFFF)
        h *= np.uint64(1099511628211)
    return h


@njit(cache=True)
def _slot(states: I16, table: I64, row: I16) -> int:
    """The slot of ``row`` in the open-addressing ``table`` over ``states``: where it is
    stored, or the empty slot where it would go (linear probing on :func:`hash_row`)."""
    mask = np.uint64(table.shape[0] - 1)
    h = hash_row(row) & mask
    w = row.shape[0]
    while True:
        idx = int(table[h])
        if idx < 0:
            return int(h)
        same = True
        for t in range(w):
            if states[idx, t] != row[t]:
                same = False
                break
        if same:
            return int(h)
        h = (h + np.uint64(1)) & mask


@njit(cache=True)
def find_row(states: I16, table: I64, row: I16) -> int:
    """Index of ``row`` in ``states`` (via the open-addressing ``table``), or -1."""
    return int(table[_slot(states, table, row)])


@njit(cache=True)
def find_or_insert(states: I16, n_states: int, table: I64, row: I16) -> int:
    """Index of ``row`` in ``states`` (via the open-addressing ``table``); if absent, store it
    at ``n_states`` and return ``-1 - n_states``."""
    slot = _slot(states, table, row)
    idx = int(table[slot])
    if idx >= 0:
        return idx
    table[slot] = n_states
    for t in range(row.shape[0]):
        states[n_states, t] = row[t]
    return -1 - n_states


@njit(cache=True)
def rebuild_table(states: I16, n_states: int, table: I64) -> None:
    table[:] = -1
    mask = np.uint64(table.shape[0] - 1)
    for s in range(n_states):
        h = hash_row(states[s]) & mask
        while table[h] >= 0:
            h = (h + np.uint64(1)) & mask
        table[h] = s


@njit(cache=True)
def unique_removals(states: I16, nodes: I64, masks: I64, n: int) -> I64:
    """Which removals lead to a sub-problem not met before in the given order (1: new): the
    same pieces split off (the mask or its complement) and the same configurations of both
    sides, each side's offsets taken relative to its first piece."""
    m = nodes.shape[0]
    full = (np.int64(1) << n) - 1
    keys = np.zeros((max(m, 1), 3 * n + 4), dtype=np.int16)
    size = 4
    while size < 4 * m:
        size *= 2
    table = np.full(size, -1, dtype=np.int64)
    row = np.empty(3 * n + 4, dtype=np.int16)
    keep = np.zeros(m, dtype=np.int64)
    count = 0
    for r in range(m):
        c = min(masks[r], full ^ masks[r])
        for t in range(4):
            row[t] = np.int16((c >> (16 * t)) & 0xFFFF)
        pos = 4
        for side in range(2):
            first = -1
            for p in range(n):
                if ((c >> p) & 1) != side:
                    if first < 0:
                        first = p
                    for t in range(3):
                        row[pos] = states[nodes[r], 3 * p + t] - states[nodes[r], 3 * first + t]
                        pos += 1
        if find_or_insert(keys, count, table, row) < 0:
            keep[r] = 1
            count += 1
    return keep
