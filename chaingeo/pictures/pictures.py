"""Pictures of a whole level: the packed assembly, the pieces handed out, and an exploded view.

The generator takes :func:`level_pictures` as a parameter (it sits below the environments and
does not import the renderer); it draws with :mod:`chaingeo.pictures.scene` (deterministic PNG
bytes, no GUI), so worker processes can call it.
"""

from __future__ import annotations

from typing import Final

import numpy as np

from chaingeo.core.geometry import Cell, Shape
from chaingeo.core.kinematics import DIRECTIONS, Move, disassembly_of_assembly_plan
from chaingeo.core.level import Level, PuzzleSolution
from chaingeo.pictures.raster import ColorLike
from chaingeo.pictures.scene import (
    DEFAULT_SIZE,
    render_level_tray,
    render_solution_views,
    render_views,
    solution_pieces,
)

PictureSet = dict[str, bytes]
#: The solved level is drawn from this view.
ASSEMBLY_VIEW: Final = "iso"
EXPLODED_TITLE: Final = "EXPLODED: the solved level, pieces pushed apart"


def level_pictures(level: Level) -> PictureSet:
    """``{"assembly": png, "pieces": png}``: the level solved, and its pieces as handed out."""
    return {
        "assembly": render_solution_views(level, views=(ASSEMBLY_VIEW,))[ASSEMBLY_VIEW],
        "pieces": render_level_tray(level),
    }


def explode_directions(level: Level) -> dict[str, tuple[Cell, int]]:
    """Per piece, the unit axis vector it is pushed along in the exploded view and how many
    steps far.

    A puzzle piece goes the way of its first slide in the level's optimal plan taken as a
    disassembly (an assembly plan is reversed); pieces going the same way are spread out, the
    first to leave the farthest. A piece the plan never slides (the last one left), and every
    stacking piece, goes radially: along the axis on which its centre lies farthest from the
    solution's centre (ties: x, then y, then z; dead centre: up), one step.
    """
    pieces = solution_pieces(level)
    first: dict[str, tuple[Cell, int]] = {}
    if isinstance(level.solution, PuzzleSolution):
        moves = list(level.solution.moves)
        plan = moves if level.goal == "disassemble" else disassembly_of_assembly_plan(moves)
        for i, m in enumerate(plan):
            if isinstance(m, Move):
                for n in m.pieces:
                    first.setdefault(n, (DIRECTIONS[m.direction], i))
    every = np.concatenate([s.voxels for s, _ in pieces.values()]).astype(np.float64)
    centre = every.mean(axis=0)
    for name in sorted(pieces):
        if name in first:
            continue
        d = pieces[name][0].voxels.mean(axis=0) - centre
        axis = int(np.argmax(np.abs(d)))
        v = [0, 0, 0]
        if abs(float(d[axis])) < 1e-9:
            v[2] = 1
        else:
            v[axis] = 1 if d[axis] > 0 else -1
        first[name] = ((v[0], v[1], v[2]), len(level.pieces) + 1)
    out: dict[str, tuple[Cell, int]] = {}
    for name, (d, when) in first.items():
        later = {w for e, w in first.values() if e == d and w > when}
        out[name] = (d, 1 + len(later))
    return out


def exploded_pieces(level: Level) -> dict[str, tuple[Shape, ColorLike]]:
    """The solved level with every piece moved ``k * s`` cells along its direction
    (:func:`explode_directions` gives both), ``s`` the least whole number, from half the largest
    extent up, at which no two pieces share a cell (moves stay on the lattice, so the picture's
    hidden faces stay exact)."""
    pieces = solution_pieces(level)
    dirs = explode_directions(level)
    extent = max(max(s.extent) for s, _ in pieces.values())
    step = max(1, (extent + 1) // 2)
    while True:
        moved: dict[str, tuple[Shape, ColorLike]] = {}
        for n, (shape, color) in pieces.items():
            d, k = dirs[n]
            moved[n] = (shape.translate([step * k * c for c in d]), color)
        cells = [c for s, _ in moved.values() for c in s.cells]
        if len(set(cells)) == len(cells):
            return moved
        step += 1


def render_exploded(level: Level, size: int = DEFAULT_SIZE) -> bytes:
    """PNG of the exploded view (3D view from the iso corner)."""
    return render_views(exploded_pieces(level), None, ("iso",), size, EXPLODED_TITLE)["iso"]
