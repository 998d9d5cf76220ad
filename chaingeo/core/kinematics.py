"""Exact puzzle kinematics: the reference semantics of a move (pure Python, set based).

This module is the specification that every faster search is tested against. A move translates
a group of pieces of one part along an axis by ``k >= 1`` units, or to infinity; it is legal
when no unit step on the way makes a voxel of the group meet a voxel of the rest of the part.
A move to infinity splits the part in two; the disassembly is done when every part is one piece.
Each move is one step whatever its distance (BurrTools' convention).

Where a level's rules allow turns, a :class:`~chaingeo.core.turns.TurnMove` turns a group of one
part by 90 degrees about a line parallel to x, y or z through cell centres or cell corners (the
convention of :mod:`chaingeo.core.turns`), its centre within the group's bounding box; it is legal
when the continuous turn sweeps through no other piece of the part (decided exactly there).
A turned piece changes orientation: a piece's pose is a rotation (index into
:data:`chaingeo.core.geometry.ROTATIONS`, 0 the identity) and an offset, its cells ``R v + offset``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from itertools import combinations
from typing import Any, Final

import numpy as np

from chaingeo.core.errors import ChainGeoError
from chaingeo.core.geometry import ROTATIONS, Cell, Shape, rotation_index
from chaingeo.core.turns import (
    AXES,
    TurnMove,
    centre_inside,
    centres_within,
    spinning_rods,
    swept_by,
    turn_pose,
)

DIRECTIONS: Final[dict[str, Cell]] = {
    "+x": (1, 0, 0),
    "-x": (-1, 0, 0),
    "+y": (0, 1, 0),
    "-y": (0, -1, 0),
    "+z": (0, 0, 1),
    "-z": (0, 0, -1),
}
OPPOSITE: Final[dict[str, str]] = {
    "+x": "-x",
    "-x": "+x",
    "+y": "-y",
    "-y": "+y",
    "+z": "-z",
    "-z": "+z",
}


class MoveError(ChainGeoError, ValueError):
    """A move that the kinematics forbids; ``reason`` says why in words a user can act on."""

    def __init__(self, move: Move | TurnMove, reason: str) -> None:
        super().__init__(f"{move.describe()}: {reason}")
        self.move = move
        self.reason = reason


@dataclass(frozen=True, order=True)
class Move:
    """Translate ``pieces`` together along ``direction`` by ``distance`` (None: to infinity)."""

    pieces: tuple[str, ...]
    direction: str
    distance: int | None

    def __post_init__(self) -> None:
        if self.direction not in DIRECTIONS:
            raise ValueError(f"unknown direction {self.direction!r}; use one of {list(DIRECTIONS)}")
        if self.distance is not None and self.distance < 1:
            raise ValueError(f"distance must be >= 1 or None (to infinity), got {self.distance}")
        if not self.pieces:
            raise ValueError("a move needs at least one piece")
        if len(set(self.pieces)) != len(self.pieces):
            raise ValueError(f"a piece is named twice in {list(self.pieces)}")
        object.__setattr__(self, "pieces", tuple(sorted(self.pieces)))

    def describe(self) -> str:
        dist = "inf" if self.distance is None else str(self.distance)
        return f"move {'+'.join(self.pieces)} {self.direction} {dist}"

    def to_json(self) -> dict[str, object]:
        return {"pieces": list(self.pieces), "direction": self.direction, "distance": self.distance}

    def inverse(self) -> Move:
        """The same group moving back the same way (an infinite move inverts to an infinite one)."""
        return Move(self.pieces, OPPOSITE[self.direction], self.distance)


def _shifted(cells: Iterable[Cell], d: Cell, k: int) -> set[Cell]:
    return {(x + d[0] * k, y + d[1] * k, z + d[2] * k) for x, y, z in cells}


def _max_free_run(group: frozenset[Cell], rest: frozenset[Cell], d: Cell) -> int | None:
    """Largest k such that steps 1..k are all collision-free, or None if the group never meets
    the rest again (it can leave to infinity).

    A step k collides iff some rest cell lies k ahead of a group cell on the same line along
    the axis, so the answer is the smallest such k less one: work bounded by the cells, never
    by the coordinates' span.
    """
    if not rest:
        return None
    axis = next(i for i in range(3) if d[i])
    sign = d[axis]
    a, b = (axis + 1) % 3, (axis + 2) % 3
    lines: dict[tuple[int, int], list[int]] = {}
    for r in rest:
        lines.setdefault((r[a], r[b]), []).append(r[axis])
    first: int | None = None
    for g in group:
        for at in lines.get((g[a], g[b]), ()):
            k = sign * (at - g[axis])
            if k >= 1 and (first is None or k < first):
                first = k
    return None if first is None else first - 1


#: A translation or a turn.
AnyMove = Move | TurnMove


@lru_cache(maxsize=4096)
def oriented(shape: Shape, rotation: int) -> Shape:
    """``shape`` turned by ``ROTATIONS[rotation]`` about the origin (cells ``R v``)."""
    return shape if rotation == 0 else shape.rotate(ROTATIONS[rotation])


@dataclass(frozen=True)
class Assembly:
    """Pieces (in their assembled position) with integer offsets, grouped into parts.

    ``parts`` lists the sub-puzzles still to take apart (and finished singletons); pieces of
    different parts never interact again. ``rotations`` holds the pieces a turn has left in
    another orientation (index into :data:`chaingeo.core.geometry.ROTATIONS`; absent: 0, as
    assembled). ``rods``: cells of a piece (assembled frame) that are round rods along an axis
    (0, 1, 2); a rod lying on a turn's axis line spins in place (see :meth:`turn_sweep`).
    """

    shapes: Mapping[str, Shape]
    offsets: Mapping[str, Cell]
    parts: tuple[frozenset[str], ...]
    rotations: Mapping[str, int] = field(default_factory=dict)
    rods: Mapping[str, Mapping[Cell, int]] = field(default_factory=dict)
    #: Each piece's cells, filled as asked: searches ask for the same piece's cells many
    #: times per state (every direction, group and distance), never for another state's.
    _cells: dict[str, frozenset[Cell]] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )

    @staticmethod
    def assembled(
        shapes: Mapping[str, Shape], rods: Mapping[str, Mapping[Cell, int]] | None = None
    ) -> Assembly:
        names = sorted(shapes)
        return Assembly(
            shapes=dict(shapes),
            offsets={n: (0, 0, 0) for n in names},
            parts=(frozenset(names),),
            rods={n: dict(r) for n, r in (rods or {}).items() if r},
        )

    def rotation_of(self, name: str) -> int:
        return self.rotations.get(name, 0)

    def cells_of(self, name: str) -> frozenset[Cell]:
        found = self._cells.get(name)
        if found is None:
            ox, oy, oz = self.offsets[name]
            shape = oriented(self.shapes[name], self.rotation_of(name))
            found = frozenset((x + ox, y + oy, z + oz) for x, y, z in shape)
            self._cells[name] = found
        return found

    def moved(
        self, offsets: Mapping[str, Cell], parts: tuple[frozenset[str], ...] | None = None
    ) -> Assembly:
        """The same pieces, orientations and rods at ``offsets`` (and ``parts``)."""
        parts = self.parts if parts is None else parts
        return Assembly(self.shapes, offsets, parts, self.rotations, self.rods)

    def part_of(self, name: str) -> frozenset[str]:
        for p in self.parts:
            if name in p:
                return p
        raise KeyError(name)

    def is_separated(self) -> bool:
        return all(len(p) == 1 for p in self.parts)

    def free_distance(self, pieces: Sequence[str], direction: str) -> int | None:
        """How far the group can travel in ``direction``: 0 if blocked, None for unlimited."""
        part = self.part_of(pieces[0])
        group = frozenset(c for n in pieces for c in self.cells_of(n))
        rest = frozenset(c for n in sorted(part - set(pieces)) for c in self.cells_of(n))
        return _max_free_run(group, rest, DIRECTIONS[direction])

    def clearance(self, pieces: Sequence[str], direction: str) -> int:
        """Distance after which the group's span along the axis has passed the rest's span:
        from there on it can never meet the rest again, so a move that far is a removal."""
        d = DIRECTIONS[direction]
        axis = next(i for i in range(3) if d[i])
        part = self.part_of(pieces[0])
        group = [c[axis] for n in pieces for c in self.cells_of(n)]
        rest = [c[axis] for n in sorted(part - set(pieces)) for c in self.cells_of(n)]
        if d[axis] > 0:
            return max(rest) - min(group) + 1
        return max(group) - min(rest) + 1

    def blockers(self, name: str, direction: str) -> list[str]:
        """Pieces of the same part that a one-unit step of ``name`` alone would hit."""
        d = DIRECTIONS[direction]
        moved = _shifted(self.cells_of(name), d, 1)
        return [
            other
            for other in sorted(self.part_of(name) - {name})
            if not moved.isdisjoint(self.cells_of(other))
        ]

    def check(self, move: Move | TurnMove) -> None:
        """Raise :class:`MoveError` unless ``move`` is legal here."""
        unknown = [n for n in move.pieces if n not in self.shapes]
        if unknown:
            raise MoveError(move, f"unknown piece(s) {unknown}")
        part = self.part_of(move.pieces[0])
        if any(n not in part for n in move.pieces):
            raise MoveError(move, "the pieces belong to different, already separated parts")
        if set(move.pieces) == part:
            raise MoveError(move, "the group is a whole part: nothing to move it against")
        if isinstance(move, TurnMove):
            why = self.turn_problem(move)
            if why is not None:
                raise MoveError(move, why)
            return
        free = self.free_distance(move.pieces, move.direction)
        if move.distance is None:
            if free is not None:
                raise MoveError(move, f"blocked after {free} unit(s); it cannot leave")
        elif free is not None and free < move.distance:
            raise MoveError(move, f"blocked after {free} unit(s), {move.distance} asked")

    def spinning(self, names: Iterable[str], axis: int, centre2: Sequence[int]) -> set[Cell]:
        """The cells of these pieces' round rods on the turn's line: they spin in place
        (:func:`chaingeo.core.turns.spinning_rods`)."""
        return {
            c
            for n in names
            if self.rods.get(n)
            for c in spinning_rods(
                self.rods[n], ROTATIONS[self.rotation_of(n)], self.offsets[n], axis, centre2
            )
        }

    def turn_sweep(
        self, names: Sequence[str], axis: int, quarter: int, centre2: Sequence[int]
    ) -> set[Cell]:
        """Every cell the pieces sweep through turning together (exact: see
        :func:`chaingeo.core.turns.swept_by`; rods on the axis line spin in place)."""
        spin = self.spinning(names, axis, centre2)
        cells = [c for n in names for c in self.cells_of(n) if c not in spin]
        return swept_by(cells, axis, quarter, centre2) | spin

    def turn_problem(self, move: TurnMove) -> str | None:
        """Why the (well-formed, one-part) turn is illegal here, or None: its centre must lie in
        the group's bounding box, and the turning group must sweep through no other piece (a
        rod of another piece spinning on the axis line is passed by, never hit)."""
        a = move.axis_index
        group = [c for n in move.pieces for c in self.cells_of(n)]
        if not centre_inside(group, a, move.centre2):
            return "the axis must pass through the group's bounding box"
        swept = self.turn_sweep(move.pieces, a, move.quarter, move.centre2)
        part = self.part_of(move.pieces[0])
        for other in sorted(part - set(move.pieces)):
            fixed = self.cells_of(other) - self.spinning([other], a, move.centre2)
            hit = sorted(swept & fixed)
            if hit:
                return f"it would sweep through {other} at {hit[0]}"
        return None

    def removes(self, move: Move | TurnMove) -> bool:
        """Does this (legal) move take its group out of the part? True for distance None and for
        a finite move long enough to clear the rest for good; never for a turn."""
        if isinstance(move, TurnMove):
            return False
        if move.distance is None:
            return True
        if self.free_distance(move.pieces, move.direction) is not None:
            return False
        return move.distance >= self.clearance(move.pieces, move.direction)

    def apply(self, move: Move | TurnMove) -> Assembly:
        """The assembly after ``move`` (checked); this object is left unchanged."""
        self.check(move)
        if isinstance(move, TurnMove):
            return self.turned(move)
        group = frozenset(move.pieces)
        if self.removes(move):
            part = self.part_of(move.pieces[0])
            parts = (*tuple(p for p in self.parts if p != part), group, part - group)
            return self.moved(self.offsets, _sorted_parts(parts))
        d = DIRECTIONS[move.direction]
        k = move.distance
        assert k is not None  # distance None always removes
        offsets = dict(self.offsets)
        for n in move.pieces:
            x, y, z = offsets[n]
            offsets[n] = (x + d[0] * k, y + d[1] * k, z + d[2] * k)
        return self.moved(offsets)

    def turned(self, move: TurnMove) -> Assembly:
        """The group of ``move`` turned (not checked): new orientations and offsets."""
        offsets = dict(self.offsets)
        rotations = dict(self.rotations)
        for n in move.pieces:
            r, offsets[n] = turn_pose(ROTATIONS[self.rotation_of(n)], offsets[n], move)
            rotations[n] = rotation_index(r)
        rotations = {n: r for n, r in rotations.items() if r != 0}
        return Assembly(self.shapes, offsets, self.parts, rotations, self.rods)


class SearchLimitError(ChainGeoError, RuntimeError):
    """A search or enumeration stopped at its cap; the message says which cap and how to lift it.

    ``reason`` says what was reached; ``cap`` names the cap when it is a field of the caller's
    limits (``"seconds"``, ``"max_states"``, ...), so a front end names its own option for it
    (the command line its flag) while the message names the Python field."""

    def __init__(self, reason: str, cap: str | None = None, owner: str = "SearchLimits") -> None:
        hint = f"; raise {owner}({cap}=...)" if cap else ""
        super().__init__(reason + hint)
        self.reason = reason
        self.cap = cap


def movable_groups(state: Assembly, direction: str, limit: int = 4096) -> list[tuple[str, ...]]:
    """Every group of one part that can take a unit step (or more) in ``direction``.

    A group can step exactly when it is closed under "is blocked by": whoever blocks a member
    must come along. So the groups are the proper, non-empty closed subsets of each part; they
    are enumerated from the blocking relation, never by trying all subsets.
    """
    out: list[tuple[str, ...]] = []
    for part in state.parts:
        if len(part) < 2:
            continue
        names = sorted(part)
        needs = {n: frozenset(state.blockers(n, direction)) for n in names}
        closure: dict[str, frozenset[str]] = {}
        for n in names:
            seen = {n}
            stack = [n]
            while stack:
                for b in needs[stack.pop()]:
                    if b not in seen:
                        seen.add(b)
                        stack.append(b)
            closure[n] = frozenset(seen)
        found = _unions_of_closures(part, closure, limit, direction)
        out.extend(tuple(sorted(g)) for g in found)
    return sorted(out, key=lambda g: (len(g), g))


def _unions_of_closures(
    part: frozenset[str], closure: Mapping[str, frozenset[str]], limit: int, direction: str
) -> set[frozenset[str]]:
    """Closed sets are exactly the unions of single-piece closures: grow them breadth first."""
    found: set[frozenset[str]] = set()
    frontier = [c for c in closure.values() if c != part]
    found.update(frontier)
    while frontier:
        nxt_frontier: list[frozenset[str]] = []
        for current in frontier:
            for n in sorted(part - current):
                nxt = current | closure[n]
                if nxt != part and nxt not in found:
                    found.add(nxt)
                    nxt_frontier.append(nxt)
            if len(found) > limit:
                raise SearchLimitError(
                    f"more than {limit} movable groups along {direction}; raise the limit"
                )
        frontier = nxt_frontier
    return found


def legal_moves(state: Assembly, max_group: int | None = None) -> list[Move]:
    """All legal moves, sorted: each movable group, each direction, every distance it can go
    (finite steps short of clearing the rest, and one removal when it can leave)."""
    moves: list[Move] = []
    for direction in DIRECTIONS:
        for group in movable_groups(state, direction):
            if max_group is not None and len(group) > max_group:
                continue
            free = state.free_distance(group, direction)
            if free is None:
                moves.extend(
                    Move(group, direction, k) for k in range(1, state.clearance(group, direction))
                )
                moves.append(Move(group, direction, None))
            else:
                moves.extend(Move(group, direction, k) for k in range(1, free + 1))
    return sorted(moves, key=lambda m: (m.pieces, m.direction, m.distance is None, m.distance or 0))


def legal_turns(state: Assembly, max_group: int | None = None) -> list[TurnMove]:
    """Every legal turn, sorted: each proper group of a part (every subset, tried one by one:
    this is the reference), each axis and sense, each centre in the group's bounding box."""
    out: list[TurnMove] = []
    for part in state.parts:
        names = sorted(part)
        top = len(names) - 1 if max_group is None else min(max_group, len(names) - 1)
        for size in range(1, top + 1):
            for group in combinations(names, size):
                cells = [c for n in group for c in state.cells_of(n)]
                others = [n for n in names if n not in group]
                rest = {c for n in others for c in state.cells_of(n)}
                for a, axis in enumerate(AXES):
                    for centre in centres_within(cells, a):
                        fixed = rest - state.spinning(others, a, centre)
                        for q in (1, -1):
                            if state.turn_sweep(group, a, q, centre).isdisjoint(fixed):
                                out.append(TurnMove(group, axis, q, centre))
    return sorted(out)


