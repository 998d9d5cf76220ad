"""A deliberately naive exact-cover counter (pure Python sets) used as a test oracle.

It shares no code with :mod:`solvers`: orientations come from the 24 rotation matrices,
translations from brute force, symmetries from the 48 signed permutations.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from chaingeo.core.geometry import SYMMETRIES

Cell = tuple[int, int, int]
Piece = tuple[frozenset[Cell], int, int]  # cells, min copies, max copies


def _normal(cells: frozenset[Cell]) -> frozenset[Cell]:
    mx = min(c[0] for c in cells)
    my = min(c[1] for c in cells)
    mz = min(c[2] for c in cells)
    return frozenset((x - mx, y - my, z - mz) for x, y, z in cells)


def _apply(m: npt.NDArray[np.int64], cells: frozenset[Cell]) -> frozenset[Cell]:
    out: set[Cell] = set()
    for c in cells:
        x, y, z = (int(v) for v in m @ np.array(c))
        out.add((x, y, z))
    return frozenset(out)


def placements(shape: frozenset[Cell], target: frozenset[Cell]) -> list[frozenset[Cell]]:
    orients = {_normal(_apply(m, shape)) for m in SYMMETRIES[:24]}
    out = set()
    for o in orients:
        for t in target:
            for anchor in o:
                d = (t[0] - anchor[0], t[1] - anchor[1], t[2] - anchor[2])
                p = frozenset((x + d[0], y + d[1], z + d[2]) for x, y, z in o)
                if p <= target:
                    out.add(p)
    return sorted(out, key=sorted)


def solutions(
    pieces: Sequence[Piece], target: frozenset[Cell], optional: frozenset[Cell] = frozenset()
) -> list[frozenset[tuple[int, frozenset[Cell]]]]:
    """All solutions as sets of (piece type index, cells); identical types must be pre-merged."""
    table = [placements(s, target) for s, _, _ in pieces]
    mandatory = sorted(target - optional)
    found: list[frozenset[tuple[int, frozenset[Cell]]]] = []

    def rec(
        filled: frozenset[Cell], used: list[int], chosen: list[tuple[int, frozenset[Cell]]]
    ) -> None:
        empty = [c for c in mandatory if c not in filled]
        if not empty:
            if all(used[i] >= lo for i, (_, lo, _) in enumerate(pieces)):
                found.append(frozenset(chosen))
            return
        cell = empty[0]
        for i, (_, _, hi) in enumerate(pieces):
            if used[i] >= hi:
                continue
            for p in table[i]:
                if cell in p and not (p & filled):
                    used[i] += 1
                    chosen.append((i, p))
                    rec(filled | p, used, chosen)
                    chosen.pop()
                    used[i] -= 1

    rec(frozenset(), [0] * len(pieces), [])
    return found


def distinct(
    sols: list[frozenset[tuple[int, frozenset[Cell]]]],
    pieces: Sequence[Piece],
    target: frozenset[Cell],
    reflections: bool,
    optional: frozenset[Cell] = frozenset(),
) -> int:
    """Orbits of the solutions under the symmetries of (target, optional cells), pieces
    identified by shape."""
    lo = tuple(min(c[i] for c in target) for i in range(3))

    def norm_key(cells: frozenset[Cell]) -> frozenset[Cell]:
        forms = [_normal(_apply(m, cells)) for m in SYMMETRIES[:24]]
        return min(forms, key=sorted)

    kinds = [norm_key(s) for s, _, _ in pieces]

    def as_shapes(
        sol: frozenset[tuple[int, frozenset[Cell]]],
    ) -> frozenset[tuple[frozenset[Cell], frozenset[Cell]]]:
        return frozenset((kinds[i], cells) for i, cells in sol)

    canon = {as_shapes(s) for s in sols}
    group = []
    for m in SYMMETRIES if reflections else SYMMETRIES[:24]:
        img = _apply(m, target)
        shift = tuple(lo[i] - min(c[i] for c in img) for i in range(3))
        if frozenset((x + shift[0], y + shift[1], z + shift[2]) for x, y, z in img) != target:
            continue
        moved = _apply(m, optional)
        if frozenset((x + shift[0], y + shift[1], z + shift[2]) for x, y, z in moved) == optional:
            group.append((m, shift))
    seen: set[frozenset[tuple[frozenset[Cell], frozenset[Cell]]]] = set()
    orbits = 0
    for sol in canon:
        if sol in seen:
            continue
        orbits += 1
        for m, shift in group:
            image = frozenset(
                (
                    norm_key(_apply(m, cells)),
                    frozenset(
                        (x + shift[0], y + shift[1], z + shift[2]) for x, y, z in _apply(m, cells)
                    ),
                )
                for _, cells in sol
            )
            if image in canon:
                seen.add(image)
    return orbits


def box(a: int, b: int, c: int) -> frozenset[Cell]:
    return frozenset(itertools.product(range(a), range(b), range(c)))
