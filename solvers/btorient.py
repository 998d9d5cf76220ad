"""Which of an assembly's symmetric images BurrTools disassembles.

BurrTools' disassembler lists moves along ``+x`` before ``-x`` and piece by piece, so the level
it prints can depend on how the assembly lies in the result. Its assembler reports one image
per class: the one no symmetry of the result makes smaller (``assembly.cpp``,
``smallerRotationExists`` and ``compare``), comparing the pieces' placements ``(transformation,
x, y, z)`` (``placement_c::operator<``), the symmetry breaker (the *pivot*, ``assembler_0.cpp``:
the first shape with the fewest symmetries shared with the result) first, then every piece in
order; copies of one shape are sorted by placement (``assembly_c::sort``). A placement's
transformation is the first of BurrTools' 24 rotations that gives the placed orientation
(``ROTATIONS_BT``) and its position is where the shape's origin lands (burrTxt puts every
hotspot at the origin, ``initHotspot``).

Mirror images take part only when every piece is its own mirror image up to rotation (pieces
swapping with a mirror partner are not modelled: their classes keep the image found first).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from chaingeo.core.formats.bt_model import ROTATIONS_BT
from chaingeo.core.geometry import SYMMETRIES, Shape

Key = tuple[int, int, int, int]
#: A symmetry of the result: ``cell -> matrix @ cell + shift``.
Symmetry = tuple[np.ndarray, np.ndarray]


def _normal(cells: np.ndarray) -> bytes:
    c = cells - cells.min(axis=0)
    return bytes(c[np.lexsort(c.T[::-1])].tobytes())


def placement(grid: np.ndarray, placed: np.ndarray) -> Key | None:
    """BurrTools' placement ``(transformation, x, y, z)`` of a shape (voxels ``grid`` in its own
    grid) whose voxels lie at ``placed``; None when no rotation gives that orientation."""
    want = _normal(placed)
    for t, m in enumerate(ROTATIONS_BT):
        rot = grid @ m.T
        if _normal(rot) == want:
            pos = placed.min(axis=0) - rot.min(axis=0)
            return (t, int(pos[0]), int(pos[1]), int(pos[2]))
    return None


def self_rotations(cells: np.ndarray) -> int:
    """How many of the 48 symmetries map the voxels onto themselves (up to translation)."""
    want = _normal(cells)
    return sum(_normal(cells @ m.T) == want for m in SYMMETRIES)


def symmetries_of(cells: np.ndarray) -> list[Symmetry]:
    """The symmetries of a voxel set (every matrix of SYMMETRIES mapping it onto itself)."""
    base = cells.min(axis=0)
    want = _normal(cells)
    out = []
    for m in SYMMETRIES:
        img = cells @ m.T
        if _normal(img) == want:
            out.append((np.asarray(m), base - img.min(axis=0)))
    return out


def bt_image(
    placed: Mapping[str, Shape],
    grids: Mapping[str, np.ndarray],
    parts: Sequence[Sequence[str]],
    symmetries: Sequence[Symmetry],
    result: np.ndarray | None = None,
) -> tuple[dict[str, Shape], np.ndarray]:
    """The image of the assembly ``placed`` that BurrTools disassembles, pieces in its order.

    ``grids``: each piece's voxels in its shape's own grid; ``parts``: the pieces of each part
    of the problem in order (copies of a shape together); ``symmetries``: the result's (proper
    and improper; improper ones are used only when every piece is its own mirror image);
    ``result``: the result's cells, for the pivot (default: the union of the pieces). Returns
    the image and the symmetry's matrix (the identity when the assembly stays as it is)."""
    names = [n for p in parts for n in p]
    eye = np.eye(3, dtype=np.int64)
    if len(names) < 2 or len(symmetries) < 2:
        return {n: placed[n] for n in names}, eye
    achiral = all(
        _normal(grids[n] * np.array([-1, 1, 1])) in {_normal(grids[n] @ m.T) for m in ROTATIONS_BT}
        for n in names
    )
    cells = np.concatenate([placed[n].voxels for n in names]) if result is None else result
    res_syms = symmetries_of(cells)
    counts = []
    for p in parts:
        g = grids[p[0]]
        shared = sum(_normal(g @ m.T) == _normal(g) for m, _ in res_syms)
        counts.append(shared)
    pivot_part = int(np.argmin(counts))
    pivot = sum(len(p) for p in parts[:pivot_part]) if len(parts[pivot_part]) == 1 else -1
    best: tuple[list[Key], dict[str, Shape], np.ndarray] | None = None
    for m, shift in symmetries:
        if round(float(np.linalg.det(m))) < 0 and not achiral:
            continue
        image: dict[str, Shape] = {}
        keys: list[Key] = []
        ok = True
        for part in parts:
            got = []
            for n in part:
                vox = placed[n].voxels @ np.asarray(m).T + shift
                key = placement(grids[n], vox)
                if key is None:
                    ok = False
                    break
                got.append((key, vox))
            if not ok:
                break
            got.sort(key=lambda kv: kv[0])
            for n, (key, vox) in zip(part, got, strict=True):
                image[n] = Shape(vox)
                keys.append(key)
        if not ok:
            continue
        order = keys if pivot < 0 else [keys[pivot], *keys[:pivot], *keys[pivot + 1 :]]
        if best is None or order < best[0]:
            best = (order, image, np.asarray(m))
    if best is None:
        return {n: placed[n] for n in names}, eye
    return best[1], best[2]