def move_sort_key(m: Move | TurnMove) -> tuple[Any, ...]:
    """One order for translations and turns: by group, then translations (as
    :func:`legal_moves` sorts them), then turns by axis, sense and centre."""
    if isinstance(m, TurnMove):
        return (m.pieces, "rotate", m.axis, m.quarter, m.centre2)
    return (m.pieces, m.direction, m.distance is None, m.distance or 0)


def legal_steps(
    state: Assembly, max_group: int | None = None, turns: bool = False
) -> list[Move | TurnMove]:
    """:func:`legal_moves`, and with ``turns`` :func:`legal_turns` too, in one sorted list."""
    steps: list[Move | TurnMove] = [*legal_moves(state, max_group)]
    if turns:
        steps.extend(legal_turns(state, max_group))
    return sorted(steps, key=move_sort_key)


def _sorted_parts(parts: Iterable[frozenset[str]]) -> tuple[frozenset[str], ...]:
    return tuple(sorted(parts, key=lambda p: sorted(p)))


def replay_disassembly(
    shapes: Mapping[str, Shape],
    moves: Sequence[Move | TurnMove],
    rods: Mapping[str, Mapping[Cell, int]] | None = None,
) -> Assembly:
    """Apply ``moves`` from the assembled state; raise :class:`MoveError` at the first bad one."""
    state = Assembly.assembled(shapes, rods)
    for m in moves:
        state = state.apply(m)
    return state


