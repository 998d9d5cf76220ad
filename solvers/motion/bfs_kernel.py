"""The breadth-first search of one part's configurations, in numba: its growing arrays
(:class:`Tree`), their growth, and the layer-by-layer expansion (:func:`expand`).

One kernel call expands layer after layer, without Python between layers, until a layer yields a
removal, a buffer is full or a budget of nodes is spent; the caller
(:class:`chaingeo.solvers.motion.partsearch.PartSearch`, or
:func:`chaingeo.solvers.motion.levelsearch.greedy` from inside numba) grows the full buffer and
calls again. The moves of a state come from
:func:`chaingeo.solvers.motion.kinematics_kernel.node_moves`,
states are stored in :func:`chaingeo.solvers.motion.kinematics_kernel.find_or_insert`'s hash table.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from chaingeo.core.arrays import I16, I64
from chaingeo.kernels.jit import njit
from chaingeo.solvers.motion.kinematics_kernel import (
    Pieces,
    find_or_insert,
    node_moves,
    rebuild_table,
    shift_child,
)

#: Status codes returned by :func:`expand` (5 and 6 are
#: :mod:`chaingeo.solvers.motion.turns_kernel`' own).
DONE, NEED_STATES, NEED_SEPS, TOO_MANY_GROUPS, NEED_MOVES, PAUSED = 0, 1, 2, 3, 4, 7


class Tree(NamedTuple):
    """A breadth-first search's growing arrays: the state rows, each state's parent and the move
    that made it (rows), and the open-addressing ``table`` over the rows
    (:func:`chaingeo.solvers.motion.kinematics_kernel.find_or_insert`);
    a search replaces them as they fill (:func:`grow_search`, :func:`fit_table`)."""

    states: I16
    parent: I64
    move: I64
    table: I64


@njit(cache=True)
def grow_search(
    states: I16, parent: I64, move: I64, new_cap: int
) -> tuple[I16, I64, I64]:  # fmt: skip
    """A search's state rows, parents and moves copied into room for ``new_cap`` states."""
    cap = states.shape[0]
    grown = np.zeros((new_cap, states.shape[1]), dtype=np.int16)
    grown[:cap] = states
    grown_parent = np.full(new_cap, -1, dtype=np.int64)
    grown_parent[:cap] = parent
    grown_move = np.zeros((new_cap, 3), dtype=np.int64)
    grown_move[:cap] = move
    return grown, grown_parent, grown_move


@njit(cache=True)
def fit_table(table: I64, states: I16, n_states: int) -> I64:
    """``table``, or a new one rebuilt over ``states`` once it has fewer than four slots per
    state row (open addressing stays short)."""
    if table.shape[0] >= 4 * states.shape[0]:
        return table
    size = 1
    while size < 4 * states.shape[0]:
        size *= 2
    out = np.full(size, -1, dtype=np.int64)
    rebuild_table(states, n_states, out)
    return out


@njit(cache=True)
def slide_children(
    tree: Tree, node: int, n: int, rows: int, moves_buf: I64, child: I16, seps: I64,
    n_seps: int, n_states: int,
) -> tuple[int, int, int]:  # fmt: skip
    """The children of ``node`` (``n`` pieces) by the first ``rows`` slides of ``moves_buf``
    (:func:`chaingeo.solvers.motion.kinematics_kernel.node_moves`' rows: mask, direction, farthest
    distance, removes): each removal appended to ``seps`` as ``(node, mask, direction)``, each
    new state to the tree with its parent and move (mask, direction, distance; any further
    move columns 0). Returns ``(status, n_states, n_seps)``: DONE, or the buffer to grow (the
    caller expands ``node`` again from scratch)."""
    states, parent, move, table = tree
    for r in range(rows):
        mask = np.uint64(moves_buf[r, 0])
        d = moves_buf[r, 1]
        if moves_buf[r, 3]:
            if n_seps >= seps.shape[0]:
                return NEED_SEPS, n_states, n_seps
            seps[n_seps, 0] = node
            seps[n_seps, 1] = np.int64(mask)
            seps[n_seps, 2] = d
            n_seps += 1
        for k in range(1, moves_buf[r, 2] + 1):
            if n_states >= states.shape[0] or 2 * (n_states + 1) > table.shape[0]:
                return NEED_STATES, n_states, n_seps
            shift_child(states[node], child, 0, None, n, moves_buf[r, 0], d, k)
            if find_or_insert(states, n_states, table, child) < 0:
                parent[n_states] = node
                move[n_states, 0] = np.int64(mask)
                move[n_states, 1] = d
                move[n_states, 2] = k
                for j in range(3, move.shape[1]):
                    move[n_states, j] = 0
                n_states += 1
    return DONE, n_states, n_seps


