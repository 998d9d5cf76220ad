"""Target shapes for generated interlocking puzzles, as *layouts* of overlapping piece slots.

A layout is a list of slots (voxel sets) that overlap; a *design* says, for every cell shared by
two or more slots, which slot owns it (or that it stays empty). Piece ``k`` is its slot's own
cells plus the shared cells it owns, so any design is a non-overlapping assembly of the target:
six-piece burrs, towers of stacked burr units (12 pieces and up), three-piece burrs and
three-plate burrs. Cube
layouts instead partition an ``n x n x n`` cube (:func:`cube_cells`), handled by the generator.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cache, partial

from chaingeo.core.geometry import Cell, Shape
from chaingeo.core.piecesets.burrs import SLOTS, slot_cells
from chaingeo.core.registry import Registry


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
        return [Shape(cells) for cells in self.piece_cells(design)]

    def piece_cells(self, design: Sequence[int]) -> list[list[Cell]]:
        """The cells of each piece of ``design``, unsorted (no shapes built: the search asks
        only whether they are connected, of many designs)."""
        shared = self.shared
        if len(design) != len(shared):
            raise ValueError(f"a design has {len(shared)} entries, got {len(design)}")
        shared_set = set(shared)
        out: list[list[Cell]] = [[c for c in s.cells if c not in shared_set] for s in self.slots]
        for cell, owner in zip(shared, design, strict=True):
            if owner >= 0:
                out[owner].append(cell)
        return out


@cache
def _shared(slots: tuple[Shape, ...]) -> tuple[Cell, ...]:
    count: dict[Cell, int] = {}
    for s in slots:
        for c in s.cells:
            count[c] = count.get(c, 0) + 1
    return tuple(sorted(c for c, k in count.items() if k > 1))


def burr6() -> Layout:
    return Layout(
        "burr6",
        tuple(slot_cells(a, c) for a, c in SLOTS),
        "six-piece burr (Kongming / Lu Ban lock): six 2x2x6 sticks, three pairs crossing",
    )


def burr_tower(units: int) -> Layout:
    """``units`` six-piece burr units stacked along z: the z-sticks of neighbouring units meet
    end to end, so the units block one another; ``6 * units`` pieces."""
    slots = [
        slot_cells(axis, (corner[0], corner[1], corner[2] + 6 * u))
        for u in range(units)
        for axis, corner in SLOTS
    ]
    return Layout(
        f"burr{6 * units}",
        tuple(slots),
        f"larger burr: a tower of {units} six-piece burr units stacked along z",
    )


def _box(lo: Cell, size: Cell) -> Shape:
    return Shape(
        [
            (lo[0] + i, lo[1] + j, lo[2] + k)
            for i in range(size[0])
            for j in range(size[1])
            for k in range(size[2])
        ]
    )


def three_crossing(
    name: str, length: int, first: tuple[int, int], second: tuple[int, int], description: str
) -> Layout:
    """Three mutually orthogonal boxes in a cyclic ("twisted") arrangement.

    The box along axis ``a`` is ``length`` long on ``a``; on axis ``a + 1`` it covers
    ``first = (width, start)`` and on axis ``a + 2`` ``second = (width, start)`` (axes mod 3),
    so the three boxes are images of one another under the cyclic permutation x -> y -> z.
    When the two starts differ, each box crosses the others off-centre: every stick (or plate)
    covers only part of the others' paths, which is what lets translation-only designs come
    apart. Boxes sharing one centred core (equal starts, full cross-sections) are always locked:
    each piece must keep a bridge through the core, and every bridge lies in the others' paths.
    """
    slots = []
    for axis in range(3):
        lo = [0, 0, 0]
        size = [0, 0, 0]
        size[axis] = length
        for (width, start), other in ((first, (axis + 1) % 3), (second, (axis + 2) % 3)):
            lo[other], size[other] = start, width
        slots.append(_box((lo[0], lo[1], lo[2]), (size[0], size[1], size[2])))
    return Layout(name, tuple(slots), description)


def burr3() -> Layout:
    """Three-piece burr: three 3x3x7 sticks; each pair overlaps two units deep (38 shared cells;
    random designs with holes plus hill climbing reach levels 2 to 5, see
    docs/guides/generating.md)."""
    return three_crossing(
        "burr3",
        7,
        (3, 2),
        (3, 1),
        "three-piece burr: three 3x3x7 sticks crossing pairwise, off-centre",
    )


def plate3() -> Layout:
    """Three-plate burr: three notched 6x4x1 plates, each slotted through the other two
    (10 shared cells; every design that comes apart has level 2 or 3, checked exhaustively)."""
    return three_crossing(
        "plate3",
        6,
        (4, 1),
        (1, 2),
        "three-plate burr: three 6x4x1 notched plates, mutually orthogonal",
    )


#: Layout builders by puzzle shape name; cubeN, mazeN and burr6x8[u] have families of their
#: own (:data:`chaingeo.generator.puzzle.SHAPES`).
LAYOUTS: Registry[Callable[[], Layout]] = Registry(
    "puzzle shape", missing="unknown {kind} {name!r} (cubeN, mazeN, burr6x8, burr6x8u or a layout)"
)
LAYOUTS.register("burr3", burr3)
LAYOUTS.register("plate3", plate3)
LAYOUTS.register("burr6", burr6)
LAYOUTS.register("burr12", partial(burr_tower, 2))
LAYOUTS.register("burr18", partial(burr_tower, 3))
LAYOUTS.register("burr24", partial(burr_tower, 4))
LAYOUTS.register("burr36", partial(burr_tower, 6))


def get_layout(name: str) -> Layout:
    return LAYOUTS.get(name)()


def cube_cells(n: int) -> list[Cell]:
    return [(x, y, z) for x in range(n) for y in range(n) for z in range(n)]
