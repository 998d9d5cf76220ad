"""Turn moves on flat integer arrays (numba): which groups can turn 90 degrees about which line.
The reference it must equal is :mod:`chaingeo.core.turns`.

The semantics are :mod:`chaingeo.core.turns` and :func:`chaingeo.core.kinematics.legal_turns` (the
reference): a group turns about a line parallel to axis ``a`` through cell centres or cell corners
(``centre2``, doubled cell units, the two coordinates across ``a`` of one parity) inside the
group's bounding box, legal when it sweeps through no other piece of its part.

As for translations (:mod:`chaingeo.solvers.motion.kinematics_kernel`), the legal groups of one
turn (axis,
sense, centre) are the sets closed under a relation between pieces, here "turning alone, ``j`` would
sweep through ``i``": a group sweeps through nothing outside it exactly when it holds everyone its
members sweep through. The relation comes from the exact swept-cell *stencils* of
:mod:`chaingeo.solvers.motion.turns_sweep_kernel` (one fixed table of relative positions near the
axis, looked up
in a hash of the state's cells) and, for cells further out, the exact pair test against the other
pieces' cells of the same slice; the closed sets come from
:func:`chaingeo.solvers.motion.kinematics_kernel.closed_groups`, never from trying subsets. No
table or grid
grows with how far apart the pieces stand: the work per centre is bounded by the cells (the centres
are those of the part's box).

A part's pieces may stand in any of the 24 orientations, so every piece is pre-rotated: slot
``24 p + r`` holds piece ``p`` turned by ``ROTATIONS[r]`` (cells ``R v``), sorted per axis for
the gap kernel. A state is one ``int16`` row of ``3 n`` offsets then ``n`` rotation indices.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import NamedTuple

import numpy as np

from chaingeo.core.arrays import I64, U64
from chaingeo.core.geometry import ROTATIONS, Shape, rotation_index
from chaingeo.core.turns import quarter_index
from chaingeo.kernels.jit import njit
from chaingeo.solvers.motion import bfs_kernel as bfs
from chaingeo.solvers.motion import kinematics_kernel as mv
from chaingeo.solvers.motion.turns_sweep_kernel import (
    FAR_LIMIT,
    StencilArrays,
    rmax2,
    rmin2,
    turn_hit,
)

N_ROT = 24
#: Extra status of the search kernel: a cell lies beyond
#: :data:`chaingeo.solvers.motion.turns_sweep_kernel.FAR_LIMIT` of a turn's axis, where the exact
#: int64 test
#: would overflow.
TOO_FAR = 5
#: Move kinds in the search's move rows: 0..5 translations (``DIRECTIONS`` order), then turns
#: ``TURN_BASE + 2 axis + (0 for +90, 1 for -90)``.
TURN_BASE = 6

#: ``COMPOSE[q, r]``: index of ``ROTATIONS[q] @ ROTATIONS[r]``.
COMPOSE = np.array(
    [[rotation_index(ROTATIONS[q] @ ROTATIONS[r]) for r in range(N_ROT)] for q in range(N_ROT)],
    dtype=np.int64,
)
#: The 24 rotation matrices, (24, 3, 3).
MATRICES = np.ascontiguousarray(np.stack(ROTATIONS), dtype=np.int64)
#: ``QUARTERS[axis, 0 | 1]``: rotation index of the +90 / -90 degree turn about that axis.
QUARTERS = np.array([[quarter_index(a, 1), quarter_index(a, -1)] for a in range(3)], np.int64)


class TurnTable:
    """Every piece in every orientation: sorted voxels, bounding boxes, rod flags.

    ``rods[name]`` maps a cell of the piece (assembled frame) to the axis (0, 1, 2) of a round
    rod filling it: such a cell turning about its own axis line sweeps nothing but itself."""

    def __init__(
        self, shapes: Mapping[str, Shape], rods: Mapping[str, Mapping[tuple[int, int, int], int]]
    ) -> None:
        self.names: tuple[str, ...] = tuple(sorted(shapes))
        self.shapes = {n: shapes[n] for n in self.names}
        self.rods = {n: dict(rods.get(n, {})) for n in self.names}
        self._parts: dict[tuple[int, ...], tuple[I64, I64, I64, I64, I64]] = {}
        #: Row buffer for :func:`node_turns`, kept (and grown) across states.
        self.rows_buf = np.zeros((256, 6), dtype=np.int64)

    def part_arrays(self, members: Sequence[int]) -> tuple[I64, I64, I64, I64, I64]:
        """:meth:`build_part_arrays`, kept per set of members (a position's parts recur)."""
        key = tuple(members)
        got = self._parts.get(key)
        if got is None:
            got = self._parts[key] = self.build_part_arrays(members)
        return got

    def build_part_arrays(self, members: Sequence[int]) -> tuple[I64, I64, I64, I64, I64]:
        """``(vox, starts, lo, hi, rod)`` for the pieces ``members`` (indices into ``names``),
        slot ``24 i + r`` for the ``i``-th member turned by ``ROTATIONS[r]``: ``vox[a]`` sorted
        by (the two other axes, then ``a``), ``rod`` aligned with ``vox[0]`` (-1: no rod)."""
        per_axis: list[list[I64]] = [[], [], []]
        rod_rows: list[I64] = []
        sizes: list[int] = []
        lo = np.zeros((len(members) * N_ROT, 3), dtype=np.int64)
        hi = np.zeros((len(members) * N_ROT, 3), dtype=np.int64)
        for i, m in enumerate(members):
            name = self.names[m]
            base = np.asarray(self.shapes[name].voxels, dtype=np.int64)
            rod_axis = np.array(
                [self.rods[name].get((int(x), int(y), int(z)), -1) for x, y, z in base],
                dtype=np.int64,
            )
            for r in range(N_ROT):
                v = base @ MATRICES[r].T
                axes = np.full(len(v), -1, dtype=np.int64)
                for k, a in enumerate(rod_axis.tolist()):
                    if a >= 0:
                        axes[k] = int(np.flatnonzero(MATRICES[r][:, a])[0])
                for a in range(3):
                    u, w = (a + 1) % 3, (a + 2) % 3
                    order = np.lexsort((v[:, a], v[:, w], v[:, u]))
                    per_axis[a].append(v[order])
                    if a == 0:
                        rod_rows.append(axes[order])
                lo[i * N_ROT + r] = v.min(axis=0)
                hi[i * N_ROT + r] = v.max(axis=0)
                sizes.append(len(v))
        starts = np.zeros(len(sizes) + 1, dtype=np.int64)
        starts[1:] = np.cumsum(sizes)
        vox = np.empty((3, int(starts[-1]), 3), dtype=np.int64)
        for a in range(3):
            vox[a] = np.concatenate(per_axis[a])
        return vox, starts, lo, hi, np.concatenate(rod_rows)


@njit(cache=True)
def gather(
    vox_all: I64, starts_all: I64, lo_all: I64, hi_all: I64, rod_all: I64, rot: I64
) -> tuple[I64, I64, I64, I64, I64]:
    """The per-piece arrays of one state (piece ``i`` in orientation ``rot[i]``), in the layout
    of :func:`chaingeo.solvers.motion.kinematics_kernel.node_moves`, and the rod axes aligned with
    ``vox[0]``."""
    n = rot.shape[0]
    starts = np.zeros(n + 1, dtype=np.int64)
    for i in range(n):
        s = i * 24 + rot[i]
        starts[i + 1] = starts[i] + starts_all[s + 1] - starts_all[s]
    vox = np.empty((3, starts[n], 3), dtype=np.int64)
    rod = np.empty(starts[n], dtype=np.int64)
    lo = np.empty((n, 3), dtype=np.int64)
    hi = np.empty((n, 3), dtype=np.int64)
    for i in range(n):
        s = i * 24 + rot[i]
        a0 = starts_all[s]
        for k in range(starts[i + 1] - starts[i]):
            for a in range(3):
                for t in range(3):
                    vox[a, starts[i] + k, t] = vox_all[a, a0 + k, t]
            rod[starts[i] + k] = rod_all[a0 + k]
        for t in range(3):
            lo[i, t] = lo_all[s, t]
            hi[i, t] = hi_all[s, t]
    return vox, starts, lo, hi, rod


@njit(cache=True)
def _hash_slot(keys: I64, key: int, bits: int) -> int:
    """The slot of ``key`` in the open-addressing table ``keys`` (or the empty slot it would
    take)."""
    mask = np.int64((1 << bits) - 1)
    mixed = (np.uint64(key) * np.uint64(0x9E3779B97F4A7C15)) >> np.uint64(64 - bits)
    h = np.int64(mixed)
    while keys[h] != -1 and keys[h] != key:
        h = (h + np.int64(1)) & mask
    return int(h)


@njit(cache=True)
def node_turns(
    vox: I64,
    starts: I64,
    lo: I64,
    hi: I64,
    rod: I64,
    off: I64,
    st_start: I64,
    st_end: I64,
    st_cells: I64,
    bound: int,
    max_group: int,
    group_limit: int,
    groups: U64,
    out: I64,
) -> int:
    """List the legal turns of one state into ``out`` rows ``(mask, axis, sense, c0, c1,
    c2)`` (sense 0: +90, 1: -90; ``c`` the doubled centre, its axis component 0). Returns the
    row count; -1 if ``out`` is too small, -2 past ``group_limit`` groups of one turn, -3 when
    a cell lies beyond :data:`chaingeo.solvers.motion.turns_sweep_kernel.FAR_LIMIT` of a centre.

    A cell within ``bound`` of the axis looks its stencil (``st_*``,
    :mod:`chaingeo.solvers.motion.turns_sweep_kernel`) up in a hash of the occupied cells; a cell
    further out is
    tested pair by pair against the other pieces' cells of its slice. Memory is linear in the cells,
    whatever their spread."""
    n = starts.shape[0] - 1
    full = (np.uint64(1) << np.uint64(n)) - np.uint64(1)
    total = starts[n]
    cells = np.empty((total, 3), dtype=np.int64)
    owner = np.empty(total, dtype=np.int64)
    for i in range(n):
        for k in range(starts[i], starts[i + 1]):
            owner[k] = i
            for t in range(3):
                cells[k, t] = vox[0, k, t] + off[i, t]
    glo = np.empty(3, dtype=np.int64)
    ghi = np.empty(3, dtype=np.int64)
    for t in range(3):
        glo[t] = cells[:, t].min()
        ghi[t] = cells[:, t].max()
    dims = ghi - glo + 1
    bits = 4
    while (1 << bits) < 4 * total:
        bits += 1
    keys = np.full(1 << bits, -1, dtype=np.int64)
    key_cell = np.full(1 << bits, -1, dtype=np.int64)  # slot -> the cell index k there
    for k in range(total):
        key = ((cells[k, 0] - glo[0]) * dims[1] + cells[k, 1] - glo[1]) * dims[2] + (
            cells[k, 2] - glo[2]
        )
        h = _hash_slot(keys, key, bits)
        keys[h] = key
        key_cell[h] = k
    # each piece's bounding box now, for the "centre inside the group's box" rule
    plo = np.empty((n, 3), dtype=np.int64)
    phi = np.empty((n, 3), dtype=np.int64)
    for i in range(n):
        for t in range(3):
            plo[i, t] = lo[i, t] + off[i, t]
            phi[i, t] = hi[i, t] + off[i, t]
    hits = np.zeros(n, dtype=np.uint64)
    reach = np.zeros(n, dtype=np.uint64)
    r_lo = np.empty(total, dtype=np.int64)
    r_hi = np.empty(total, dtype=np.int64)
    p_lo = np.empty(n, dtype=np.int64)
    p_hi = np.empty(n, dtype=np.int64)
    c = np.empty(3, dtype=np.int64)
    hit_cell = np.empty(3, dtype=np.int64)
    rows = 0
    for a in range(3):
        u = (a + 1) % 3
        v = (a + 2) % 3
        # the cells by slice across ``a``: cells ``order[s_lo[k]:s_hi[k]]`` share cell k's slice
        order = np.argsort(cells[:, a], kind="mergesort")
        s_lo = np.empty(total, dtype=np.int64)
        s_hi = np.empty(total, dtype=np.int64)
        first = 0
        for e in range(1, total + 1):
            if e == total or cells[order[e], a] != cells[order[first], a]:
                for f in range(first, e):
                    s_lo[order[f]] = first
                    s_hi[order[f]] = e
                first = e
        for cu in range(2 * glo[u] - 1, 2 * ghi[u] + 2):
            for cv in range(2 * glo[v] - 1, 2 * ghi[v] + 2):
                if (cu - cv) % 2 != 0:
                    continue
                # squares meet turning only if their ranges of radii overlap: per cell, per
                # piece, and so which pieces each piece may reach at all (sharing a slice)
                p_lo[:] = 1 << 62
                p_hi[:] = -1
                for k in range(total):
                    su = 2 * cells[k, u] - cu
                    sv = 2 * cells[k, v] - cv
                    r_lo[k] = rmin2(su, sv)
                    r_hi[k] = rmax2(su, sv)
                    p_lo[owner[k]] = min(p_lo[owner[k]], r_lo[k])
                    p_hi[owner[k]] = max(p_hi[owner[k]], r_hi[k])
                for i in range(n):
                    reach[i] = np.uint64(0)
                    for o in range(n):
                        if (
                            o != i
                            and plo[i, a] <= phi[o, a]
                            and plo[o, a] <= phi[i, a]
                            and max(p_lo[i], p_lo[o]) < min(p_hi[i], p_hi[o])
                        ):
                            reach[i] |= np.uint64(1) << np.uint64(o)
                for sense in range(2):
                    for i in range(n):
                        hits[i] = np.uint64(1) << np.uint64(i)
                    for k in range(total):
                        i = owner[k]
                        todo = reach[i] & ~hits[i]
                        if todo == 0:
                            continue  # it sweeps through every piece it may reach
                        near = False
                        for o in range(n):
                            if todo & (np.uint64(1) << np.uint64(o)) and max(
                                r_lo[k], p_lo[o]
                            ) < min(r_hi[k], p_hi[o]):
                                near = True
                                break
                        if not near:
                            continue  # no piece left to hit at its radii
                        su = 2 * cells[k, u] - cu
                        sv = 2 * cells[k, v] - cv
                        if su == 0 and sv == 0 and rod[k] == a:
                            continue  # a round rod spinning about its own axis
                        need = max(abs(su), abs(sv))
                        if need > FAR_LIMIT:
                            return -3
                        if need > bound:  # far out: the exact test against its slice
                            for e in range(s_lo[k], s_hi[k]):
                                k2 = order[e]
                                o = owner[k2]
                                bo = np.uint64(1) << np.uint64(o)
                                if hits[i] & bo:
                                    continue
                                fu = 2 * cells[k2, u] - cu
                                fv = 2 * cells[k2, v] - cv
                                if fu == 0 and fv == 0 and rod[k2] == a:
                                    continue  # a rod spinning on the axis line is passed by
                                if turn_hit(su, sv, fu, fv, sense):
                                    hits[i] |= bo
                            continue
                        for e in range(st_start[sense, su + bound, sv + bound],
                                       st_end[sense, su + bound, sv + bound]):  # fmt: skip
                            hit_cell[a] = cells[k, a]
                            hit_cell[u] = (st_cells[e, 0] + cu) // 2
                            hit_cell[v] = (st_cells[e, 1] + cv) // 2
                            x = hit_cell[0] - glo[0]
                            y = hit_cell[1] - glo[1]
                            z = hit_cell[2] - glo[2]
                            if 0 <= x < dims[0] and 0 <= y < dims[1] and 0 <= z < dims[2]:
                                h = _hash_slot(keys, (x * dims[1] + y) * dims[2] + z, bits)
                                k2 = key_cell[h]
                                if k2 >= 0 and not (
                                    rod[k2] == a and 2 * hit_cell[u] == cu and 2 * hit_cell[v] == cv
                                ):  # (a rod spinning on the axis line is passed by)
                                    hits[i] |= np.uint64(1) << np.uint64(owner[k2])
                    # close "must come along" (Warshall on bit rows)
                    for m in range(n):
                        bm = np.uint64(1) << np.uint64(m)
                        for i in range(n):
                            if hits[i] & bm:
                                hits[i] |= hits[m]
                    ng = mv.closed_groups(hits, n, group_limit, groups, max_group)
                    if ng < 0:
                        return -2
                    for gi in range(ng):
                        g = groups[gi]
                        if g == full:
                            continue
                        size = 0
                        blo_u = 1 << 40
                        bhi_u = -(1 << 40)
                        blo_v = 1 << 40
                        bhi_v = -(1 << 40)
                        for i in range(n):
                            if g & (np.uint64(1) << np.uint64(i)):
                                size += 1
                                blo_u = min(blo_u, plo[i, u])
                                bhi_u = max(bhi_u, phi[i, u])
                                blo_v = min(blo_v, plo[i, v])
                                bhi_v = max(bhi_v, phi[i, v])
                        if max_group >= 0 and size > max_group:
                            continue
                        if not (
                            2 * blo_u - 1 <= cu <= 2 * bhi_u + 1
                            and 2 * blo_v - 1 <= cv <= 2 * bhi_v + 1
                        ):
                            continue
                        if rows >= out.shape[0]:
                            return -1
                        c[a] = 0
                        c[u] = cu
                        c[v] = cv
                        out[rows, 0] = np.int64(g)
                        out[rows, 1] = a
                        out[rows, 2] = sense
                        out[rows, 3] = c[0]
                        out[rows, 4] = c[1]
                        out[rows, 5] = c[2]
                        rows += 1
    return rows


@njit(cache=True)
def turn_pose(rot: int, off: I64, q: int, c: I64, out: I64) -> int:
    """Pose ``(rot, off)`` turned by rotation ``q`` about doubled centre ``c``: writes the
    new offset into ``out`` and returns the new rotation index."""
    for t in range(3):
        acc = 0
        for s in range(3):
            acc += MATRICES[q, t, s] * (2 * off[s] - c[s])
        out[t] = (acc + c[t]) // 2
    return int(COMPOSE[q, rot])


#: Status of :func:`expand_turns` besides those of
#: :func:`chaingeo.solvers.motion.bfs_kernel.expand`.
NEED_TURNS = 6


class TurnPieces(NamedTuple):
    """A part's pieces in each of their 24 orientations as :func:`expand_turns` reads them
    (:meth:`TurnTable.part_arrays`: voxels, starts, boxes, rod axes), the group caps
    (``max_group`` -1: any), and the buffers its per-state kernels write (move rows, turn rows,
    groups)."""

    vox: I64
    starts: I64
    lo: I64
    hi: I64
    rod: I64
    max_group: int
    group_limit: int
    moves: I64
    turns: I64
    groups: U64


@njit(cache=True)
def expand_turns(
    tree: bfs.Tree, n_states: int, node_start: int, node_end: int, pieces: TurnPieces,
    st: StencilArrays, seps: I64, n_seps: int,
) -> tuple[int, int, int, int, int]:  # fmt: skip
    """Expand nodes ``node_start..node_end-1`` of a breadth-first search with translations and
    turns (rows: ``3 n`` offsets, then ``n`` rotation indices; piece 0 never moves: when it
    belongs to the moving group, the rest moves the opposite way instead).

    ``move`` rows: ``(mask, kind, p0, p1, p2)``, kind ``0..5`` a translation by ``p0`` along
    that direction, ``TURN_BASE + 2 axis + sense`` a turn about doubled centre ``(p0, p1, p2)``;
    ``mask`` is the group that moves (as a move of the reference it names those pieces).
    Returns ``(status, next node, n_states, n_seps, 0)``. On a status other than DONE (or
    ``TOO_FAR``, which ends the search) the caller grows that buffer and calls again from the
    next node (re-expanded from scratch)."""
    states, parent, move, table = tree
    (vox_all, starts_all, lo_all, hi_all, rod_all, max_group, group_limit, moves_buf, turns_buf,
     groups_buf) = pieces  # fmt: skip
    st_start, st_end, st_cells, bound = st
    n = starts_all.shape[0] // 24
    w = 4 * n
    gaps = np.empty((3, n, n), dtype=np.int64)
    off = np.empty((n, 3), dtype=np.int64)
    rot = np.empty(n, dtype=np.int64)
    child = np.empty(w, dtype=np.int16)
    c = np.empty(3, dtype=np.int64)
    new_off = np.empty(3, dtype=np.int64)
    while n_seps > 0 and seps[n_seps - 1, 0] >= node_start:
        n_seps -= 1
    for node in range(node_start, node_end):
        for p in range(n):
            for t in range(3):
                off[p, t] = states[node, 3 * p + t]
            rot[p] = states[node, 3 * n + p]
        vox, starts, lo, hi, rod = gather(vox_all, starts_all, lo_all, hi_all, rod_all, rot)
        rows = mv.node_moves(
            vox, starts, lo, hi, off, max_group, group_limit, False, gaps, groups_buf, moves_buf
        )
        if rows == -2:
            return bfs.TOO_MANY_GROUPS, node, n_states, n_seps, 0
        if rows == -1:
            return bfs.NEED_MOVES, node, n_states, n_seps, 0
        nt = node_turns(
            vox, starts, lo, hi, rod, off, st_start, st_end, st_cells, bound,
            max_group, group_limit, groups_buf, turns_buf,
        )  # fmt: skip
        if nt == -1:
            return NEED_TURNS, node, n_states, n_seps, 0
        if nt == -2:
            return bfs.TOO_MANY_GROUPS, node, n_states, n_seps, 0
        if nt == -3:
            return TOO_FAR, node, n_states, n_seps, 0
        status, n_states, n_seps = bfs.slide_children(
            tree, node, n, rows, moves_buf, child, seps, n_seps, n_states
        )
        if status != bfs.DONE:
            return status, node, n_states, n_seps, 0
        for r in range(nt):
            mask = np.uint64(turns_buf[r, 0])
            a = turns_buf[r, 1]
            sense = turns_buf[r, 2]
            for t in range(3):
                c[t] = turns_buf[r, 3 + t]
            anchor_moves = (mask & np.uint64(1)) != np.uint64(0)
            q = QUARTERS[a, 1 - sense] if anchor_moves else QUARTERS[a, sense]
            if n_states >= states.shape[0] or 2 * (n_states + 1) > table.shape[0]:
                return bfs.NEED_STATES, node, n_states, n_seps, 0
            for t in range(w):
                child[t] = states[node, t]
            for p in range(n):
                inside = (mask & (np.uint64(1) << np.uint64(p))) != np.uint64(0)
                if inside != anchor_moves:
                    child[3 * n + p] = turn_pose(rot[p], off[p], q, c, new_off)
                    for t in range(3):
                        child[3 * p + t] = new_off[t]
            got = mv.find_or_insert(states, n_states, table, child)
            if got < 0:
                parent[n_states] = node
                move[n_states, 0] = np.int64(mask)
                move[n_states, 1] = TURN_BASE + 2 * a + sense
                move[n_states, 2] = c[0]
                move[n_states, 3] = c[1]
                move[n_states, 4] = c[2]
                n_states += 1
    return bfs.DONE, node_end, n_states, n_seps, 0