def disassembly_of_assembly_plan(moves: Sequence[Move | TurnMove]) -> list[Move | TurnMove]:
    """An assembly plan is a disassembly played backwards: reverse it and invert each move."""
    return [m.inverse() for m in reversed(moves)]


def insertion_shifts(moving: Iterable[Cell], fixed: Iterable[Cell], direction: str) -> list[Cell]:
    """Every translation ``t`` (lexicographic order) by which the cells ``moving`` can come in
    along ``direction`` from infinitely far and land next to ``fixed``: nothing overlaps, the
    way in is free, and the two bounding boxes touch or overlap on every axis (the bound that
    keeps an assembly's action set finite). The reference for the numba kernel of
    :mod:`chaingeo.insertions`."""
    acells, bcells = list(moving), list(fixed)
    d = DIRECTIONS[direction]
    axis = next(i for i in range(3) if d[i])
    sign = d[axis]
    lat = [i for i in range(3) if i != axis]
    # lines[lateral] = axis values v of the shifts that overlap b (t in D iff a + t meets b)
    lines: dict[tuple[int, int], list[int]] = {}
    for a in acells:
        for b in bcells:
            v = (b[0] - a[0], b[1] - a[1], b[2] - a[2])
            lines.setdefault((v[lat[0]], v[lat[1]]), []).append(v[axis])
    bound = {k: (min(vs), max(vs)) for k, vs in lines.items()}
    lo = [min(c[i] for c in bcells) - 1 - max(c[i] for c in acells) for i in range(3)]
    hi = [max(c[i] for c in bcells) + 1 - min(c[i] for c in acells) for i in range(3)]
    out: list[Cell] = []
    for t0 in range(lo[0], hi[0] + 1):
        for t1 in range(lo[1], hi[1] + 1):
            for t2 in range(lo[2], hi[2] + 1):
                t = (t0, t1, t2)
                line = bound.get((t[lat[0]], t[lat[1]]))
                if line is not None and (t[axis] >= line[0] if sign > 0 else t[axis] <= line[1]):
                    continue  # the way back out along -direction meets b
                out.append(t)
    return out


