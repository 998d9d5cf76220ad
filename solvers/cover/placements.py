"""Every placement of a piece inside a target voxel set, as flat cell-index arrays.

**Cell indexing.** A target's cells are numbered by their rank in ``target.voxels`` (sorted by
x, then y, then z). For an ``a x b x c`` box with its corner at the origin that is
``index = (x * b + y) * c + z``.

A placement is one distinct orientation (of :meth:`Shape.orientations`) times one translation
that keeps every voxel inside the target. Placements are computed once per
``(canonical shape, target)`` and cached: rotated copies of a piece share one table.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import numpy.typing as npt

from chaingeo.core.arrays import I32, Bools
from chaingeo.core.geometry import SYMMETRIES, Shape

IntArray = npt.NDArray[np.int64]


@dataclass(frozen=True, eq=False)
class TargetIndex:
    """A target voxel set with its cell numbering and a dense lookup grid."""

    target: Shape
    origin: IntArray  # min corner of the target
    dims: tuple[int, int, int]  # bounding-box extent
    grid: I32  # cell index at [x, y, z] - origin, or -1 outside the target

    @property
    def n_cells(self) -> int:
        return len(self.target)

    def index_of(self, cells: npt.ArrayLike) -> I32:
        """Cell indices of absolute voxels (``-1`` for voxels outside the target)."""
        v = np.asarray(cells, dtype=np.int64).reshape(-1, 3) - self.origin
        inside = np.all((v >= 0) & (v < np.asarray(self.dims)), axis=1)
        out = np.full(len(v), -1, dtype=np.int32)
        w = v[inside]
        out[inside] = self.grid[w[:, 0], w[:, 1], w[:, 2]]
        return out


@lru_cache(maxsize=256)
def target_index(target: Shape) -> TargetIndex:
    if len(target) == 0:
        raise ValueError("the target voxel set is empty")
    origin = target.min_corner
    dims = target.extent
    grid = np.full(dims, -1, dtype=np.int32)
    rel = target.voxels - origin
    grid[rel[:, 0], rel[:, 1], rel[:, 2]] = np.arange(len(target), dtype=np.int32)
    grid.setflags(write=False)
    return TargetIndex(target, origin, dims, grid)


def fitting_shifts(fits: Bools, vox: IntArray, layer: IntArray) -> tuple[IntArray, IntArray]:
    """Every ``(orientation, shift)`` putting each voxel ``vox[o, j]`` (orientations of ``k``
    voxels, each at the origin) on a cell where ``fits[layer[o, j]]`` holds (``fits``:
    ``(layers, *dims)``, a layer per colour), in orientation order then lexicographic shift
    order, as one ``np.argwhere`` per orientation lists them.

    The first voxel's fitting cells give each orientation's candidates; then all orientations
    advance together, one voxel at a time, on a grid padded so that a voxel past the box is a
    miss: ``k`` numpy steps on the surviving candidates instead of one slice per orientation
    and voxel (0.09 s of Python on SolidSixPieceBurrs' 25 pieces). Memory stays that of the
    candidates and of the grid (twice the box a side, one byte a cell)."""
    dims = np.asarray(fits.shape[1:], dtype=np.int64)
    n, k = vox.shape[0], vox.shape[1]
    if n == 0 or k == 0:
        return np.zeros(0, np.int64), np.zeros((0, 3), np.int64)
    pad = 2 * dims - 1
    grid = np.zeros((fits.shape[0], *pad.tolist()), dtype=bool)
    grid[:, : dims[0], : dims[1], : dims[2]] = fits
    flat = grid.reshape(-1)
    stride = np.array([pad[1] * pad[2], pad[2], 1], dtype=np.int64)
    offset = vox @ stride + layer * int(pad.prod())  # voxel j of o, in the flat padded grid
    free = [np.argwhere(f) for f in fits]  # each layer's fitting cells, lexicographic
    room = (vox.max(axis=1) < dims).all(axis=1)  # the orientation fits in the box at all
    orients, shifts = [np.zeros(0, np.int64)], [np.zeros((0, 3), np.int64)]
    for lay, cells in enumerate(free):
        mine = np.flatnonzero(room & (layer[:, 0] == lay))
        sh = cells[None, :, :] - vox[mine, 0][:, None, :]  # (orientations, cells, 3)
        o, c = np.nonzero((sh >= 0).all(axis=2))
        orients.append(mine[o])
        shifts.append(sh[o, c])
    orient, shift = np.concatenate(orients), np.concatenate(shifts).astype(np.int64)
    if len(free) > 1:  # coloured: back to orientation order across the layers
        order = np.argsort(orient, kind="stable")
        orient, shift = orient[order], shift[order]
    base = shift[:, 0] * stride[0] + shift[:, 1] * stride[1] + shift[:, 2]
    at = np.arange(len(orient))
    for j in range(1, k):
        at = at[flat[base[at] + offset[orient[at], j]]]
    return orient[at], shift[at]


@dataclass(frozen=True, eq=False)
class Placements:
    """All placements of one piece (given by its canonical form) inside one target.

    ``cells[i]`` are the sorted cell indices of placement ``i``; it is orientation
    ``orientation[i]`` (an index into ``orientations``) translated by ``offset[i]``.
    ``lookup[o, tx, ty, tz]`` inverts that: the placement of orientation ``o`` whose min corner
    is ``origin + (tx, ty, tz)``, or -1.
    """

    shape: Shape
    orientations: tuple[Shape, ...]
    cells: I32  # (n, len(shape))
    orientation: I32  # (n,)
    offset: IntArray  # (n, 3)
    lookup: I32  # (n_orientations, *dims)
    origin: IntArray  # the target's min corner: lookup translations are relative to it

    def __len__(self) -> int:
        return len(self.cells)

    def find(self, placed: Shape) -> int:
        """Index of the placement whose voxels are exactly ``placed``, or -1."""
        key = placed.normalized().cells
        for o, orient in enumerate(self.orientations):
            if orient.cells == key:
                t = placed.min_corner - self.origin
                if np.any(t < 0) or np.any(t >= np.asarray(self.lookup.shape[1:])):
                    return -1
                return int(self.lookup[o, t[0], t[1], t[2]])
        return -1


def placements(shape: Shape, target: Shape) -> Placements:
    """Every placement of ``shape`` (any rotation, any translation) inside ``target``."""
    return _placements(shape.canonical(), target)


@lru_cache(maxsize=4096)
def _placements(canon: Shape, target: Shape) -> Placements:
    idx = target_index(target)
    orients = canon.orientations()
    vox = np.stack([o.voxels for o in orients])
    fits = (idx.grid >= 0)[None]
    orient, rel = fitting_shifts(fits, vox, np.zeros(vox.shape[:2], dtype=np.int64))
    placed = vox[orient] + rel[:, None, :]
    cells = np.sort(idx.grid[placed[..., 0], placed[..., 1], placed[..., 2]], axis=1)
    lookup = np.full((len(orients), *idx.dims), -1, dtype=np.int32)
    lookup[orient, rel[:, 0], rel[:, 1], rel[:, 2]] = np.arange(len(orient), dtype=np.int32)
    result = Placements(
        shape=canon,
        orientations=orients,
        cells=cells.astype(np.int32),
        orientation=orient.astype(np.int32),
        offset=rel + idx.origin,
        lookup=lookup,
        origin=idx.origin,
    )
    for arr in (result.cells, result.orientation, result.offset, result.lookup):
        arr.setflags(write=False)
    return result


def target_symmetries(target: Shape, reflections: bool = True) -> list[tuple[IntArray, IntArray]]:
    """The lattice symmetries ``v -> M v + t`` mapping ``target`` onto itself, identity first.

    Same order as :data:`SYMMETRIES` (rotations first); for a box at the origin this is exactly
    :func:`chaingeo.core.geometry.box_symmetries`. ``reflections=False`` keeps the rotations only.
    """
    mats = SYMMETRIES if reflections else SYMMETRIES[:24]
    lo = target.min_corner
    out: list[tuple[IntArray, IntArray]] = []
    for m in mats:
        image = target.rotate(m)
        t = lo - image.min_corner
        if image.translate(t) == target:
            out.append((m, t.astype(np.int64)))
    return out


def cell_permutation(target: Shape, m: IntArray, t: IntArray) -> I32:
    """``perm[i]`` = index of the image of cell ``i`` under the symmetry ``v -> m v + t``."""
    idx = target_index(target)
    perm = idx.index_of(target.voxels @ np.asarray(m).T + np.asarray(t))
    if np.any(perm < 0):
        raise ValueError("not a symmetry of the target")
    return perm
