"""The BurrTools level search of one assembly in one numba call.

Python set-up per part search (arrays, removals, splits, moves) cost ~40 us, several times the
search itself on a six-piece burr, so the whole recursion runs here: breadth first to the first
layer with removals (:func:`chaingeo.solvers.motion.bfs_kernel.expand`), removals tried single
pieces first, then both parts recursively, memoised per part configuration; the result is a flat
tree that :mod:`chaingeo.solvers.motion.disassemble` decodes. Same order, tie-breaks and caps as
its Python original, which still serves turning pieces and piece groups
(:meth:`chaingeo.solvers.motion.disassemble._Solver.greedy`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from chaingeo.core.arrays import I16, I64
from chaingeo.kernels.jit import njit
from chaingeo.solvers.motion import bfs_kernel as bfs
from chaingeo.solvers.motion import kinematics_kernel as mv

#: Status codes in ``ctx[STATUS]`` (0: fine): a cap reached, more nodes expanded than
#: ``params[BUDGET]``, or a buffer to enlarge and rerun.
STATE_CAP, GROUP_CAP, TOTAL_CAP, OVER_BUDGET, NEED_BUFFERS = 1, 3, 8, 9, 10
#: Slots of ``ctx``: counts of tree nodes, moves and memo entries, states over all searches,
#: status and its detail (the part's piece count for STATE_CAP), nodes expanded.
N_NODES, N_MOVES, N_MEMO, STATES, STATUS, INFO, EXPANDED = 0, 1, 2, 3, 4, 5, 6
#: Slots of ``params``: max_group (-1: any), group_limit, max_states, max_total_states (-1:
#: none), the most nodes to expand (the kernel cannot read the clock: a longer search is left
#: to the Python search, which checks the deadline as it goes).
MAX_GROUP, GROUP_LIMIT, MAX_STATES, MAX_TOTAL, BUDGET = 0, 1, 2, 3, 4
#: Rows a part's search starts with (most parts come apart in a few states).
_FIRST_CAP = 64


class Puzzle(NamedTuple):
    """The whole puzzle's piece arrays that every part gathers its rows from
    (:class:`chaingeo.solvers.motion.partsearch.PieceTable`: voxels sorted per axis, where each
    piece's rows start, boxes)."""

    vox: I64
    starts: I64
    lo: I64
    hi: I64


class LevelTree(NamedTuple):
    """The tree :func:`greedy` writes: ``nodes`` rows (first move, move count, removed
    sub-tree, left sub-tree) and ``moves`` rows (global mask, direction, distance; -1: a
    removal); ``ctx`` counts the rows used."""

    nodes: I64
    moves: I64


class Memo(NamedTuple):
    """Parts already searched: ``keys`` rows (the part's pieces as a mask in four int16, then
    offsets relative to its first piece), their open-addressing ``table``
    (:func:`chaingeo.solvers.motion.kinematics_kernel.find_or_insert`) and ``val`` (the part's tree
    index; -1: cannot come apart)."""

    keys: I16
    table: I64
    val: I64


@njit(cache=True)
def part_arrays(
    vox_all: I64, starts_all: I64, lo_all: I64, hi_all: I64, members: I64
) -> tuple[I64, I64, I64, I64]:
    """The part's rows of the piece table
    (:meth:`chaingeo.solvers.motion.partsearch.PieceTable.part_arrays`)."""
    k = members.shape[0]
    starts = np.zeros(k + 1, dtype=np.int64)
    for i in range(k):
        m = members[i]
        starts[i + 1] = starts[i] + starts_all[m + 1] - starts_all[m]
    vox = np.empty((3, starts[k], 3), dtype=np.int64)
    lo = np.empty((k, 3), dtype=np.int64)
    hi = np.empty((k, 3), dtype=np.int64)
    for i in range(k):
        m = members[i]
        for a in range(3):
            for r in range(starts_all[m + 1] - starts_all[m]):
                for t in range(3):
                    vox[a, starts[i] + r, t] = vox_all[a, starts_all[m] + r, t]
        for t in range(3):
            lo[i, t] = lo_all[m, t]
            hi[i, t] = hi_all[m, t]
    return vox, starts, lo, hi


@njit(cache=True)
def _global(mask: np.int64, members: I64) -> np.int64:
    out = np.int64(0)
    for i in range(members.shape[0]):
        if (mask >> i) & 1:
            out |= np.int64(1) << members[i]
    return out


@njit(cache=True)
def _memo_row(members: I64, width: int) -> I16:
    """A memo key with the part's pieces (a 64-bit mask in four int16) filled in."""
    g = np.int64(0)
    for i in range(members.shape[0]):
        g |= np.int64(1) << members[i]
    row = np.zeros(width, dtype=np.int16)
    for t in range(4):
        row[t] = np.int16((g >> (16 * t)) & 0xFFFF)
    return row


@njit(cache=True)
def _memo_slot(members: I64, offsets: I64, ctx: I64, memo: Memo) -> int:
    """The memo entry of the part (its pieces, and offsets relative to its first piece):
    ``-1 - index`` when new, -(2**40) when the memo is full."""
    memo_keys, memo_table = memo.keys, memo.table
    row = _memo_row(members, memo_keys.shape[1])
    for i in range(members.shape[0]):
        for t in range(3):
            row[4 + 3 * i + t] = offsets[i, t] - offsets[0, t]
    n_memo = ctx[N_MEMO]
    if 2 * (n_memo + 1) > memo_table.shape[0] or n_memo >= memo_keys.shape[0]:
        idx = mv.find_row(memo_keys, memo_table, row)
        return idx if idx >= 0 else -(1 << 40)
    got = mv.find_or_insert(memo_keys, n_memo, memo_table, row)
    if got < 0:
        ctx[N_MEMO] = n_memo + 1
    return got


@njit(cache=True)
def greedy(
    puzzle: Puzzle, members: I64, offsets: I64, params: I64, ctx: I64, out: LevelTree, memo: Memo
) -> int:
    """The tree of the part ``members`` (global piece indices, ascending) at ``offsets``: its
    index in ``out.nodes`` (-1: a single piece), -1 if it cannot be taken apart, -2 on a status
    set in ``ctx``. Parts met before come from ``memo``."""
    slot = _memo_slot(members, offsets, ctx, memo)
    if slot == -(1 << 40):
        ctx[STATUS] = NEED_BUFFERS
        return -2
    if slot >= 0:
        return int(memo.val[slot])
    slot = -1 - slot
    if params[MAX_TOTAL] >= 0 and ctx[STATES] > params[MAX_TOTAL]:
        ctx[STATUS] = TOTAL_CAP
        return -2
    k = members.shape[0]
    w = 3 * k
    max_states = params[MAX_STATES]
    vox, starts, lo, hi = part_arrays(puzzle.vox, puzzle.starts, puzzle.lo, puzzle.hi, members)
    cap = max(2, min(_FIRST_CAP, max_states))
    states = np.zeros((cap, w), dtype=np.int16)
    parent = np.full(cap, -1, dtype=np.int64)
    move = np.zeros((cap, 3), dtype=np.int64)
    size = 1
    while size < 4 * cap:
        size *= 2
    table = np.full(size, -1, dtype=np.int64)
    seps = np.zeros((64, 3), dtype=np.int64)
    moves_buf = np.zeros((64, 4), dtype=np.int64)
    groups_buf = np.empty(min(params[GROUP_LIMIT], 1 << 16) + 1, dtype=np.uint64)
    row = np.empty(w, dtype=np.int16)
    for i in range(k):
        for t in range(3):
            row[3 * i + t] = offsets[i, t] - offsets[0, t]
    mv.find_or_insert(states, 0, table, row)
    n_states = 1
    n_seps = 0
    layers = np.zeros(cap + 2, dtype=np.int64)
    layers[1] = 1
    n_layers = 2
    node = 0
    result = -1
    while result == -1 and layers[n_layers - 1] != layers[n_layers - 2]:
        first_sep = n_seps
        while True:
            before = node
            status, node, n_states, n_seps, n_layers = bfs.expand(
                bfs.Tree(states, parent, move, table), n_states, node, layers, n_layers,
                max_states, params[BUDGET] - ctx[EXPANDED],
                mv.Pieces(vox, starts, lo, hi, params[MAX_GROUP], params[GROUP_LIMIT],
                          moves_buf, groups_buf),
                seps, n_seps, False,
            )  # fmt: skip
            ctx[EXPANDED] += node - before
            if status == bfs.DONE:
                break
            if status == bfs.PAUSED:
                ctx[STATUS] = OVER_BUDGET
                return -2
            if status == bfs.NEED_STATES:
                cap = states.shape[0]
                if n_states + 1 >= cap:
                    if cap >= max_states:
                        ctx[STATUS] = STATE_CAP
                        ctx[INFO] = k
                        return -2
                    new_cap = min(2 * cap, max_states)
                    states, parent, move = bfs.grow_search(states, parent, move, new_cap)
                    grown_layers = np.zeros(new_cap + 2, dtype=np.int64)
                    grown_layers[: cap + 2] = layers
                    layers = grown_layers
                table = bfs.fit_table(table, states, n_states)
            elif status == bfs.NEED_MOVES:
                moves_buf = np.zeros((2 * moves_buf.shape[0], 4), dtype=np.int64)
            elif status == bfs.NEED_SEPS:
                grown_seps = np.zeros((2 * seps.shape[0], 3), dtype=np.int64)
                grown_seps[: seps.shape[0]] = seps
                seps = grown_seps
            else:  # TOO_MANY_GROUPS
                ctx[STATUS] = GROUP_CAP
                return -2
        m = n_seps - first_sep
        if m == 0:
            continue
        # Like BurrTools, prefer taking out single pieces (then smaller groups) first.
        # Stable by piece count; the removals already come in node order.
        found = np.empty((m, 3), dtype=np.int64)
        r = 0
        for size_r in range(1, k):
            for q in range(first_sep, n_seps):
                if mv._popcount(np.uint64(seps[q, 1])) == size_r:
                    found[r] = seps[q]
                    r += 1
        keep = mv.unique_removals(states, found[:, 0].copy(), found[:, 1].copy(), k)
        for r in range(m):
            if not keep[r]:
                continue
            at, mask = found[r, 0], found[r, 1]
            sides = np.empty(2, dtype=np.int64)  # removed, left
            ok = True
            for side in range(2):
                sub = np.empty(k, dtype=np.int64)
                k_sub = 0
                for i in range(k):
                    if ((mask >> i) & 1) == (1 - side):
                        sub[k_sub] = i
                        k_sub += 1
                sides[side] = -1
                if k_sub == 1:
                    continue
                sub_members = np.empty(k_sub, dtype=np.int64)
                sub_off = np.empty((k_sub, 3), dtype=np.int64)
                for j in range(k_sub):
                    sub_members[j] = members[sub[j]]
                    for t in range(3):
                        sub_off[j, t] = states[at, 3 * sub[j] + t]
                got = greedy(puzzle, sub_members, sub_off, params, ctx, out, memo)
                if got == -2:
                    return -2
                if got == -1:
                    ok = False
                    break
                sides[side] = got
            if not ok:
                continue
            result = _record(out, ctx, parent, move, members, at, mask, found[r, 2], sides)
            if result == -2:
                return -2
            break
    ctx[STATES] += n_states
    memo.val[slot] = result
    if result == -1 and not _remember_stuck(members, states, n_states, ctx, memo):
        return -2
    return result


@njit(cache=True)
def _remember_stuck(members: I64, states: I16, n_states: int, ctx: I64, memo: Memo) -> bool:
    """Every state of a part's component that cannot come apart goes into the memo as stuck
    (from any of them the search would see the same component), so that no state of it is
    searched again; False (NEED_BUFFERS) when the memo is full."""
    memo_keys, memo_table, memo_val = memo
    row = _memo_row(members, memo_keys.shape[1])
    w = states.shape[1]
    for node in range(1, n_states):
        for t in range(w):
            row[4 + t] = states[node, t]
        n_memo = ctx[N_MEMO]
        if 2 * (n_memo + 1) > memo_table.shape[0] or n_memo >= memo_keys.shape[0]:
            ctx[STATUS] = NEED_BUFFERS
            return False
        if mv.find_or_insert(memo_keys, n_memo, memo_table, row) < 0:
            memo_val[n_memo] = -1
            ctx[N_MEMO] = n_memo + 1
    return True


@njit(cache=True)
def _record(
    out: LevelTree, ctx: I64, parent: I64, move: I64, members: I64, at: int, mask: np.int64,
    direction: int, sides: I64,
) -> int:  # fmt: skip
    """Append a tree node: the path to ``at``, then the removal; -2 when a buffer is full."""
    nodes, moves = out
    length = 1
    p = at
    while p > 0:
        length += 1
        p = parent[p]
    first = ctx[N_MOVES]
    if first + length > moves.shape[0] or ctx[N_NODES] >= nodes.shape[0]:
        ctx[STATUS] = NEED_BUFFERS
        return -2
    p = at
    i = first + length - 2
    while p > 0:
        moves[i, 0] = _global(move[p, 0], members)
        moves[i, 1] = move[p, 1]
        moves[i, 2] = move[p, 2]
        i -= 1
        p = parent[p]
    last = first + length - 1
    moves[last, 0] = _global(mask, members)
    moves[last, 1] = direction
    moves[last, 2] = -1
    ctx[N_MOVES] = first + length
    idx = ctx[N_NODES]
    nodes[idx, 0] = first
    nodes[idx, 1] = length
    nodes[idx, 2] = sides[0]
    nodes[idx, 3] = sides[1]
    ctx[N_NODES] = idx + 1
    return int(idx)
