"""Structural checks on a packed box: isolated pieces and linear (one-piece-at-a-time) assembly.

Linear assembly follows the CHAIN generator: take pieces out of the packed box one at a time,
each by a straight translation along one of the six axes, and reverse that into an assembly
order. Unlike the original script, which only tested the first unit step, a removal here must
be free for every unit step until the piece has left the box, so each insertion is physically
possible. Removing a piece never blocks another one, so the greedy removal finds an order
exactly when one exists.
"""

from __future__ import annotations

from collections.abc import Sequence

from chaingeo.core.geometry import NEIGHBOURS, Cell, Shape
from chaingeo.core.kinematics import DIRECTIONS, OPPOSITE


def has_isolated_piece(placements: Sequence[Shape]) -> bool:
    """True when some piece shares no face with any other piece.

    In an exact packing of a box with two or more pieces this never happens (the box is
    face-connected), so the check guards hand-made or partial packings.
    """
    owner = {c: i for i, s in enumerate(placements) for c in s}
    for i, s in enumerate(placements):
        touches = any(
            owner.get((x + dx, y + dy, z + dz), i) != i
            for x, y, z in s
            for dx, dy, dz in NEIGHBOURS
        )
        if not touches:
            return True
    return False


def _free_to_leave(
    cells: Shape, me: int, owner: dict[Cell, int], box: Sequence[int], d: Cell
) -> bool:
    for x, y, z in cells:
        k = 1
        while True:
            c = (x + d[0] * k, y + d[1] * k, z + d[2] * k)
            if not all(0 <= c[i] < box[i] for i in range(3)):
                break
            if owner.get(c, me) != me:
                return False
            k += 1
    return True


def removal_sequence(
    placements: Sequence[Shape], box: Sequence[int]
) -> list[tuple[int, str]] | None:
    """Greedy disassembly: ``(piece index, direction it slides out)``, or None if stuck.

    At each step the lowest-numbered piece that can slide out (directions in the order
    ``+x -x +y -y +z -z``) leaves.
    """
    owner = {c: i for i, s in enumerate(placements) for c in s}
    remaining = list(range(len(placements)))
    out: list[tuple[int, str]] = []
    while remaining:
        for i in remaining:
            d_name = next(
                (
                    name
                    for name, d in DIRECTIONS.items()
                    if _free_to_leave(placements[i], i, owner, box, d)
                ),
                None,
            )
            if d_name is not None:
                out.append((i, d_name))
                remaining.remove(i)
                for c in placements[i]:
                    del owner[c]
                break
        else:
            return None
    return out


def assembly_order(placements: Sequence[Shape], box: Sequence[int]) -> list[tuple[int, str]] | None:
    """Linear assembly: ``(piece index, direction it slides in)`` in insertion order, or None."""
    seq = removal_sequence(placements, box)
    if seq is None:
        return None
    return [(i, OPPOSITE[d]) for i, d in reversed(seq)]
