"""Pattern databases for the A* disassembler: exact distances of small sub-puzzles.

For a subset ``S`` of the pieces (a pair or a triple) the *sub-puzzle* is ``S`` alone, the
other pieces removed. Its *one-part states* are ``S``'s relative offsets with ``S`` still one
part; ``g_S(X)`` is the fewest moves that take every piece of ``S`` apart from ``X`` under the
rules of :mod:`chaingeo.core.kinematics` (same ``max_group``). :class:`PatternDB` holds ``g_S`` for
every one-part state it has met, in one open-addressing table keyed by
``(subset id, offsets of S[1], S[2] relative to S[0])``; why these values bound the whole
puzzle's distance is proven in :mod:`chaingeo.solvers.optimal.astar`.

A table entry is filled by an exact search of the sub-puzzle from a state ``X`` (forward
breadth first, numba): every state reachable from ``X`` is enumerated with its moves, so the
set is closed under moves and the distances computed on it are exact. Then, backwards from the
states where a removal is possible (``c(Y) = 1 + g`` of the pair a removal leaves, ``1`` for a
pair), Dial's bucket queue gives ``g(Y) = min(c(Y), 1 + min over moves Y -> Z of g(Z))`` for
every state at once. States already in the table are not expanded again (their value is
final). A state from which ``S`` never comes apart gets :data:`DEAD`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np

from chaingeo.core.arrays import I16, I32, I64
from chaingeo.core.kinematics import SearchLimitError
from chaingeo.kernels.jit import entry, njit
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.motion import kinematics_kernel as mv
from chaingeo.solvers.motion.partsearch import PieceTable

#: ``g`` of a state from which the sub-puzzle never comes apart (larger than any real plan).
DEAD = 1 << 20
#: Width of a key row: subset id, then 3 offsets each of S[1] and S[2] (zeros for a pair).
KEY_WIDTH = 7
#: Status codes of :func:`sub_component`.
SUB_DONE, SUB_NEED_STATES, SUB_NEED_EDGES, SUB_NEED_MOVES, SUB_TOO_MANY_GROUPS = 0, 1, 2, 3, 4


#: Index of a key row in the database (-1 when absent): the shared open-addressing lookup.
lookup = mv.find_row


@njit(cache=True)
def _key_of(sid: int, state: I16, m: int, key: I16) -> None:
    key[0] = sid
    for t in range(6):
        key[1 + t] = state[3 + t] if 3 + t < 3 * m else 0


class Component(NamedTuple):
    """The growing arrays of one sub-puzzle's enumeration (:func:`sub_component`): state rows
    and their hash ``table``, each state's database value or -1 (``known``), the moves
    ``(from, to)`` and the removals ``(state, mask)`` seen."""

    states: I16
    table: I64
    known: I32
    edges: I64
    rems: I64


class Database(NamedTuple):
    """A pattern database's arrays as a kernel reads them: key rows, values, hash table."""

    keys: I16
    vals: I32
    table: I64


@njit(cache=True)
def sub_component(
    comp: Component, n_states: int, node: int, n_edges: int, n_rems: int,
    pieces: mv.Pieces, sid: int, db: Database,
) -> tuple[int, int, int, int, int]:  # fmt: skip
    """Breadth first over the one-part states of a sub-puzzle from ``node`` on, recording every
    move ``(from, to)`` in ``edges`` and every removal ``(state, mask)`` in ``rems``. A new
    state already in the pattern database gets ``known`` = its value and is not expanded.
    Returns ``(status, next node, n_states, n_edges, n_rems)``; on a status other than
    SUB_DONE the caller grows the named buffer and calls again from ``next`` (whose edges and
    removals have been dropped)."""
    states, table, known, edges, rems = comp
    vox, starts, lo, hi, max_group, group_limit, moves_buf, groups_buf = pieces
    pkeys, pvals, ptable = db
    m = starts.shape[0] - 1
    w = 3 * m
    gaps = np.empty((3, m, m), dtype=np.int64)
    off = np.empty((m, 3), dtype=np.int64)
    child = np.empty(w, dtype=np.int16)
    key = np.empty(KEY_WIDTH, dtype=np.int16)
    while node < n_states:
        if known[node] >= 0:
            node += 1
            continue
        e0 = n_edges
        r0 = n_rems
        row = states[node]  # once per node: a view taken per child costs a reference count
        for p in range(m):
            for t in range(3):
                off[p, t] = row[3 * p + t]
        rows = mv.node_moves(
            vox, starts, lo, hi, off, max_group, group_limit, False, gaps, groups_buf, moves_buf
        )
        if rows == -2:
            return SUB_TOO_MANY_GROUPS, node, n_states, e0, r0
        if rows == -1:
            return SUB_NEED_MOVES, node, n_states, e0, r0
        for r in range(rows):
            mask = np.uint64(moves_buf[r, 0])
            d = moves_buf[r, 1]
            kmax = moves_buf[r, 2]
            if moves_buf[r, 3]:
                if n_rems >= rems.shape[0]:
                    return SUB_NEED_EDGES, node, n_states, e0, r0
                rems[n_rems, 0] = node
                rems[n_rems, 1] = np.int64(mask)
                n_rems += 1
            for k in range(1, kmax + 1):
                if n_states >= states.shape[0] or 2 * (n_states + 1) > table.shape[0]:
                    return SUB_NEED_STATES, node, n_states, e0, r0
                if n_edges >= edges.shape[0]:
                    return SUB_NEED_EDGES, node, n_states, e0, r0
                mv.shift_child(row, child, 0, None, m, moves_buf[r, 0], d, k)
                got = mv.find_or_insert(states, n_states, table, child)
                if got < 0:
                    got = -1 - got
                    _key_of(sid, child, m, key)
                    idx = lookup(pkeys, ptable, key)
                    known[got] = pvals[idx] if idx >= 0 else -1
                    n_states += 1
                edges[n_edges, 0] = node
                edges[n_edges, 1] = got
                n_edges += 1
        node += 1
    return SUB_DONE, node, n_states, n_edges, n_rems


