"""BurrTools' verdict for every piece order at once: proven, or shown to depend on the order.

BurrTools' disassembler (:mod:`chaingeo.solvers.motion.btsearch`) takes the first separation
in its search order, and that order follows the pieces' order; with congruent pieces the order
is the labelling, so a verdict may in principle depend on it. What does not depend on it:

* the moves of a state: per direction and step, every union (not all pieces) of the groups
  that must come along when one piece moves, a set whatever order lists it; so a part's
  states, and each one's breadth-first depth, are the same up to renaming the pieces;
* the depth ``d`` of the first separating node: the least depth of a state from which some
  group can leave (the search checks a node for leaving groups when it expands it, in depth
  order);
* the separation any order can pick: a state of depth ``d`` with a leaving group, and there a
  single piece that can leave when one can (any of them), else a group of at most half the
  part that must come along when one piece leaves (any of them).

:func:`verdict_for_all_orders` takes every such candidate, and recursively its two parts: the
assembly is a solution for every order when every candidate's parts are, none for every order
when every candidate leaves a part that is none for every order; else None (it may depend on
the order). Parts are keyed by geometry alone (their pieces' voxels up to a translation).

Within the caps it is always decisive, and why is worth saying: the moves reach every
translation of every group (a group of more than half moves as its complement the other way),
so a part comes apart exactly when some sequence of moves takes it apart; such a sequence, with
the other pieces dropped, takes apart any part a separation leaves (the state before it is
reachable and moves are reversible). So every candidate's parts come apart exactly when the
part does; the search is the check that does not rest on this argument.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from chaingeo.core.arrays import I16, I64
from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import SearchLimitError
from chaingeo.kernels.jit import njit
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion import btsearch as bt
from chaingeo.solvers.motion import kinematics_kernel as mv
from chaingeo.solvers.motion.levelsearch import STATE_CAP
from chaingeo.solvers.motion.partsearch import PieceTable

#: Verdict for every order: True (a solution), False (none), None (it may depend on the order).
Verdict = bool | None
#: Verdicts of parts by their geometry (:meth:`OrderFree.key`), shareable between assemblies.
Memo = dict[tuple[bytes, ...], Verdict]


@njit(cache=True)
def layer_candidates(part: bt.PartGaps, states: I16, nodes: I64) -> tuple[I64, I64]:
    """Every separation an order can pick at the states ``nodes``: ``(node, mask)`` pairs,
    single pieces where one can leave the state, else the groups of at most half."""
    k = part.members.shape[0]
    gaps = np.empty((3, k, k), dtype=np.int64)
    off = np.empty((k, 3), dtype=np.int64)
    todo = np.empty(k, dtype=np.int64)
    out_node = np.empty(6 * k * nodes.shape[0], dtype=np.int64)
    out_mask = np.empty(6 * k * nodes.shape[0], dtype=np.int64)
    n = 0
    for node in nodes:
        for p in range(k):
            for t in range(3):
                off[p, t] = states[node, 3 * p + t]
        mv.memo_pair_gaps(part.vox, part.starts, part.lo, part.hi, part.members, off, gaps,
                          part.memo_rel, part.memo_gap)  # fmt: skip
        for limit in (1, k // 2):
            first = n
            for d in range(6):
                for i in range(k):
                    m = bt._reach(gaps, d, i, mv.INF, k, limit, todo)
                    if m == 0:
                        continue
                    seen = False
                    for r in range(first, n):
                        seen = seen or out_mask[r] == m
                    if not seen:
                        out_node[n] = node
                        out_mask[n] = m
                        n += 1
            if n > first:
                break
    return out_node[:n], out_mask[:n]


@njit(cache=True)
def _depths(parent: I64, n_states: int) -> I64:
    """Breadth-first depth of each state (a state's parent is listed before it)."""
    depth = np.zeros(n_states, dtype=np.int64)
    for q in range(1, n_states):
        depth[q] = depth[parent[q]] + 1
    return depth


class OrderFree:
    """:func:`verdict_for_all_orders` with its table, caps and memo (by part geometry)."""

    def __init__(self, shapes: Mapping[str, Shape], limits: SearchLimits, deadline: Deadline,
                 memo: Memo | None = None) -> None:  # fmt: skip
        self.table = PieceTable(shapes)
        self.limits = limits
        self.deadline = deadline
        self.memo_rel, self.memo_gap = mv.gap_memo(len(self.table.names))
        self.memo: Memo = {} if memo is None else memo
        self.local: dict[tuple[tuple[int, ...], bytes], Verdict] = {}
        # Each piece's voxels in lexicographic order, which a translation keeps.
        self.sorted = [v[np.lexsort(v.T[::-1])] for v in self.table.voxels]
        self.states = 0

    def key(self, members: tuple[int, ...], offsets: I64) -> tuple[bytes, ...]:
        """The part's geometry: its pieces' placed voxels, sorted, up to a translation."""
        at = np.asarray(members)
        shift = offsets - (self.table.lo[at] + offsets).min(axis=0)
        return tuple(sorted((self.sorted[p] + shift[j]).tobytes() for j, p in enumerate(members)))

    def part(self, members: tuple[int, ...], offsets: I64) -> Verdict:
        """The part's verdict for every order (``offsets``: its pieces', in ``members``' order)."""
        if len(members) < 2:
            return True
        here = (members, (offsets - offsets[0]).tobytes())  # this assembly's pieces: cheaper
        if here not in self.local:
            key = self.key(members, offsets)
            if key not in self.memo:
                self.memo[key] = self._search(members, offsets)
            self.local[here] = self.memo[key]
        return self.local[here]

    def _search(self, members: tuple[int, ...], offsets: I64) -> Verdict:
        self.deadline.check()
        t, k = self.table, len(members)
        local = np.asarray(members, dtype=np.int64)
        part = bt.PartGaps(t.vox, t.starts, t.lo, t.hi, local, self.memo_rel, self.memo_gap)
        start = (offsets - offsets[0]).reshape(-1).astype(np.int16)
        lim = self.limits
        status, states, parent, _, ctx = bt.run_part(
            part, start, lim.max_states, 1 << 62, lim.group_limit
        )
        n_states = int(ctx[0])
        self.states += n_states
        if status == -STATE_CAP:
            raise SearchLimitError(f"state cap of {lim.max_states} reached in a {k}-piece part",
                                   "max_states")  # fmt: skip
        if status == bt.TOO_MANY_GROUPS:
            raise SearchLimitError(f"more than {lim.group_limit} movable groups along one "
                                   "direction in one state", "group_limit")  # fmt: skip
        if status == bt.STUCK:
            return False  # every state was met: none comes apart, whatever the order
        depth = _depths(parent, n_states)
        layer = np.flatnonzero(depth == depth[int(ctx[2])]).astype(np.int64)
        nodes, masks = layer_candidates(part, states, layer)
        return self._combine(members, states, nodes, masks)

    def _combine(self, members: tuple[int, ...], states: I16, nodes: I64, masks: I64) -> Verdict:
        """True when every candidate's parts come apart for every order, False when every
        candidate leaves a part that never does; None otherwise (stops at the first mixture)."""
        k = len(members)
        seen: set[bool] = set()
        for node, mask in zip(nodes.tolist(), masks.tolist(), strict=True):
            off = states[node].astype(np.int64).reshape(k, 3)
            inside = [j for j in range(k) if mask >> j & 1]
            outside = [j for j in range(k) if not mask >> j & 1]
            sides = [self.part(tuple(members[j] for j in js), off[js]) for js in (outside, inside)]
            got = False if False in sides else (True if sides == [True, True] else None)
            if got is None:
                return None
            seen.add(got)
            if len(seen) > 1:
                return None
        return seen.pop() if seen else None


def verdict_for_all_orders(
    shapes: Mapping[str, Shape],
    limits: SearchLimits | None = None,
    deadline: Deadline | None = None,
    memo: Memo | None = None,
) -> Verdict:
    """BurrTools' verdict on an assembly (every piece at its place) for every order of its
    pieces and every turn of the whole, or None when it may depend on them (see the module's
    docstring). One piece is no disassembly (``disassembler_a.cpp``). ``memo``: part verdicts
    met before (filled in). Caps raise :class:`SearchLimitError`."""
    if len(shapes) < 2:
        return False
    lim = limits or SearchLimits()
    solver = OrderFree(shapes, lim, deadline or Deadline(lim.seconds), memo)
    n = len(solver.table.names)
    if n > mv.MAX_PIECES:
        raise ValueError(f"at most {mv.MAX_PIECES} pieces per part, got {n}")
    return solver.part(tuple(range(n)), np.zeros((n, 3), dtype=np.int64))
