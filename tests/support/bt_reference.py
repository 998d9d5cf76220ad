"""A deliberately naive oracle for BurrTools' problem semantics (pure Python sets).

It shares no code with :mod:`solvers`: orientations from the 24 rotation matrices, placements
by brute force, assemblies by plain backtracking (every fixed result cell covered once, every
variable cell at most once, each part ``lo..hi`` times, pieces may lie wholly on variable
cells, colour rules per voxel), classes by joining every assembly with its images under the
result's symmetries *that are assemblies too*, and taking apart by breadth-first search with
the reference kinematics (:mod:`chaingeo.core.kinematics`) under BurrTools' group rule.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from chaingeo.core.geometry import SYMMETRIES, Shape
from chaingeo.core.kinematics import Assembly, legal_moves, state_key

Cell = tuple[int, int, int]
Voxel = tuple[Cell, int]  # (cell, colour)
Placed = frozenset[Voxel]


@dataclass(frozen=True)
class RefPart:
    voxels: frozenset[Voxel]
    lo: int = 1
    hi: int = 1
    group: int = 0  # one group for every piece of the part (0: none)


def _apply(m: np.ndarray, vox: frozenset[Voxel]) -> frozenset[Voxel]:
    out = set()
    for (x, y, z), c in vox:
        a, b, d = (int(v) for v in m @ np.array((x, y, z)))
        out.add(((a, b, d), c))
    return frozenset(out)


def _normal(vox: frozenset[Voxel]) -> frozenset[Voxel]:
    lo = [min(v[0][i] for v in vox) for i in range(3)]
    return frozenset(((x - lo[0], y - lo[1], z - lo[2]), c) for (x, y, z), c in vox)


def placements(
    part: RefPart,
    cells: frozenset[Cell],
    color: Mapping[Cell, int],
    allowed: Callable[[int, int], bool],
) -> list[Placed]:
    orients = {_normal(_apply(m, part.voxels)) for m in SYMMETRIES[:24]}
    out: set[Placed] = set()
    for o in orients:
        (ax, ay, az), _ = min(o)
        for tx, ty, tz in cells:
            d = (tx - ax, ty - ay, tz - az)
            p = frozenset(((x + d[0], y + d[1], z + d[2]), c) for (x, y, z), c in o)
            if all(v in cells and allowed(c, color.get(v, 0)) for v, c in p):
                out.add(p)
    return sorted(out, key=sorted)


def assemblies(
    parts: Sequence[RefPart],
    fixed: frozenset[Cell],
    variable: frozenset[Cell],
    color: Mapping[Cell, int],
    allowed: Callable[[int, int], bool],
    max_holes: int | None = None,
) -> list[frozenset[tuple[int, Placed]]]:
    """Every assembly as a set of ``(part index, placed voxels)`` (parts must be distinct
    shapes, else copies would be counted in every order)."""
    cells = fixed | variable
    table = [placements(p, cells, color, allowed) for p in parts]
    found: list[frozenset[tuple[int, Placed]]] = []

    floating = [(i, p) for i, t in enumerate(table) for p in t if _floating(p, fixed)]

    def finish(
        filled: set[Cell], used: list[int], chosen: list[tuple[int, Placed]], k: int
    ) -> None:
        """Add pieces wholly on free variable cells, in list order (each set once)."""
        enough = all(used[i] >= p.lo for i, p in enumerate(parts))
        if enough and (max_holes is None or len(variable - filled) <= max_holes):
            found.append(frozenset(chosen))
        for j in range(k, len(floating)):
            i, p = floating[j]
            pc = {v for v, _ in p}
            if used[i] < parts[i].hi and not (pc & filled):
                used[i] += 1
                chosen.append((i, p))
                finish(filled | pc, used, chosen, j + 1)
                chosen.pop()
                used[i] -= 1

    def rec(filled: set[Cell], used: list[int], chosen: list[tuple[int, Placed]]) -> None:
        empty = sorted(fixed - filled)
        if not empty:
            finish(filled, used, chosen, 0)
            return
        cell = empty[0]
        for i, part in enumerate(parts):
            if used[i] >= part.hi:
                continue
            for p in table[i]:
                pc = {v for v, _ in p}
                if cell in pc and not (pc & filled):
                    used[i] += 1
                    chosen.append((i, p))
                    rec(filled | pc, used, chosen)
                    chosen.pop()
                    used[i] -= 1

    rec(set(), [0] * len(parts), [])
    return sorted(set(found), key=lambda a: sorted((i, sorted(p)) for i, p in a))


def _floating(p: Placed, fixed: frozenset[Cell]) -> bool:
    return not any(v in fixed for v, _ in p)


def symmetries(
    fixed: frozenset[Cell], variable: frozenset[Cell], color: Mapping[Cell, int], mirrors: bool
) -> list[tuple[np.ndarray, Cell]]:
    """The result's symmetries (cells, variable marks and colours kept)."""
    cells = fixed | variable
    lo = tuple(min(c[i] for c in cells) for i in range(3))
    out = []
    for m in SYMMETRIES if mirrors else SYMMETRIES[:24]:
        img = {c: tuple(int(v) for v in m @ np.array(c)) for c in cells}
        shift = tuple(lo[i] - min(v[i] for v in img.values()) for i in range(3))
        moved = {c: (v[0] + shift[0], v[1] + shift[1], v[2] + shift[2]) for c, v in img.items()}
        if (
            set(moved.values()) == cells
            and all((moved[c] in variable) == (c in variable) for c in cells)
            and all(color.get(moved[c], 0) == color.get(c, 0) for c in cells)
        ):
            out.append((m, (shift[0], shift[1], shift[2])))
    return out


