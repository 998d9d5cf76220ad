"""BurrTools puzzles (cube grid) in memory: shapes with colours, problems, stored solutions.

The classes mirror what a ``.xmpuzzle`` file holds, so a file read and written back is the same
puzzle (:mod:`chaingeo.core.formats.bt_read`, :mod:`chaingeo.core.formats.bt_write`):

* a :class:`BTShape` is a voxel grid: ``#`` filled, ``+`` variable (a result cell that may stay
  empty), ``_`` empty; a filled or variable voxel may carry a colour ``1..63`` (0: none), a
  hotspot (where a placement puts the shape) and a weight;
* a :class:`BTProblem` lists its parts (:class:`BTPart`: a shape used ``min..max`` times, in
  piece groups), the result shape, the colour rules (which piece colour may sit on which result
  colour; uncoloured voxels go anywhere), an optional cap on empty variable cells, and the
  stored solutions;
* a :class:`BTPuzzle` holds the colours, the shapes and the problems.

A transform ``t < 24`` is the rotation ``ROTATIONS_BT[t]`` (applied as ``M @ v``); ``t >= 24``
is the mirror through ``x = 0`` followed by rotation ``t - 24``. A placement puts the shape's
hotspot at its position: voxel ``v`` lands on ``M @ (v - hotspot) + position``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import Final

import numpy as np

from chaingeo.core.errors import ChainGeoError
from chaingeo.core.geometry import QUARTER_TURNS, Shape

Cell = tuple[int, int, int]
RGB = tuple[int, int, int]

#: BurrTools allows at most 63 colours (colour 0 means "no colour").
MAX_COLORS: Final = 63


# BurrTools' numbering of the 24 proper rotations of the cube grid (applied as v' = M v):
# rotation 4 k + r is base k followed by r quarter turns about x, i.e. B_k @ Rx^r, with the
# bases I, Ry^3, Ry^2, Ry, Rz, Rz^3 (right-handed quarter turns).
def _bt_rotations() -> tuple[np.ndarray, ...]:
    rx, ry, rz = (QUARTER_TURNS[a] for a in "xyz")
    eye = np.eye(3, dtype=np.int64)
    bases = (eye, ry.T, ry @ ry, ry, rz, rz.T)
    out = []
    for b in bases:
        m = b
        for _ in range(4):
            frozen = np.ascontiguousarray(m)
            frozen.setflags(write=False)
            out.append(frozen)
            m = m @ rx
    return tuple(out)


ROTATIONS_BT: Final[tuple[np.ndarray, ...]] = _bt_rotations()
MIRROR_X: Final = np.diag([-1, 1, 1]).astype(np.int64)
#: All 48 transforms in BurrTools' order: 24 rotations, then the same after a mirror in x.
TRANSFORMS_BT: Final[tuple[np.ndarray, ...]] = ROTATIONS_BT + tuple(
    m @ MIRROR_X for m in ROTATIONS_BT
)


class BurrToolsError(ChainGeoError, ValueError):
    """A file that is not a readable cube-grid BurrTools puzzle: where, and why."""

    def __init__(self, source: str, where: str, reason: str) -> None:
        super().__init__(f"{source}: {where}: {reason}")
        self.source = source
        self.where = where
        self.reason = reason


@dataclass(frozen=True)
class BTShape:
    """One voxel grid of the file. ``colors`` lists the coloured voxels, sorted."""

    name: str | None
    size: tuple[int, int, int]
    filled: Shape  # '#' voxels, in the shape's own grid
    variable: Shape  # '+' voxels (may stay empty in a result)
    colors: tuple[tuple[Cell, int], ...] = ()  # (voxel, colour >= 1), sorted by voxel
    hotspot: Cell = (0, 0, 0)
    weight: int = 1

    @property
    def cells(self) -> Shape:
        """Every voxel that may be filled (``#`` and ``+``)."""
        return Shape(list(self.filled.cells) + list(self.variable.cells))

    @cached_property
    def color_map(self) -> Mapping[Cell, int]:
        return dict(self.colors)

    def color(self, cell: Cell) -> int:
        """The colour of a voxel (0: uncoloured)."""
        return self.color_map.get(cell, 0)

    @property
    def colored(self) -> bool:
        return bool(self.colors)


def colored_shape(
    name: str | None,
    filled: Shape,
    variable: Shape | None = None,
    colors: Mapping[Cell, int] | None = None,
    *,
    size: tuple[int, int, int] | None = None,
) -> BTShape:
    """A shape from voxels already in a non-negative grid (the grid is their bounding box from
    the origin unless ``size`` is given); ``colors`` maps voxels to colours (0 entries dropped)."""
    var = variable if variable is not None else Shape([])
    allv = list(filled.cells) + list(var.cells)
    if size is None:
        hi = np.max(np.asarray(allv), axis=0) + 1 if allv else np.ones(3, dtype=np.int64)
        size = (int(hi[0]), int(hi[1]), int(hi[2]))
    cols = tuple(sorted((c, int(k)) for c, k in (colors or {}).items() if k))
    return BTShape(name, size, filled, var, cols)


@dataclass(frozen=True)
class BTPart:
    """A shape of a problem, used ``min..max`` times; ``groups`` are ``(group id, count)``
    pairs (id >= 1): pieces of one group need not be taken apart from each other."""

    shape: int
    min: int
    max: int
    groups: tuple[tuple[int, int], ...] = ()


@dataclass(frozen=True)
class BTPlacement:
    shape: int
    position: tuple[int, int, int]
    transform: int

    def place(self, shape: BTShape) -> Shape:
        m = TRANSFORMS_BT[self.transform]
        return shape.cells.translate(-np.asarray(shape.hotspot)).rotate(m).translate(self.position)


@dataclass(frozen=True)
class BTSolution:
    """One stored solution: a placement per piece of the problem (None: piece unused), the
    solution's attributes, and its other elements (the separation tree, ``<separationInfo>``)
    as XML text, kept as read and not interpreted."""

    placements: tuple[BTPlacement | None, ...]
    attributes: tuple[tuple[str, str], ...] = ()
    extra: tuple[str, ...] = ()


@dataclass(frozen=True)
class BTProblem:
    name: str | None
    parts: tuple[BTPart, ...]
    result: int
    solutions: tuple[BTSolution, ...] = ()
    recorded: Mapping[str, int] = field(default_factory=dict)  # assemblies, solutions, time
    color_pairs: tuple[tuple[int, int], ...] = ()  # (piece colour, result colour), both >= 1
    max_holes: int | None = None  # at most this many variable result cells left empty
    state: int = 0  # BurrTools' solve state (0 unsolved, 1 solving, 2 solved)

    @property
    def pieces(self) -> tuple[tuple[int, int, int], ...]:
        """``(shape index, min count, max count)`` of each part."""
        return tuple((p.shape, p.min, p.max) for p in self.parts)

    @property
    def piece_slots(self) -> tuple[int, ...]:
        """The shape of each piece slot of a stored assembly (``max`` slots per part)."""
        return tuple(p.shape for p in self.parts for _ in range(p.max))

    def placement_allowed(self, piece_color: int, result_color: int, n_colors: int) -> bool:
        """BurrTools' rule: anything goes without colours or on an uncoloured voxel; otherwise
        the pair must be listed."""
        if n_colors == 0 or piece_color == 0 or result_color == 0:
            return True
        return (piece_color, result_color) in self.color_pairs


@dataclass(frozen=True)
class BTPuzzle:
    shapes: tuple[BTShape, ...]
    problems: tuple[BTProblem, ...]
    comment: str = ""
    colors: tuple[RGB, ...] = ()
    comment_popup: bool = False

    def problem(self, index: int) -> BTProblem:
        if not 0 <= index < len(self.problems):
            raise IndexError(f"problem {index} does not exist; the file has {len(self.problems)}")
        return self.problems[index]

    def assemblies(self, index: int) -> list[dict[int, Shape]]:
        """The stored assemblies of problem ``index``: piece slot -> placed voxels."""
        prob = self.problem(index)
        out = []
        for sol in prob.solutions:
            out.append(
                {
                    slot: p.place(self.shapes[p.shape])
                    for slot, p in enumerate(sol.placements)
                    if p is not None
                }
            )
        return out
