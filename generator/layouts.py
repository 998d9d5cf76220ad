"""Target shapes for generated interlocking puzzles, as *layouts* of overlapping piece slots.

A layout is a list of slots (voxel sets) that overlap; a *design* says, for every cell shared by
two or more slots, which slot owns it (or that it stays empty). Piece ``k`` is its slot's own
cells plus the shared cells it owns, so any design is a non-overlapping assembly of the target:
burrs (sticks crossing in the middle), plate burrs and burrs made of several burr units. Cube
layouts instead partition an ``n x n x n`` cube (:func:`cube_cells`), handled by the generator.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache

from chaingeo.geometry import Cell, Shape
from chaingeo.piecesets.burrs import SLOTS, slot_cells


@dataclass(frozen=True)
class Layout:
    name: str
    slots: tuple[Shape, ...]
    description: str

    @property
    def shared(self) -> tuple[Cell, ...]:
        """Cells in two or more slots, sorted."""
        return _shared(self.slots)

    def owners(self, cell: Cell) -> tuple[int, ...]:
        return tuple(i for i, s in enumerate(self.slots) if cell in s.cell_set)

    def pieces(self, design: Sequence[int]) -> list[Shape]:
        """The pieces of ``design`` (owner slot per shared cell, -1 for empty)."""
        shared = self.shared
        if len(design) != len(shared):
            raise ValueError(f"a design has {len(shared)} entries, got {len(design)}")
        shared_set = set(shared)
        out: list[list[Cell]] = [
            [c for c in s.cells if c not in shared_set] for s in self.slots
        ]
        for cell, owner in zip(shared, design, strict=True):
            if owner >= 0:
                out[owner].append(cell)
        return [Shape(cells) for cells in out]


@cache
def _shared(slots: tuple[Shape, ...]) -> tuple[Cell, ...]:
    count: dict[Cell, int] = {}
    for s in slots:
        for c in s.cells:
            count[c] = count.get(c, 0) + 1
    return tuple(sorted(c for c, k in count.items() if k > 1))


def _box(lo: Cell, size: Cell) -> Shape:
    return Shape(
        [
            (lo[0] + i, lo[1] + j, lo[2] + k)
            for i in range(size[0])
            for j in range(size[1])
            for k in range(size[2])
        ]
    )


def _stick(axis: int, corner: Cell, length: int) -> Shape:
    size = [2, 2, 2]
    size[axis] = length
    return _box(corner, (size[0], size[1], size[2]))


def burr6() -> Layout:
    return Layout(
        "burr6",
        tuple(slot_cells(a, c) for a, c in SLOTS),
        "six-piece burr (Kongming / Lu Ban lock): six 2x2x6 sticks, three pairs crossing",
    )


def burr3() -> Layout:
    """Three 2x2x6 sticks through one central 2x2x2 cube, one per axis."""
    return Layout(
        "burr3",
        (_stick(0, (0, 2, 2), 6), _stick(1, (2, 0, 2), 6), _stick(2, (2, 2, 0), 6)),
        "three-piece burr: three 2x2x6 sticks crossing in one 2x2x2 core",
    )


def plate3() -> Layout:
    """Three 2-thick 6x6 plates, one per axis, crossing in the middle."""
    return Layout(
        "plate3",
        (_box((2, 0, 0), (2, 6, 6)), _box((0, 2, 0), (6, 2, 6)), _box((0, 0, 2), (6, 6, 2))),
        "three-plate burr: three 6x6 plates, 2 thick, crossing in the middle",
    )


def burr_chain(units: int) -> Layout:
    """``units`` six-piece burr units in a row along x, sharing two long x-sticks: the y- and
    z-sticks of each unit are its own, so there are ``2 + 4 * units`` pieces."""
    slots: list[Shape] = [_stick(0, (0, 2, 1), 6 * units), _stick(0, (0, 2, 3), 6 * units)]
    for u in range(units):
        for axis, corner in SLOTS:
            if axis == 0:
                continue
            slots.append(slot_cells(axis, (corner[0] + 6 * u, corner[1], corner[2])))
    return Layout(
        f"burr{2 + 4 * units}",
        tuple(slots),
        f"larger burr: {units} burr units along two shared {6 * units}-long sticks",
    )


LAYOUTS = {
    "burr6": burr6,
    "burr3": burr3,
    "plate3": plate3,
    "burr10": lambda: burr_chain(2),
    "burr14": lambda: burr_chain(3),
    "burr18": lambda: burr_chain(4),
    "burr34": lambda: burr_chain(8),
}


def get_layout(name: str) -> Layout:
    try:
        return LAYOUTS[name]()
    except KeyError:
        raise ValueError(
            f"unknown puzzle shape {name!r}; known: {sorted(LAYOUTS)} and cubeN (e.g. cube3)"
        ) from None


def cube_cells(n: int) -> list[Cell]:
    return [(x, y, z) for x in range(n) for y in range(n) for z in range(n)]