# ---------------------------------------------------------------------------------------------
# Reference searches (pure Python): the oracle the numba search is tested and timed against
# ---------------------------------------------------------------------------------------------


def state_key(state: Assembly) -> tuple[tuple[Any, ...], ...]:
    """Hashable identity of a state: each part with its offsets relative to its first piece
    (positions are relative: moving a group one way equals moving the rest the other way).
    Where turns left pieces of a part in different orientations, the part is seen from its
    first piece's pose (the whole part turned back so that piece is as assembled) and the
    relative orientations follow the offsets."""
    out: list[tuple[Any, ...]] = []
    for part in state.parts:
        names = sorted(part)
        base = state.rotation_of(names[0])
        bx, by, bz = state.offsets[names[0]]
        rel = tuple((x - bx, y - by, z - bz) for x, y, z in (state.offsets[n] for n in names))
        rots = tuple(state.rotation_of(n) for n in names)
        if base:  # see the part from its first piece: turn it all back to that piece's pose
            back = ROTATIONS[base].T
            rel = tuple(_cell(back @ np.asarray(v, dtype=np.int64)) for v in rel)
            rots = tuple(rotation_index(back @ ROTATIONS[r]) for r in rots)
        out.append((tuple(names), rel) if not any(rots) else (tuple(names), rel, rots))
    return tuple(sorted(out))


