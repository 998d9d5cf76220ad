"""BurrTools' disassembler: the first separation in its exact search order (numba).

BurrTools (``disassembler_0.cpp``) searches a part breadth first, nodes in the order they were
found, and stops at the *first* node whose successor splits the part; the two parts are then
taken apart the same way, and when one cannot be, the assembly is no solution
(``disassembler_a.cpp``, ``checkSubproblems``). Which separation comes first, and so the level
string, depends on the order in which a node's successors are listed
(``movementanalysator.cpp``, ``find``), reproduced here:

1. a single piece that can leave, directions ``+x, -x, +y, -y, +z, -z``, pieces in order;
2. a group that can leave: the pieces that must come along when piece ``i`` leaves, at most
   half of the part's pieces (``n // 2``), same order;
3. moves: per direction, per piece ``i``, per step ``s = 1, 2, ...`` while the pieces that must
   come along number at most ``n // 2``: that group moved ``s`` (unless listed already in this
   direction), then its unions with every group of the same step listed before in this
   direction, newest first (neither containing the other, not every piece).

A group moving along ``+a`` and the rest along ``-a`` give the same relative state; states are
offsets relative to the part's first piece (BurrTools' ``disassemblerNode_c::operator==``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from chaingeo.core.arrays import I16, I64
from chaingeo.core.kinematics import Move, SearchLimitError
from chaingeo.kernels.jit import njit
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion import bfs_kernel as bfs
from chaingeo.solvers.motion import kinematics_kernel as mv
from chaingeo.solvers.motion.levelsearch import (
    EXPANDED,
    GROUP_CAP,
    INFO,
    OVER_BUDGET,
    STATE_CAP,
    STATES,
    STATUS,
    TOTAL_CAP,
    LevelTree,
    _record,
)
from chaingeo.solvers.motion.partsearch import DIRECTION_NAMES, PieceTable, part_size

#: Status of :func:`part_search`: a separation found, the part cannot come apart, a buffer to
#: grow (the caller grows it and calls again), past the node budget (call again to go on),
#: more groups along one direction than the limit.
SEPARATED, STUCK, NEED_STATES, PAUSED, TOO_MANY_GROUPS = 0, 1, 2, 3, 4


@njit(cache=True)
def _reach(gaps: I64, d: int, i: int, s: int, k: int, limit: int, todo: I64) -> np.int64:
    """The pieces that must come along when piece ``i`` moves ``s`` along direction ``d``
    (``s >= mv.INF``: leaves for good), as a mask; 0 when they are more than ``limit``.
    ``todo``: room for ``k`` pieces (the caller's, reused)."""
    a = d // 2
    neg = d % 2 == 1
    mask = np.int64(1) << i
    todo[0] = i
    top = 1
    count = 1
    while top > 0:
        top -= 1
        p = todo[top]
        for j in range(k):
            if (mask >> j) & 1:
                continue
            g = gaps[a, j, p] if neg else gaps[a, p, j]
            if s > g:
                count += 1
                if count > limit:
                    return np.int64(0)
                mask |= np.int64(1) << j
                todo[top] = j
                top += 1
    return mask


class PartGaps(NamedTuple):
    """A part as :func:`part_search` reads it: the whole puzzle's :class:`PieceTable` arrays,
    the part's pieces (``members``: rows of them) and the memo of their pair gaps
    (:func:`chaingeo.solvers.motion.kinematics_kernel.memo_pair_gaps`, shared by a puzzle's
    parts)."""

    vox: I64
    starts: I64
    lo: I64
    hi: I64
    members: I64
    memo_rel: I64
    memo_gap: I64


@njit(cache=True)
def _leaving(gaps: I64, k: int, todo: I64) -> tuple[np.int64, int]:
    """The first group that can leave a state with pair gaps ``gaps`` and its direction, in
    BurrTools' order (single pieces first, then groups of at most half); ``(0, -1)``: none."""
    for limit in (1, k // 2):
        for d in range(6):
            for i in range(k):
                m = _reach(gaps, d, i, mv.INF, k, limit, todo)
                if m != 0:
                    return m, d
    return np.int64(0), -1


@njit(cache=True)
def part_search(part: PartGaps, tree: bfs.Tree, ctx: I64, budget: int, group_limit: int) -> int:
    """Breadth-first search of one part in BurrTools' order up to its first separation.

    ``states`` row 0 is the start (relative offsets); ``ctx``: ``[n_states, next node,
    separating node, its mask, its direction]``, updated in place so that a call that returns
    PAUSED or NEED_STATES can be repeated (the node being expanded starts over; the states it
    added stay, as BurrTools would have added them in the same order). ``move`` rows: mask,
    direction, distance of the move that found each state. The part's pieces are the table
    rows ``members`` of :class:`PartGaps`. Returns a status code."""
    vox, starts, lo, hi, members, memo_rel, memo_gap = part
    states, parent, move, table = tree
    k = members.shape[0]
    half = k // 2
    gaps = np.empty((3, k, k), dtype=np.int64)
    off = np.empty((k, 3), dtype=np.int64)
    child = np.empty(3 * k, dtype=np.int16)
    todo = np.empty(k, dtype=np.int64)
    f_mask = np.empty(64, dtype=np.int64)
    f_step = np.empty(64, dtype=np.int64)
    n_states = ctx[0]
    node = ctx[1]
    done = 0
    while node < n_states:
        if done >= budget:
            ctx[1] = node
            return PAUSED
        for p in range(k):
            for t in range(3):
                off[p, t] = states[node, 3 * p + t]
        mv.memo_pair_gaps(vox, starts, lo, hi, members, off, gaps, memo_rel, memo_gap)
        m, d = _leaving(gaps, k, todo)
        if m != 0:
            ctx[1] = node
            ctx[2] = node
            ctx[3] = m
            ctx[4] = d
            return SEPARATED
        for d in range(6):
            nf = 0
            for i in range(k):
                s = 1
                while True:
                    m = _reach(gaps, d, i, s, k, half, todo)
                    if m == 0:
                        break
                    pending = 1  # the group itself, then its unions
                    q = -1
                    while True:
                        if pending == 1:
                            cand = m
                        else:
                            if q < 0:
                                break
                            o = f_mask[q]
                            same = f_step[q] == s
                            q -= 1
                            cand = m | o
                            # A union: same step, neither group holding the other, not all.
                            if not same or (cand ^ m) == 0 or (cand ^ o) == 0:
                                continue
                            if mv._popcount(np.uint64(cand)) == k:
                                continue
                        new = True
                        for r in range(nf):
                            if f_mask[r] == cand and f_step[r] == s:
                                new = False
                                break
                        if pending == 1:
                            pending = 0
                            if not new:
                                break  # listed already: no unions either
                            q = nf  # scan from the group itself back to the oldest
                        elif not new:
                            continue
                        if nf >= group_limit:
                            ctx[1] = node
                            return TOO_MANY_GROUPS
                        if nf >= f_mask.shape[0]:
                            grown = np.empty(2 * nf, dtype=np.int64)
                            grown[:nf] = f_mask
                            f_mask = grown
                            grown = np.empty(2 * nf, dtype=np.int64)
                            grown[:nf] = f_step
                            f_step = grown
                        f_mask[nf] = cand
                        f_step[nf] = s
                        nf += 1
                        mv.shift_child(states[node], child, 0, None, k, cand, d, s)
                        if n_states >= states.shape[0] or 2 * (n_states + 1) > table.shape[0]:
                            ctx[0] = n_states
                            ctx[1] = node
                            return NEED_STATES
                        if mv.find_or_insert(states, n_states, table, child) < 0:
                            parent[n_states] = node
                            move[n_states, 0] = cand
                            move[n_states, 1] = d
                            move[n_states, 2] = s
                            n_states += 1
                            ctx[0] = n_states
                    s += 1
        node += 1
        done += 1
    ctx[0] = n_states
    ctx[1] = node
    return STUCK


#: Slots of ``params`` of :func:`first_tree`: max_states (one part), group_limit, the most
#: nodes to expand in the call, max_total_states (-1: none).
MAX_STATES, GROUP_LIMIT, BUDGET, MAX_TOTAL = 0, 1, 2, 3
#: ``ctx`` of :func:`first_tree` has the slots and status codes of
#: :func:`chaingeo.solvers.motion.levelsearch.greedy` (its tree is decoded the same way); no memo.


@njit(cache=True)
def run_part(
    part: PartGaps, start: I16, max_states: int, budget: int, group_limit: int
) -> tuple[int, I16, I64, I64, I64]:  # fmt: skip
    """:func:`part_search` from ``start`` with buffers grown as needed, up to ``max_states``
    states: ``(status, states, parent, move, ctx)`` (status ``-STATE_CAP`` past the cap)."""
    w = start.shape[0]
    cap = max(2, min(64, max_states))
    states = np.zeros((cap, w), dtype=np.int16)
    parent = np.full(cap, -1, dtype=np.int64)
    move = np.zeros((cap, 3), dtype=np.int64)
    table = bfs.fit_table(np.full(1, -1, dtype=np.int64), states, 0)
    mv.find_or_insert(states, 0, table, start)
    ctx = np.zeros(5, dtype=np.int64)
    ctx[0] = 1
    while True:
        before = ctx[1]
        status = part_search(part, bfs.Tree(states, parent, move, table), ctx, budget, group_limit)
        budget -= ctx[1] - before
        if status != NEED_STATES:
            return status, states, parent, move, ctx
        if ctx[0] + 1 >= states.shape[0]:
            cap = states.shape[0]
            if cap >= max_states:
                return -STATE_CAP, states, parent, move, ctx
            states, parent, move = bfs.grow_search(states, parent, move, min(2 * cap, max_states))
        table = bfs.fit_table(table, states, ctx[0])


@njit(cache=True)
def first_tree(
    vox_all: I64,
    starts_all: I64,
    lo_all: I64,
    hi_all: I64,
    start: I64,
    params: I64,
    ctx: I64,
    nodes: I64,
    moves: I64,
) -> int:
    """BurrTools' disassembly tree of the whole puzzle (pieces ``0..n-1`` at offsets
    ``start``) in one call: each part's first separation (:func:`part_search`), the part left
    behind searched before the part removed. Returns the root's row in ``nodes`` (first move,
    move count, removed sub-tree, left sub-tree; -1: a single piece), -1 when some part cannot
    come apart (no solution), -2 on a status set in ``ctx``. ``moves`` rows: global mask,
    direction, distance (-1: leaves for good)."""
    n = starts_all.shape[0] - 1
    # Pending parts (a stack): members mask, the tree row and column to fill, offsets.
    p_mask = np.zeros(n, dtype=np.int64)
    p_row = np.zeros(n, dtype=np.int64)
    p_col = np.zeros(n, dtype=np.int64)
    p_off = np.zeros((n, n, 3), dtype=np.int64)
    p_mask[0] = (np.int64(1) << n) - 1
    p_row[0] = -1
    for i in range(n):
        for t in range(3):
            p_off[0, i, t] = start[i, t]
    top = 1
    root = -1
    no_sides = np.full(2, -1, dtype=np.int64)  # filled in when the parts are done
    memo_rel = np.full((n, n, 3), mv.NO_OFFSET, dtype=np.int64)  # mv.gap_memo: shared by parts
    memo_gap = np.zeros((3, n, n), dtype=np.int64)
    gaps = np.empty((3, n, n), dtype=np.int64)
    todo = np.empty(n, dtype=np.int64)
    no_parent = np.full(1, -1, dtype=np.int64)  # a separation at the start: no moves before
    no_move = np.zeros((1, 3), dtype=np.int64)
    while top > 0:
        top -= 1
        gmask = p_mask[top]
        k = mv._popcount(np.uint64(gmask))
        members = np.empty(k, dtype=np.int64)
        j = 0
        for i in range(n):
            if (gmask >> i) & 1:
                members[j] = i
                j += 1
        row = np.empty(3 * k, dtype=np.int16)
        for j in range(k):
            for t in range(3):
                row[3 * j + t] = p_off[top, j, t] - p_off[top, 0, t]
        parent_row = p_row[top]
        parent_col = p_col[top]
        if params[MAX_TOTAL] >= 0 and ctx[STATES] > params[MAX_TOTAL]:
            ctx[STATUS] = TOTAL_CAP
            return -2
        # Most parts come apart at once: their start state is tried before any search is set up.
        mv.memo_pair_gaps(vox_all, starts_all, lo_all, hi_all, members, p_off[top], gaps,
                          memo_rel, memo_gap)  # fmt: skip
        mask, direction = _leaving(gaps, k, todo)
        if mask != 0:
            status, states, parent, move = SEPARATED, row.reshape(1, 3 * k), no_parent, no_move
            pctx = np.array([1, 0, 0, mask, direction], dtype=np.int64)
        else:
            part = PartGaps(vox_all, starts_all, lo_all, hi_all, members, memo_rel, memo_gap)
            status, states, parent, move, pctx = run_part(
                part, row, params[MAX_STATES], params[BUDGET] - ctx[EXPANDED], params[GROUP_LIMIT]
            )
        ctx[EXPANDED] += pctx[1]
        ctx[STATES] += pctx[0]
        if status == PAUSED:
            ctx[STATUS] = OVER_BUDGET
            return -2
        if status == -STATE_CAP:
            ctx[STATUS] = STATE_CAP
            ctx[INFO] = k
            return -2
        if status == TOO_MANY_GROUPS:
            ctx[STATUS] = GROUP_CAP
            return -2
        if status == STUCK:
            return -1
        at, mask, direction = pctx[2], pctx[3], pctx[4]
        idx = _record(LevelTree(nodes, moves), ctx, parent, move, members, at, mask, direction,
                      no_sides)  # fmt: skip
        if idx == -2:
            return -2
        if parent_row < 0:
            root = idx
        else:
            nodes[parent_row, parent_col] = idx
        # Push the removed part, then the part left (searched first, as BurrTools does).
        for side in range(2):  # 0: removed (column 2), 1: left (column 3)
            sub = 0
            c = 0
            for j in range(k):
                if ((mask >> j) & 1) == (1 - side):
                    sub |= np.int64(1) << members[j]
                    for t in range(3):
                        p_off[top, c, t] = states[at, 3 * j + t]
                    c += 1
            if c < 2:
                continue
            p_mask[top] = sub
            p_row[top] = idx
            p_col[top] = 2 + side
            top += 1
    return root


@dataclass(frozen=True)
class FirstSplit:
    """A part's first separation: the moves (ending with the removal), the pieces removed and
    the pieces left (global indices, in order) with their offsets just before the removal."""

    moves: tuple[Move, ...]
    removed: tuple[int, ...]
    removed_offsets: np.ndarray
    left: tuple[int, ...]
    left_offsets: np.ndarray


#: Nodes expanded between two readings of the clock.
CHUNK = 20000


def first_split(
    table: PieceTable,
    members: tuple[int, ...],
    offsets: np.ndarray,
    limits: SearchLimits,
    deadline: Deadline,
) -> tuple[FirstSplit | None, int]:
    """The Python face of :func:`part_search` (for piece groups and long searches): the first
    separation of a part in BurrTools' order, or None when it cannot come apart; and the
    states searched. Checks ``deadline`` every :data:`CHUNK` nodes; caps raise
    :class:`SearchLimitError`."""
    k = part_size(members)
    local = np.asarray(members, dtype=np.int64)
    memo_rel, memo_gap = mv.gap_memo(len(table.names))
    off = np.asarray(offsets, dtype=np.int64).reshape(k, 3)
    start = (off - off[0]).reshape(-1).astype(np.int16)
    max_states = limits.max_states
    cap = max(2, min(64, max_states))
    states = np.zeros((cap, 3 * k), dtype=np.int16)
    parent = np.full(cap, -1, dtype=np.int64)
    move = np.zeros((cap, 3), dtype=np.int64)
    hash_table = np.full(1 << (4 * cap - 1).bit_length(), -1, dtype=np.int64)
    mv.find_or_insert(states, 0, hash_table, start)
    ctx = np.array([1, 0, 0, 0, 0], dtype=np.int64)
    while True:
        deadline.check()
        part = PartGaps(table.vox, table.starts, table.lo, table.hi, local, memo_rel, memo_gap)
        tree = bfs.Tree(states, parent, move, hash_table)
        status = part_search(part, tree, ctx, CHUNK, limits.group_limit)
        if status == NEED_STATES:
            if ctx[0] + 1 >= states.shape[0]:
                if states.shape[0] >= max_states:
                    raise SearchLimitError(
                        f"state cap of {max_states} reached in a {k}-piece part",
                        "max_states",
                    )
                new = min(2 * states.shape[0], max_states)
                states, parent, move = bfs.grow_search(states, parent, move, new)
            hash_table = bfs.fit_table(hash_table, states, int(ctx[0]))
        elif status == TOO_MANY_GROUPS:
            raise SearchLimitError(
                f"more than {limits.group_limit} movable groups along one direction in one state",
                "group_limit",
            )
        elif status != PAUSED:
            break
    n_states = int(ctx[0])
    if status == STUCK:
        return None, n_states
    at, mask, direction = int(ctx[2]), int(ctx[3]), int(ctx[4])

    def named(local: int, d: int, dist: int | None) -> Move:
        pieces = tuple(table.names[members[i]] for i in range(k) if local >> i & 1)
        return Move(pieces, DIRECTION_NAMES[d], dist)

    path: list[Move] = [named(mask, direction, None)]
    q = at
    while q > 0:
        m = move[q]
        path.append(named(int(m[0]), int(m[1]), int(m[2])))
        q = int(parent[q])
    here = states[at].astype(np.int64).reshape(k, 3)
    inside = [i for i in range(k) if mask >> i & 1]
    outside = [i for i in range(k) if not mask >> i & 1]
    split = FirstSplit(
        tuple(path[::-1]),
        tuple(members[i] for i in inside),
        here[inside],
        tuple(members[i] for i in outside),
        here[outside],
    )
    return split, n_states