def classes(
    found: list[frozenset[tuple[int, Placed]]],
    parts: Sequence[RefPart],
    group: list[tuple[np.ndarray, Cell]],
) -> list[frozenset[tuple[int, Placed]]]:
    """One assembly per class: two assemblies are one when a symmetry maps one onto the other
    (pieces identified by their placed coloured voxels)."""
    as_voxels = {frozenset(p for _, p in a): a for a in found}
    seen: set[frozenset[Placed]] = set()
    reps = []
    for a in found:
        key = frozenset(p for _, p in a)
        if key in seen:
            continue
        reps.append(a)
        for m, s in group:
            img = frozenset(
                frozenset(((x + s[0], y + s[1], z + s[2]), c) for (x, y, z), c in _apply(m, p))
                for p in key
            )
            if img in as_voxels:
                seen.add(img)
    return reps


def comes_apart(pieces: Mapping[str, frozenset[Cell]], group_of: Mapping[str, int]) -> bool:
    """Some sequence of moves separates the pieces into parts that are single pieces or made
    of one group only (BurrTools' rule 1; the whole puzzle is always searched)."""
    start = Assembly.assembled({n: Shape(sorted(c)) for n, c in pieces.items()})
    seen = {state_key(start)}
    frontier = [start]
    while frontier:
        nxt = []
        for state in frontier:
            for move in legal_moves(state):
                if state.removes(move):
                    part = state.part_of(move.pieces[0])
                    sides = [frozenset(move.pieces), part - set(move.pieces)]
                    if all(_settled(side, state, group_of) for side in sides):
                        return True
                    continue
                child = state.apply(move)
                k = state_key(child)
                if k not in seen:
                    seen.add(k)
                    nxt.append(child)
        frontier = nxt
    return False


def _settled(side: frozenset[str], state: Assembly, group_of: Mapping[str, int]) -> bool:
    if len(side) == 1:
        return True
    gids = {group_of.get(n, 0) for n in side}
    if len(gids) == 1 and 0 not in gids:
        return True
    return comes_apart({n: state.cells_of(n) for n in side}, group_of)