def _cell(v: Any) -> Cell:
    return (int(v[0]), int(v[1]), int(v[2]))


def blocking_matrix(state: Assembly, direction: str) -> dict[tuple[str, str], int | None]:
    """``(i, j) -> how far i alone can travel along direction with j fixed`` (None: never
    meets it), for every ordered pair of pieces in the same part: Cutler's movement matrix."""
    d = DIRECTIONS[direction]
    out: dict[tuple[str, str], int | None] = {}
    for part in state.parts:
        for i in sorted(part):
            for j in sorted(part):
                if i != j:
                    out[(i, j)] = _max_free_run(state.cells_of(i), state.cells_of(j), d)
    return out


def reference_first_level(
    shapes: Mapping[str, Shape],
    max_group: int | None = None,
    max_states: int = 200_000,
    turns: bool = False,
    rods: Mapping[str, Mapping[Cell, int]] | None = None,
) -> int | None:
    """Fewest moves until some group leaves the assembled puzzle (the removal counts): the first
    number of BurrTools' level, by plain breadth-first search; None if nothing ever leaves.
    Raises :class:`SearchLimitError` past ``max_states`` states. For tests."""
    start = Assembly.assembled(shapes, rods)
    seen = {state_key(start)}
    frontier = [start]
    depth = 0
    while frontier:
        depth += 1
        nxt: list[Assembly] = []
        for state in frontier:
            for move in legal_steps(state, max_group, turns):
                if state.removes(move):
                    return depth
                child = state.apply(move)
                key = state_key(child)
                if key not in seen:
                    seen.add(key)
                    nxt.append(child)
        if len(seen) > max_states:
            raise SearchLimitError(f"reference search passed {max_states} states")
        frontier = nxt
    return None