@njit(cache=True)
def removal_costs(
    states: I16,
    n_states: int,
    rems: I64,
    n_rems: int,
    m: int,
    pair_sid: I64,
    pkeys: I16,
    pvals: I32,
    ptable: I64,
    cost: I32,
    misses: I16,
) -> int:
    """``cost[s]`` = the cheapest removal at state ``s``: 1 plus ``g`` of the pair it leaves
    together (triples; for pairs just 1), :data:`DEAD` where ``s`` has none. Pair states not
    yet in the database are written to ``misses`` (a row each) and counted; the costs are
    only valid when the count returned is 0."""
    for s in range(n_states):
        cost[s] = DEAD
    key = np.empty(KEY_WIDTH, dtype=np.int16)
    n_miss = 0
    for r in range(n_rems):
        s = rems[r, 0]
        mask = rems[r, 1]
        if m == 2:
            cost[s] = 1
            continue
        # A triple splits into a single piece and a pair; find the pair (local q < p).
        bits = mask if (mask & (mask - 1)) != 0 else 7 ^ mask
        q = 0 if bits & 1 else 1
        p = 2 if bits & 4 else 1
        key[0] = pair_sid[q, p]
        for t in range(3):
            key[1 + t] = states[s, 3 * p + t] - states[s, 3 * q + t]
            key[4 + t] = 0
        idx = lookup(pkeys, ptable, key)
        if idx < 0:
            if n_miss < misses.shape[0]:
                for t in range(KEY_WIDTH):
                    misses[n_miss, t] = key[t]
            n_miss += 1
            continue
        c = 1 + pvals[idx]
        if pvals[idx] < DEAD and c < cost[s]:
            cost[s] = c
    return n_miss


@njit(cache=True)
def backward_distances(
    n_states: int, edges: I64, n_edges: int, cost: I32, known: I32, dist: I32
) -> None:
    """``dist[s] = min(cost[s], 1 + min over edges s -> t of dist[t])`` (a known state keeps
    its value): Dial's bucket queue over the reversed edges, sources at their own cost."""
    # Reversed adjacency (CSR by target).
    head = np.zeros(n_states + 1, dtype=np.int64)
    for e in range(n_edges):
        head[edges[e, 1] + 1] += 1
    for s in range(n_states):
        head[s + 1] += head[s]
    fill = head[:-1].copy()
    src = np.empty(n_edges, dtype=np.int64)
    for e in range(n_edges):
        t = edges[e, 1]
        src[fill[t]] = edges[e, 0]
        fill[t] += 1
    top = 0
    for s in range(n_states):
        dist[s] = known[s] if known[s] >= 0 else cost[s]
        if dist[s] < DEAD and dist[s] > top:
            top = dist[s]
    limit = top + n_states + 2
    # Buckets as linked lists of entries (node, next); each improvement adds one entry.
    bhead = np.full(limit + 1, -1, dtype=np.int64)
    enode = np.empty(n_states + n_edges + 1, dtype=np.int64)
    enext = np.empty(n_states + n_edges + 1, dtype=np.int64)
    ne = 0
    for s in range(n_states):
        if dist[s] < DEAD:
            enode[ne] = s
            enext[ne] = bhead[dist[s]]
            bhead[dist[s]] = ne
            ne += 1
    for b in range(limit + 1):
        while bhead[b] >= 0:
            e = bhead[b]
            bhead[b] = enext[e]
            t = enode[e]
            if dist[t] != b:
                continue  # stale entry
            for i in range(head[t], head[t + 1]):
                s = src[i]
                if known[s] < 0 and b + 1 < dist[s]:
                    dist[s] = b + 1
                    enode[ne] = s
                    enext[ne] = bhead[b + 1]
                    bhead[b + 1] = ne
                    ne += 1


