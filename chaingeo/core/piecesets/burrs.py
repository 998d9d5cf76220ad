"""The six-piece burr family: 2x2x6 sticks notched in the middle, and the Solid Knot they fill.

A stick lies along x (``x = 0..5``, ``y, z = 0..1``). Twelve of its cubes may be cut away: the
middle four units of the top layer (``x = 1..4``, ``z = 1``, both ``y``) and the middle two
units of the bottom layer (``x = 2..3``, ``z = 0``, both ``y``); every other cube sits where no
other stick can reach in an assembled six-piece burr. A piece is named by the 12-bit ``code`` of
the cubes it lacks (bit ``i`` = :data:`REMOVABLE` ``[i]``). Up to rotation the connected codes
give Cutler's 837 distinct pieces.

*Notchable* pieces are those a saw can make: the removed cubes are a union of full-width unit
notches (:data:`NOTCHES`); there are 59 (Cutler). Six sticks in the standard arrangement fill
the *Solid Knot* (104 cubes) when no cube is left empty; :data:`SOLID_BURR_CODES` lists the
25 notchable pieces that occur in such solid assemblies (the burr catalogue; with 0..6 copies
each they make 1063 assemblies, 314 of which come apart: Cutler's solid six-piece burrs).
"""

from __future__ import annotations

from functools import cache
from typing import Final

from chaingeo.core.geometry import Cell, Shape

#: The twelve cubes of a stick that a notch may remove, in bit order.
REMOVABLE: Final[tuple[Cell, ...]] = tuple(
    [(x, y, 1) for x in range(1, 5) for y in range(2)]
    + [(x, y, 0) for x in (2, 3) for y in range(2)]
)
_STICK: Final[tuple[Cell, ...]] = tuple(
    (x, y, z) for x in range(6) for y in range(2) for z in range(2)
)


def burr_piece(code: int) -> Shape:
    """The stick with the cubes of ``code`` (12 bits) removed, lying along x."""
    if not 0 <= code < 1 << len(REMOVABLE):
        raise ValueError(f"a burr piece code has 12 bits, got {code}")
    gone = {REMOVABLE[i] for i in range(len(REMOVABLE)) if code >> i & 1}
    return Shape([c for c in _STICK if c not in gone])


@cache
def six_piece_family() -> dict[int, Shape]:
    """The distinct connected pieces (up to rotation), each under its smallest code."""
    seen: dict[Shape, int] = {}
    for code in range(1 << len(REMOVABLE)):
        piece = burr_piece(code)
        if piece.is_connected():
            seen.setdefault(piece.canonical(), code)
    return {code: burr_piece(code) for code in sorted(seen.values())}


def _notches() -> tuple[frozenset[Cell], ...]:
    """Unit notches: the two cubes at one x across the full width of one face of the stick
    (top at x = 1..4; bottom and both sides at x = 2..3, where cubes may go at all)."""
    out = [frozenset({(x, 0, 1), (x, 1, 1)}) for x in range(1, 5)]
    for x in (2, 3):
        out += [
            frozenset({(x, 0, 0), (x, 1, 0)}),
            frozenset({(x, 0, 0), (x, 0, 1)}),
            frozenset({(x, 1, 0), (x, 1, 1)}),
        ]
    return tuple(out)


NOTCHES: Final[tuple[frozenset[Cell], ...]] = _notches()


@cache
def notchable_family() -> dict[int, Shape]:
    """Pieces a saw can make: the removed cubes are a union of :data:`NOTCHES` (Cutler's
    notchable pieces; 59 distinct up to rotation), each under its smallest code."""
    bit = {c: i for i, c in enumerate(REMOVABLE)}
    codes: set[int] = set()
    for choice in range(1 << len(NOTCHES)):
        cells = {c for k, n in enumerate(NOTCHES) if choice >> k & 1 for c in n}
        codes.add(sum(1 << bit[c] for c in cells))
    seen: dict[Shape, int] = {}
    for code in sorted(codes):
        piece = burr_piece(code)
        if piece.is_connected():
            seen.setdefault(piece.canonical(), code)
    return {code: burr_piece(code) for code in sorted(seen.values())}


#: The six stick slots of the assembled burr: (axis, corner) of each 2x2x6 box in a 6x6x6 cube.
SLOTS: Final[tuple[tuple[int, Cell], ...]] = (
    (0, (0, 2, 1)),
    (0, (0, 2, 3)),
    (1, (1, 0, 2)),
    (1, (3, 0, 2)),
    (2, (2, 1, 0)),
    (2, (2, 3, 0)),
)


def slot_cells(axis: int, corner: Cell) -> Shape:
    """The 2x2x6 box of one slot: long along ``axis``, starting at ``corner``."""
    size = [2, 2, 2]
    size[axis] = 6
    cx, cy, cz = corner
    return Shape(
        [
            (cx + i, cy + j, cz + k)
            for i in range(size[0])
            for j in range(size[1])
            for k in range(size[2])
        ]
    )


def solid_knot() -> Shape:
    """The union of the six slots: the shape a solid six-piece burr fills (104 cubes)."""
    cells: set[Cell] = set()
    for axis, corner in SLOTS:
        cells |= slot_cells(axis, corner).cell_set
    return Shape(sorted(cells))


#: Codes (see :func:`burr_piece`) of the 25 notchable pieces that occur in a solid six-piece
#: burr: every assembly of the notchable family (each piece 0..6 times) into the Solid Knot uses
#: only these. Computed by :func:`chaingeo.solvers.assembly.assemble.solid_burr_codes` (a slow test
#: recomputes it).
SOLID_BURR_CODES: Final[tuple[int, ...]] = (
    0, 3, 12, 15, 51, 60, 63, 195, 207, 255, 316, 572, 1303,
    1311, 1335, 1340, 1343, 1492, 1495, 1500, 1503, 1524, 1527, 1532, 1535,
)  # fmt: skip


def solid_burr_pieces() -> dict[str, Shape]:
    """The catalogue: ``{"b0000": shape, ...}`` named by hex code."""
    return {f"b{code:04x}": burr_piece(code) for code in SOLID_BURR_CODES}