def reference_optimal_disassembly(
    shapes: Mapping[str, Shape],
    max_group: int | None = None,
    max_states: int = 200_000,
    turns: bool = False,
    rods: Mapping[str, Mapping[Cell, int]] | None = None,
) -> list[Move | TurnMove] | None:
    """Fewest moves taking every piece apart, by plain breadth-first search over whole states
    (all parts at once); None if impossible. Exponential: for small puzzles and tests only."""
    start = Assembly.assembled(shapes, rods)
    if start.is_separated():
        return []
    seen: dict[object, tuple[object, Move | TurnMove | None]] = {state_key(start): (None, None)}
    frontier = [start]
    while frontier:
        nxt: list[Assembly] = []
        for state in frontier:
            for move in legal_steps(state, max_group, turns):
                child = state.apply(move)
                key = state_key(child)
                if key in seen:
                    continue
                seen[key] = (state_key(state), move)
                if child.is_separated():
                    plan: list[Move | TurnMove] = []
                    k: object = key
                    while True:
                        prev, m = seen[k]
                        if m is None:
                            break
                        plan.append(m)
                        k = prev
                    return plan[::-1]
                if len(seen) > max_states:
                    raise SearchLimitError(
                        f"reference search passed {max_states} states; raise max_states"
                    )
                nxt.append(child)
        frontier = nxt
    return None