@njit(cache=True)
def insert_all(
    pkeys: I16,
    pvals: I32,
    n_keys: int,
    ptable: I64,
    sid: int,
    states: I16,
    n_states: int,
    m: int,
    dist: I32,
) -> int:
    """Store ``dist`` of every state under its key (states already present are left);
    return the new key count. The caller has made room for ``n_states`` more keys."""
    key = np.empty(KEY_WIDTH, dtype=np.int16)
    for s in range(n_states):
        _key_of(sid, states[s], m, key)
        got = mv.find_or_insert(pkeys, n_keys, ptable, key)
        if got < 0:
            pvals[n_keys] = dist[s]
            n_keys += 1
    return n_keys


def _pow2(n: int) -> int:
    """The smallest power of two >= ``n`` (hash tables index by masking)."""
    return 1 << (n - 1).bit_length()


class PatternDB:
    """Exact ``g_S`` for a fixed family of pairs and triples of one puzzle, filled on demand.

    ``family[i]`` is the sorted global piece indices of subset ``i``; every pair inside a
    triple of the family must be in the family too (the pair tables give the triples' removal
    costs, and :mod:`chaingeo.solvers.optimal.astar`'s consistency proof needs the family closed
    downwards).
    """

    def __init__(
        self,
        table: PieceTable,
        family: Sequence[tuple[int, ...]],
        *,
        max_group: int | None,
        component_states: int,
        max_keys: int,
        group_limit: int,
        deadline: Deadline,
    ) -> None:
        self.table = table
        self.family = [tuple(sorted(s)) for s in family]
        if any(len(s) not in (2, 3) for s in self.family):
            raise ValueError("pattern database subsets are pairs or triples")
        self.sid = {s: i for i, s in enumerate(self.family)}
        for s in self.family:
            if len(s) == 3:
                for pair in ((s[0], s[1]), (s[0], s[2]), (s[1], s[2])):
                    if pair not in self.sid:
                        raise ValueError(f"family holds triple {s} but not its pair {pair}")
        n = len(table.names)
        self.fam = np.full((max(1, len(self.family)), 3), -1, dtype=np.int64)
        for i, s in enumerate(self.family):
            self.fam[i, : len(s)] = s
        self.n_family = len(self.family)
        self.pair_index = np.full((n, n), -1, dtype=np.int64)
        for s, i in self.sid.items():
            if len(s) == 2:
                self.pair_index[s[0], s[1]] = self.pair_index[s[1], s[0]] = i
        self.max_group = -1 if max_group is None else int(max_group)
        self.component_states = component_states
        self.max_keys = max_keys
        self.group_limit = group_limit
        self.deadline = deadline
        self.keys = np.zeros((1024, KEY_WIDTH), dtype=np.int16)
        self.vals = np.zeros(1024, dtype=np.int32)
        self.hash = np.full(4096, -1, dtype=np.int64)
        self.n_keys = 0
        self.searches = 0  # sub-puzzle searches run
        self._sub_component: Any = None  # sub_component typed for this database (jit.entry)
        self.searched_states = 0  # states those searches enumerated
        self._parts = {s: table.part_arrays(s) for s in self.family}
        # node_moves' buffers, shared by the enumerations (one runs at a time): a small search
        # runs dozens, and each allocated its own
        self._moves_buf = np.zeros((256, 4), dtype=np.int64)
        self._groups_buf = np.zeros(min(group_limit, 1 << 16) + 1, dtype=np.uint64)

    def _reserve(self, extra: int) -> None:
        need = self.n_keys + extra
        if need > self.max_keys:
            raise SearchLimitError(
                f"pattern database cap of {self.max_keys} entries reached; "
                "raise AStarLimits(pdb_states=...)"
            )
        cap = self.keys.shape[0]
        if need > cap:
            while cap < need:
                cap *= 2
            self.keys = np.concatenate(
                [self.keys, np.zeros((cap - self.keys.shape[0], KEY_WIDTH), np.int16)]
            )
            self.vals = np.concatenate([self.vals, np.zeros(cap - self.vals.shape[0], np.int32)])
        if self.hash.shape[0] < 2 * self.keys.shape[0]:
            self.hash = np.full(_pow2(4 * self.keys.shape[0]), -1, dtype=np.int64)
            mv.rebuild_table(self.keys, self.n_keys, self.hash)

    def value(self, key: Sequence[int]) -> int | None:
        row = np.asarray(key, dtype=np.int16)
        idx = lookup(self.keys, self.hash, row)
        return None if idx < 0 else int(self.vals[idx])

    def ensure(self, key: Sequence[int]) -> int:
        """``g`` of the one-part state ``key`` (searching its sub-puzzle if not stored yet)."""
        found = self.value(key)
        if found is not None:
            return found
        sid = int(key[0])
        members = self.family[sid]
        m = len(members)
        start = np.zeros(3 * m, dtype=np.int16)
        start[3:] = np.asarray(key[1 : 3 * m - 2], dtype=np.int16)
        states, n_states, edges, n_edges, rems, n_rems, known = self._enumerate(sid, start)
        cost = np.empty(n_states, dtype=np.int32)
        local_pairs = np.full((3, 3), -1, dtype=np.int64)
        if m == 3:
            for q in range(3):
                for p in range(q + 1, 3):
                    local_pairs[q, p] = self.sid[(members[q], members[p])]
        misses = np.zeros((256, KEY_WIDTH), dtype=np.int16)
        while True:
            args = (states, n_states, rems, n_rems, m, local_pairs)
            n_miss = removal_costs(*args, self.keys, self.vals, self.hash, cost, misses)
            if n_miss == 0:
                break
            todo = sorted({tuple(int(v) for v in r) for r in misses[: min(n_miss, 256)]})
            for pair_key in todo:
                self.ensure(pair_key)
        dist = np.empty(n_states, dtype=np.int32)
        backward_distances(n_states, edges, n_edges, cost, known, dist)
        self._reserve(n_states)
        self.n_keys = insert_all(
            self.keys, self.vals, self.n_keys, self.hash, sid, states, n_states, m, dist
        )
        got = self.value(key)
        assert got is not None
        return got

    def _enumerate(self, sid: int, start: I16) -> tuple[I16, int, I64, int, I64, int, I32]:
        m = start.shape[0] // 3
        vox, starts, lo, hi = self._parts[self.family[sid]]
        cap = max(2, min(1024, self.component_states))
        states = np.zeros((cap, 3 * m), dtype=np.int16)
        hash_ = np.full(_pow2(4 * cap), -1, dtype=np.int64)
        known = np.full(cap, -1, dtype=np.int32)
        edges = np.zeros((4 * cap, 2), dtype=np.int64)
        rems = np.zeros((256, 2), dtype=np.int64)
        pieces = mv.Pieces(
            vox, starts, lo, hi, self.max_group, self.group_limit, self._moves_buf,
            self._groups_buf,
        )  # fmt: skip
        db = Database(self.keys, self.vals, self.hash)  # not replaced while this runs
        mv.find_or_insert(states, 0, hash_, start)
        n_states, n_edges, n_rems, node = 1, 0, 0, 0
        self.searches += 1
        while True:
            self.deadline.check()
            comp = Component(states, hash_, known, edges, rems)
            args = (comp, n_states, node, n_edges, n_rems, pieces, sid, db)
            if self._sub_component is None:  # typed once per database (jit.entry)
                self._sub_component = entry(sub_component, *args)
            status, node, n_states, n_edges, n_rems = self._sub_component(*args)
            if status == SUB_DONE:
                break
            if status == SUB_NEED_STATES:
                if cap >= self.component_states:
                    raise SearchLimitError(
                        f"sub-puzzle state cap of {self.component_states} reached for pieces "
                        f"{[self.table.names[i] for i in self.family[sid]]}; "
                        "raise AStarLimits(component_states=...)"
                    )
                extra = min(2 * cap, self.component_states) - cap
                cap += extra
                states = np.concatenate([states, np.zeros((extra, 3 * m), np.int16)])
                known = np.concatenate([known, np.full(extra, -1, np.int32)])
                hash_ = np.full(_pow2(4 * cap), -1, dtype=np.int64)
                mv.rebuild_table(states, n_states, hash_)
            elif status == SUB_NEED_EDGES:  # one of the two is full: grow both
                edges = np.concatenate([edges, np.zeros_like(edges)])
                rems = np.concatenate([rems, np.zeros_like(rems)])
            elif status == SUB_NEED_MOVES:
                self._moves_buf = np.zeros((2 * self._moves_buf.shape[0], 4), dtype=np.int64)
                pieces = pieces._replace(moves=self._moves_buf)
            else:
                raise SearchLimitError(
                    f"more than {self.group_limit} movable groups along one direction; "
                    "raise AStarLimits(group_limit=...)"
                )
        self.searched_states += n_states
        return states, n_states, edges, n_edges, rems, n_rems, known
