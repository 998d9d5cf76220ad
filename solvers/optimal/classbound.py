"""A proven lower bound on o_i from blocks of pieces when moves may carry several pieces.

With single-piece moves the blocks' own optima add up (:mod:`chaingeo.solvers.optimal.blockbound`).
With moves of several pieces they do not: one move can carry pieces of several blocks at once (in a
tower of burr units, one slide along x can advance every unit that needs that slide). What still
holds is that one move has one *class* ``(axis, k)``: its axis and its finite distance. So count,
per class, how many moves each block needs; a whole plan needs, per class, at least the most any
block needs.

**Relaxed values.** For a set ``Y`` of disjoint parts of a block (each a one-part state: pieces
and offsets), ``V(Y)`` is the set of minimal *class vectors* (counts per class) defined by

* ``V(Y) = min { v_1 | ... | v_r : v_j in V(R_j) }`` over the parts ``R_j`` of ``Y`` (``|``:
  the element-wise maximum; ``min``: the minimal elements of a set of vectors), ``V(R) = {0}``
  for a single piece;
* for one part ``X``: ``V(X) = min ( { e_c + v : X -> X' a non-removal move of class c,
  v in V(X') } u { v : X -> (X_1, X_2) a removal, v in V({X_1, X_2}) } )``, over the moves of
  the kinematics (:mod:`chaingeo.core.kinematics`); moving a group one way and the rest the
  other way is one move of one class. Cycles only add, so ``V`` is the least fixed point.

**Claim.** Let the ``n`` pieces of an assembled puzzle be split into blocks ``B_1 .. B_k``, and
let ``M = min { |v_1 | ... | v_k| : v_j in V(B_j) }`` (``|v|``: the sum of the counts; ``B_j``
its pieces alone, assembled, one part). Every full disassembly has at least ``(n - 1) + M``
moves.

**Proof.** A plan has exactly ``n - 1`` removals (each splits one part in two; the end has
``n`` parts); let ``C`` count its other moves per class. Fix a block ``B`` and follow the plan
on *restricted parts*: they start as ``{B}`` and each lies inside one part of the whole state
at every time. A move of ``G`` (part ``Q``, class ``c``) acts on each restricted part
``R`` inside ``Q`` with ``G & R`` proper and non-empty by moving ``G & R`` the same way: legal,
since its obstacles ``R \\ G`` are among ``Q \\ G`` (and ``|G & R| <= |G|``, ``|R \\ G| <=
|Q \\ G|`` respect ``max_group``). If that clears ``R \\ G`` for good, ``R`` splits in two,
each half inside one part afterwards; otherwise the move cannot have been a removal of the
whole (a group that clears ``Q \\ G`` clears ``R \\ G``), so it is a non-removal of class
``c``, and every restricted part it moves without splitting moves by that same class.
By induction from the end of the plan, for each restricted state ``Y`` met with the rest of
the plan counting ``C'``, some ``w`` in ``V(Y)`` has ``w <= C'`` (element-wise): at the end
every part is a single piece and ``0`` will do; a move changes the restricted parts it acts
on, a part that splits keeps ``w`` (the removal case of ``V``), a part that moves without
splitting needs at most ``e_c`` more (the non-removal case), untouched parts keep theirs, and
the maximum over the parts grows by at most ``e_c``, which ``C`` counts for that move. So each
block has ``w_j in V(B_j)``, ``w_j <= C``; hence ``C >= w_1 | ... | w_k`` and the plan has at
least ``(n - 1) + |w_1 | ... | w_k| >= (n - 1) + M`` moves. QED.

A sum over blocks (:mod:`chaingeo.solvers.optimal.blockbound`) is right for single-piece moves only;
pairs of blocks moved at once are exactly what the maximum per class allows for.

**Computing it.** ``V`` restricted to vectors of total at most ``b`` (the *budget*) is found by
a breadth-first search of finite moves up to depth ``b`` from each one-part state, keeping
per state only the prefixes no other prefix there is below, and recursing into both halves
of every removal with what is left of the budget (memoised). If no choice of vectors reaches
``|v_1 | ... | v_k| <= b``, then ``M > b``. :func:`class_lower_bound` raises ``b`` from 0 until
the minimum is found, or stops at ``max_budget`` with the weaker, still proven ``M >
max_budget``. Turns are not covered (translations only).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import SearchLimitError
from chaingeo.solvers.motion import kinematics_kernel as mv
from chaingeo.solvers.motion.partsearch import PieceTable

#: Counts per class ``((axis, distance), count)``, sorted by class; zero counts left out.
ClassVector = tuple[tuple[tuple[int, int], int], ...]
Offsets = npt.NDArray[np.int64]

_STEP = np.array(
    [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)], dtype=np.int64
)


def total(v: ClassVector) -> int:
    return sum(count for _, count in v)


def below(w: ClassVector, v: ClassVector) -> bool:
    """``w <= v`` in every class."""
    have = dict(v)
    return all(have.get(c, 0) >= count for c, count in w)


def join(a: ClassVector, b: ClassVector) -> ClassVector:
    """The element-wise maximum."""
    out = dict(a)
    for c, count in b:
        out[c] = max(out.get(c, 0), count)
    return tuple(sorted(out.items()))


#: Largest budget (and so count per class) the packed vectors hold: 7 bits a field.
MAX_BUDGET = 127


class ClassPacking:
    """Class vectors packed in one integer, 8 bits per class (the searches compare millions of
    them). A field holds a count up to :data:`MAX_BUDGET`, its top bit is a guard, so
    comparison and maximum work on every field at once without borrows crossing fields:
    ``w <= v`` iff ``(v + H - w) & H == H`` (``H``: the guard bits of the fields in use), and
    the total is ``v % 255`` (``256 = 1 mod 255``; totals stay below 255)."""

    def __init__(self) -> None:
        self.index: dict[tuple[int, int], int] = {}
        self.classes: list[tuple[int, int]] = []
        self.high = 0  # the guard bit of every field in use
        self.full = 0  # every bit of every field in use

    def unit(self, axis: int, k: int) -> int:
        """One move of class ``(axis, k)``."""
        i = self.index.get((axis, k))
        if i is None:
            i = self.index[(axis, k)] = len(self.classes)
            self.classes.append((axis, k))
            self.high |= 0x80 << (8 * i)
            self.full |= 0xFF << (8 * i)
        return 1 << (8 * i)

    def encode(self, v: ClassVector) -> int:
        out = 0
        for (axis, k), count in v:
            if not 0 <= count <= MAX_BUDGET:
                raise ValueError(f"a count per class is 0..{MAX_BUDGET}, got {count}")
            out += count * self.unit(axis, k)
        return out

    def decode(self, v: int) -> ClassVector:
        out = [(c, v >> (8 * i) & 0xFF) for i, c in enumerate(self.classes)]
        return tuple(sorted((c, count) for c, count in out if count))

    @staticmethod
    def total(v: int) -> int:
        return v % 255

    def below(self, w: int, v: int) -> bool:
        """``w <= v`` in every class."""
        return (v + self.high - w) & self.high == self.high

    def join(self, a: int, b: int) -> int:
        """The element-wise maximum."""
        a_wins = (((a + self.high - b) & self.high) >> 7) * 0xFF  # 0xFF where a >= b
        return (a & a_wins) | (b & (self.full ^ a_wins))

    def minimal(self, vectors: Sequence[int]) -> list[int]:
        """The minimal elements (none below another), smallest totals first."""
        out: list[int] = []
        for v in sorted(set(vectors), key=lambda v: (v % 255, v)):
            if not any(self.below(w, v) for w in out):
                out.append(v)
        return out

    def smallest_join(self, choices: Sequence[Sequence[int]], cap: int) -> int | None:
        """A join of one vector per block with the smallest total, if some total is <= ``cap``."""
        best: list[int | None] = [None]
        limit = [cap + 1]

        def pick(i: int, acc: int) -> None:
            if acc % 255 >= limit[0]:
                return
            if i == len(choices):
                best[0], limit[0] = acc, acc % 255
                return
            for v in choices[i]:
                pick(i + 1, self.join(acc, v))

        pick(0, 0)
        return best[0]


@dataclass(frozen=True)
class ClassBound:
    """``bound``: proven lower bound on o_i, ``removals + finite``; ``finite``: ``M`` of the
    module docstring, or ``max_budget + 1`` when not ``complete``; ``classes``: a join of the
    blocks' vectors of that total (empty when not complete); ``block_vectors``: each block's
    minimal vectors within the last budget; ``states``: one-part states searched."""

    bound: int
    removals: int
    finite: int
    complete: bool
    classes: ClassVector
    block_vectors: tuple[tuple[ClassVector, ...], ...]
    states: int


class ClassVectors:
    """``V`` of one-part states within a budget, memoised (module docstring); shared with the
    search of :mod:`chaingeo.solvers.optimal.classsearch`, which asks for the blocks of many
    states."""

    def __init__(
        self, table: PieceTable, max_group: int | None, max_states: int, group_limit: int = 4096
    ) -> None:
        self.table = table
        self.group_limit = group_limit
        self.max_group = -1 if max_group is None else max_group
        self.max_states = max_states
        self.states = 0
        self.packing = ClassPacking()
        self.memo: dict[tuple[tuple[int, ...], bytes], tuple[int, list[int]]] = {}
        self.buf = np.zeros((4096, 4), dtype=np.int64)
        self.groups = np.zeros(group_limit + 1, dtype=np.uint64)
        self.arrays: dict[tuple[int, ...], tuple[np.ndarray, ...]] = {}  # per set of pieces

    def tick(self) -> None:
        """Count one more state searched; past the cap, stop."""
        self.states += 1
        if self.states > self.max_states:
            raise SearchLimitError(
                f"class bound state cap: more than {self.max_states} one-part states"
            )

    def moves(self, members: tuple[int, ...], off: Offsets) -> list[list[int]]:
        """Rows ``(mask, direction, kmax, removable)``, one of each group / rest pair, of the
        one-part state ``members`` at ``off``."""
        arrays = self.arrays.get(members)
        if arrays is None:
            arrays = self.arrays[members] = self.table.part_arrays(members)
        vox, starts, lo, hi = arrays
        n = len(members)
        gaps = np.empty((3, n, n), dtype=np.int64)
        while True:
            rows = mv.node_moves(
                vox, starts, lo, hi, off, self.max_group, self.group_limit,
                False, gaps, self.groups, self.buf,
            )  # fmt: skip
            if rows != -1:
                break
            self.buf = np.zeros((2 * self.buf.shape[0], 4), dtype=np.int64)
        if rows == -2:
            raise SearchLimitError(
                f"class bound: more than {self.group_limit} movable groups along one axis"
            )
        out: list[list[int]] = self.buf[:rows].tolist()
        return out

    def vectors(self, members: tuple[int, ...], off: Offsets, budget: int) -> list[int]:
        """Minimal vectors (packed, :attr:`packing`) of total <= ``budget`` of the one-part
        state ``members`` at ``off``. Known for a larger budget, they are those of total <=
        ``budget`` among its (a vector below one of them has no larger total)."""
        if not 0 <= budget <= MAX_BUDGET:
            raise ValueError(f"a budget is 0..{MAX_BUDGET}, got {budget}")
        if len(members) == 1:
            return [0]
        off = off - off[0]
        key = (members, off.tobytes())
        known = self.memo.get(key)
        if known is not None and known[0] >= budget:
            return [v for v in known[1] if v % 255 <= budget]
        found = self._search(members, off, budget)
        self.memo[key] = (budget, found)
        return found

    def _search(self, members: tuple[int, ...], off: Offsets, budget: int) -> list[int]:
        """The breadth-first search of prefixes behind :meth:`vectors`."""
        pk = self.packing
        full = (1 << len(members)) - 1
        seen: dict[bytes, list[int]] = {off.tobytes(): [0]}
        layer: list[tuple[Offsets, int]] = [(off, 0)]
        found: list[int] = []
        for depth in range(budget + 1):
            following: list[tuple[Offsets, int]] = []
            for state, prefix in layer:
                if any(pk.below(v, prefix) for v in found):
                    continue  # every plan on from here is above a vector already found
                self.tick()
                split: set[int] = set()  # a group removable several ways splits one way
                for mask, d, kmax, removable in self.moves(members, state):
                    if removable and min(mask, full ^ mask) not in split:
                        split.add(min(mask, full ^ mask))
                        found.extend(self._split(members, state, mask, prefix, budget))
                    if depth == budget:
                        continue
                    for k in range(1, kmax + 1):
                        after = moved(state, mask, d, k)
                        v = prefix + pk.unit(d // 2, k)
                        there = seen.setdefault(after.tobytes(), [])
                        if any(pk.below(u, v) for u in there):
                            continue
                        there[:] = [u for u in there if not pk.below(v, u)] + [v]
                        following.append((after, v))
            found = pk.minimal(found)
            if found == [0]:
                break
            layer = following
        return found

    def _split(
        self, members: tuple[int, ...], off: Offsets, mask: int, prefix: int, budget: int
    ) -> list[int]:
        left = budget - prefix % 255
        inside = [i for i in range(len(members)) if mask >> i & 1]
        outside = [i for i in range(len(members)) if not mask >> i & 1]
        a = self.vectors(tuple(members[i] for i in inside), off[inside], left)
        b = self.vectors(tuple(members[i] for i in outside), off[outside], left)
        join = self.packing.join
        out = [prefix + join(x, y) for x in a for y in b]
        return [v for v in out if v % 255 <= budget]


def class_lower_bound(
    shapes: Mapping[str, Shape],
    blocks: Sequence[Sequence[str]],
    *,
    max_group: int | None = None,
    max_budget: int = 16,
    max_states: int = 2_000_000,
) -> ClassBound:
    """The claim's bound (module docstring) for a partition ``blocks`` of ``shapes``'s names,
    assembled as given. Raises ``ValueError`` when the blocks are not a partition or a block
    cannot be taken apart on its own (then neither can the whole), and
    :class:`SearchLimitError` past ``max_states`` one-part states."""
    names = sorted(shapes)
    if sorted(n for b in blocks for n in b) != names:
        raise ValueError("the blocks must split the pieces: every name in exactly one block")
    table = PieceTable({n: shapes[n] for n in names})
    search = ClassVectors(table, max_group, max_states)
    members = [tuple(sorted(table.index(n) for n in b)) for b in blocks]
    removals = len(names) - 1
    if not 0 <= max_budget <= MAX_BUDGET:
        raise ValueError(f"max_budget is 0..{MAX_BUDGET}, got {max_budget}")
    pk = search.packing
    vectors: list[list[int]] = []
    for budget in range(max_budget + 1):
        vectors = [search.vectors(m, _assembled(m), budget) for m in members]
        best = pk.smallest_join(vectors, budget)
        if best is not None:
            return ClassBound(
                removals + pk.total(best), removals, pk.total(best), True, pk.decode(best),
                tuple(tuple(map(pk.decode, v)) for v in vectors), search.states,
            )  # fmt: skip
    for b, m, v in zip(blocks, members, vectors, strict=True):
        if not v and _locked(search, m):  # no vector: more than the budget, or never apart
            raise ValueError(f"block {sorted(b)} cannot be taken apart on its own")
    return ClassBound(
        removals + max_budget + 1, removals, max_budget + 1, False, (),
        tuple(tuple(map(pk.decode, v)) for v in vectors), search.states,
    )  # fmt: skip


def band_blocks(shapes: Mapping[str, Shape], height: int, axis: int = 2) -> list[list[str]]:
    """Blocks of a stack of units ``height`` layers tall along ``axis`` (a tower of burr units:
    ``height`` 6): pieces grouped by the band their lowest voxel lies in, bottom first."""
    bands: dict[int, list[str]] = {}
    for name in sorted(shapes):
        bands.setdefault(int(shapes[name].voxels[:, axis].min()) // height, []).append(name)
    return [bands[k] for k in sorted(bands)]


def moved(state: Offsets, mask: int, d: int, k: int) -> Offsets:
    """The offsets after the pieces of ``mask`` move ``k`` along direction ``d``, seen from
    piece 0 again."""
    after = state.copy()
    picked = [i for i in range(len(state)) if mask >> i & 1]
    after[picked] += _STEP[d] * k
    after -= after[0]
    return after


def _assembled(members: tuple[int, ...]) -> Offsets:
    return np.zeros((len(members), 3), dtype=np.int64)


def _locked(search: ClassVectors, members: tuple[int, ...]) -> bool:
    """Does the one-part block never come apart (no removal anywhere in its finite moves)?"""
    start = _assembled(members)
    seen = {start.tobytes()}
    todo = [start]
    while todo:
        state = todo.pop()
        search.tick()
        for mask, d, kmax, removable in search.moves(members, state):
            if removable:
                return False
            for k in range(1, kmax + 1):
                after = moved(state, mask, d, k)
                if after.tobytes() not in seen:
                    seen.add(after.tobytes())
                    todo.append(after)
    return True