@njit(cache=True)
def single_removal(moves_buf: I64, rows: int, n: int) -> int:
    """The first of ``rows`` slides that removes one piece alone (or all but one), else -1."""
    for r in range(rows):
        if moves_buf[r, 3]:
            mask = moves_buf[r, 0]
            bits = 0
            for b in range(n):
                bits += (mask >> b) & 1
            if bits == 1 or bits == n - 1:
                return r
    return -1


@njit(cache=True)
def expand(
    tree: Tree, n_states: int, node: int, layers: I64, n_layers: int, max_depth: int,
    budget: int, pieces: Pieces, seps: I64, n_seps: int, peel: bool,
) -> tuple[int, int, int, int, int]:  # fmt: skip
    """Breadth-first search, layer after layer in one call (no Python between layers).

    Layer ``d`` holds nodes ``layers[d]:layers[d + 1]`` (``n_layers`` entries); ``node`` is
    the next node of the deepest layer to expand. New states are appended with their parent
    and the move that made them (``move`` rows: mask, direction, distance); every removal seen
    is appended to ``seps`` as ``(node, mask, direction)``. Stops with DONE once a layer has
    yielded a removal, the deepest layer is empty (every state expanded) or is deeper than
    ``max_depth``; with PAUSED after ``budget`` nodes (the caller checks its deadline).
    Returns ``(status, next node, n_states, n_seps, n_layers)``; on a status asking for a
    buffer the caller grows it and calls again from ``next`` (that node is expanded again from
    scratch, so its removals are dropped first). ``layers`` holds two more entries than
    ``states`` rows (every layer has a node). With ``peel`` a node where one piece comes
    free alone yields that removal only and no children (its value is known exactly: see
    :mod:`chaingeo.solvers.motion.optimal_part`).
    """
    states = tree.states
    vox, starts, lo, hi, max_group, group_limit, moves_buf, groups_buf = pieces
    n = starts.shape[0] - 1
    w = 3 * n
    gaps = np.empty((3, n, n), dtype=np.int64)
    off = np.empty((n, 3), dtype=np.int64)
    child = np.empty(w, dtype=np.int16)
    while n_seps > 0 and seps[n_seps - 1, 0] >= node:
        n_seps -= 1
    done = 0
    while True:
        d = n_layers - 2
        first = layers[d]
        end = layers[d + 1]
        if first == end or d > max_depth:
            return DONE, node, n_states, n_seps, n_layers
        while node < end:
            if done >= budget:
                return PAUSED, node, n_states, n_seps, n_layers
            for p in range(n):
                for t in range(3):
                    off[p, t] = states[node, 3 * p + t]
            rows = node_moves(
                vox, starts, lo, hi, off, max_group, group_limit, False, gaps, groups_buf,
                moves_buf,
            )  # fmt: skip
            if rows == -2:
                return TOO_MANY_GROUPS, node, n_states, n_seps, n_layers
            if rows == -1:
                return NEED_MOVES, node, n_states, n_seps, n_layers
            free = single_removal(moves_buf, rows, n) if peel else -1
            if free >= 0:
                if n_seps >= seps.shape[0]:
                    return NEED_SEPS, node, n_states, n_seps, n_layers
                seps[n_seps, 0] = node
                seps[n_seps, 1] = moves_buf[free, 0]
                seps[n_seps, 2] = moves_buf[free, 1]
                n_seps += 1
                node += 1
                done += 1
                continue
            status, n_states, n_seps = slide_children(
                tree, node, n, rows, moves_buf, child, seps, n_seps, n_states
            )
            if status != DONE:
                return status, node, n_states, n_seps, n_layers
            node += 1
            done += 1
        layers[n_layers] = n_states
        n_layers += 1
        if n_seps > 0 and seps[n_seps - 1, 0] >= first:
            return DONE, node, n_states, n_seps, n_layers
