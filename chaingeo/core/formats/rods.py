"""Round rods in imported models: cells that are a cylinder of diameter one, not a cube.

Some real locks turn on a round neck: the three-stick Lu Ban lock among CHAIN's models has a
one-cell rod with a circular cross-section where its stick crosses the other two, so that stick
can spin in its square hole. The lattice import keeps that cell as a full cube (a disc fills
79% of the square, and every one of the 27 sub-samples of the inside test lies within it), and
a square rod cannot turn in a square hole: its corners reach sqrt(2)/2 from the axis, the hole's
walls 1/2. So the importer also records which cells are round rods
(:attr:`chaingeo.core.level.Piece.rods`), and a turn about such a rod's own axis line lets it
spin in place (:meth:`chaingeo.core.kinematics.Assembly.spinning`).

A cell of a part is a round rod along axis ``a`` when, at three heights along ``a``, the four
points 0.42 units from its centre towards its faces are inside the part's mesh and the four
points 0.08 units from each of its edges along ``a`` (0.59 from the centre) are outside: a disc
of radius 1/2 holds the first and not the second; a square holds both. Only cells whose four
neighbours across ``a`` belong to no other cell of the part are tested (a rod stands alone in its
cross-section).
"""

from __future__ import annotations

import numpy as np

from chaingeo.core.formats.mesh_lattice import (
    LatticeFit,
    PartMesh,
    Planes,
    axis_map,
    winding_numbers,
)
from chaingeo.core.geometry import Cell, Shape

#: Offsets (in units, from the cell's low corner) of the samples across the axis.
_FACE = ((0.08, 0.5), (0.92, 0.5), (0.5, 0.08), (0.5, 0.92))
_EDGE = ((0.08, 0.08), (0.08, 0.92), (0.92, 0.08), (0.92, 0.92))
_ALONG = (0.2, 0.5, 0.8)


def round_rods(part: PartMesh, planes: Planes, fit: LatticeFit, cells: Shape) -> dict[Cell, int]:
    """The cells of ``cells`` (the part's voxels, global lattice indices as
    :func:`chaingeo.core.formats.mesh_lattice.voxelize` gives them) that are round rods, with
    their axis (0, 1, 2)."""
    maps = []
    for a in range(3):
        start = fit.origin[a] + fit.phase[part.name][a] * fit.unit
        pos, w = planes.significant(a)
        maps.append(axis_map(pos, w, fit.unit, start))
    own = cells.cell_set
    tests: list[tuple[Cell, int]] = []
    for c in cells:
        for a in range(3):
            u, v = (a + 1) % 3, (a + 2) % 3
            lonely = True
            for b, d in ((u, 1), (u, -1), (v, 1), (v, -1)):
                n = list(c)
                n[b] += d
                if (n[0], n[1], n[2]) in own:
                    lonely = False
            if lonely:
                tests.append((c, a))
    if not tests:
        return {}
    points: list[list[float]] = []
    for c, a in tests:
        u, v = (a + 1) % 3, (a + 2) % 3
        for lateral in (*_FACE, *_EDGE):
            for along in _ALONG:
                p = [float(c[0]), float(c[1]), float(c[2])]
                p[a] += along
                p[u] += lateral[0]
                p[v] += lateral[1]
                points.append(p)
    t = np.asarray(points, dtype=np.float64)
    world = np.stack([maps[a](t[:, a]) for a in range(3)], axis=1)
    inside = (np.abs(winding_numbers(part, world)) > 0.5).reshape(len(tests), 2, 4 * 3)
    out: dict[Cell, int] = {}
    for (c, a), (faces, edges) in zip(tests, inside, strict=True):
        if faces.all() and not edges.any():
            out[c] = a
    return out
