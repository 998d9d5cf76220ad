"""Built-in piece sets (data) with the packing counts published for them.

The counts are the reference figures the exact-cover engine is tested against: ``solutions``
counts every packing, ``distinct`` counts them up to the box's rotations and reflections.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from chaingeo.core.geometry import Shape


@dataclass(frozen=True)
class KnownPacking:
    box: tuple[int, int, int]
    solutions: int | None
    distinct: int
    solid: bool = False  # pentominoes used as free 3D pieces rather than flat in a 1-thick box


@dataclass(frozen=True)
class PieceSet:
    name: str
    description: str
    pieces: dict[str, Shape]
    packings: tuple[KnownPacking, ...] = field(default=())

    @property
    def cells(self) -> int:
        return sum(len(s) for s in self.pieces.values())


def _flat(rows: str) -> Shape:
    """A one-voxel-thick piece drawn as text rows ('#' filled), row i at y = i, z = 0."""
    cells = [
        (x, y, 0)
        for y, line in enumerate(rows.strip().splitlines())
        for x, ch in enumerate(line.strip())
        if ch == "#"
    ]
    return Shape(cells)


SOMA = PieceSet(
    name="soma",
    description="Piet Hein's Soma cube: the seven irregular polycubes of at most four cells",
    pieces={
        "V": Shape([(0, 0, 0), (1, 0, 0), (0, 1, 0)]),
        "L": Shape([(0, 0, 0), (1, 0, 0), (2, 0, 0), (0, 1, 0)]),
        "T": Shape([(0, 0, 0), (1, 0, 0), (2, 0, 0), (1, 1, 0)]),
        "Z": Shape([(0, 0, 0), (1, 0, 0), (1, 1, 0), (2, 1, 0)]),
        "A": Shape([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 0, 1)]),  # right screw
        "B": Shape([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 1, 1)]),  # left screw (mirror of A)
        "P": Shape([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]),  # branch / tripod
    },
    packings=(KnownPacking((3, 3, 3), 11520, 240),),
)

PENTOMINOES = PieceSet(
    name="pentominoes",
    description="The 12 pentominoes, one voxel thick",
    pieces={
        "F": _flat(".##\n##.\n.#."),
        "I": _flat("#####"),
        "L": _flat("#.\n#.\n#.\n##"),
        "N": _flat("##..\n.###"),
        "P": _flat("##\n##\n#."),
        "T": _flat("###\n.#.\n.#."),
        "U": _flat("#.#\n###"),
        "V": _flat("#..\n#..\n###"),
        "W": _flat("#..\n##.\n.##"),
        "X": _flat(".#.\n###\n.#."),
        "Y": _flat(".#..\n####"),
        "Z": _flat("##.\n.#.\n.##"),
    },
    packings=(
        KnownPacking((6, 10, 1), 9356, 2339),
        KnownPacking((5, 12, 1), 4040, 1010),
        KnownPacking((2, 5, 6), 2112, 264, solid=True),
        KnownPacking((3, 4, 5), 31520, 3940, solid=True),
    ),
)

#: One published 4x4x4 Bedlam solution, read off layer by layer; the pieces are its normalised
#: parts, so the set is consistent with a known packing by construction.
BEDLAM_SOLUTION: dict[str, Shape] = {
    "A": Shape([(0, 2, 0), (0, 3, 0), (1, 3, 0), (2, 3, 0), (0, 3, 1)]),
    "B": Shape([(2, 1, 0), (2, 2, 0), (3, 2, 0), (3, 3, 0), (3, 3, 1)]),
    "C": Shape([(1, 2, 0), (2, 1, 1), (1, 2, 1), (2, 2, 1), (2, 2, 2)]),
    "D": Shape([(0, 1, 0), (0, 0, 1), (0, 1, 1), (0, 2, 1), (0, 1, 2)]),
    "E": Shape([(0, 0, 0), (1, 0, 0), (2, 0, 0), (1, 1, 0), (1, 1, 1)]),
    "F": Shape([(0, 2, 2), (0, 0, 3), (0, 1, 3), (1, 1, 3), (0, 2, 3)]),
    "G": Shape([(2, 1, 2), (3, 1, 2), (1, 0, 3), (2, 0, 3), (2, 1, 3)]),
    "H": Shape([(3, 1, 1), (3, 2, 1), (3, 2, 2), (3, 3, 2), (3, 2, 3)]),
    "V": Shape([(3, 0, 0), (3, 1, 0), (1, 0, 1), (2, 0, 1), (3, 0, 1)]),
    "W": Shape([(0, 0, 2), (1, 0, 2), (1, 1, 2), (1, 2, 2), (1, 2, 3)]),
    "X": Shape([(2, 3, 2), (2, 2, 3), (1, 3, 3), (2, 3, 3), (3, 3, 3)]),
    "Y": Shape([(1, 3, 1), (2, 3, 1), (0, 3, 2), (1, 3, 2), (0, 3, 3)]),
    "Z": Shape([(2, 0, 2), (3, 0, 2), (3, 0, 3), (3, 1, 3)]),
}

BEDLAM = PieceSet(
    name="bedlam",
    description="Bedlam cube: 12 pentacubes and one tetracube filling a 4x4x4 cube",
    pieces={name: placed.normalized() for name, placed in BEDLAM_SOLUTION.items()},
    packings=(KnownPacking((4, 4, 4), None, 19186),),
)

PIECESETS: dict[str, PieceSet] = {s.name: s for s in (SOMA, PENTOMINOES, BEDLAM)}


def get_pieceset(name: str) -> PieceSet:
    try:
        return PIECESETS[name.lower()]
    except KeyError:
        known = ", ".join(sorted(PIECESETS))
        raise KeyError(f"unknown piece set {name!r}; known: {known}") from None
