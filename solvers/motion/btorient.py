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
from functools import lru_cache

import numpy as np

from chaingeo.core.formats.bt_model import TRANSFORMS_BT
from chaingeo.core.geometry import SYMMETRIES, Shape

Key = tuple[int, int, int, int]
#: A symmetry of the result: ``cell -> matrix @ cell + shift``.
Symmetry = tuple[np.ndarray, np.ndarray]


def _normal(cells: np.ndarray) -> bytes:
    c = cells - cells.min(axis=0)
    return bytes(c[np.lexsort(c.T[::-1])].tobytes())


def _normals(stack: np.ndarray) -> list[bytes]:
    """:func:`_normal` of each voxel set of a stack ``(n, k, 3)`` (distinct voxels), in one
    sort: the lookups of a problem's shapes under 48 matrices each cost 0.02 s one at a time."""
    c = stack - stack.min(axis=1, keepdims=True)
    base = int(c.max()) + 1 if c.size else 1
    order = np.argsort((c[..., 0] * base + c[..., 1]) * base + c[..., 2], axis=1)
    rows = np.take_along_axis(c, order[..., None], axis=1).astype(np.int64)
    return [bytes(r.tobytes()) for r in rows]


def _images(mats: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """``cells @ m.T`` for every matrix of a stack: ``(len(mats), len(cells), 3)``."""
    out: np.ndarray = np.einsum("mij,kj->mki", mats, np.asarray(cells, dtype=np.int64))
    return out


_SYMMETRY_STACK = np.asarray(SYMMETRIES, dtype=np.int64).reshape(-1, 3, 3)


def symmetries_of(cells: np.ndarray) -> list[Symmetry]:
    """The symmetries of a voxel set (every matrix of SYMMETRIES mapping it onto itself), read
    only. Cached by the set: every assembly of a problem asks for its result's, twice."""
    return list(_symmetries(_set_key(cells)))


def _set_key(cells: np.ndarray) -> bytes:
    """The voxels in sorted order, as bytes (what the symmetries depend on)."""
    rows = np.asarray(cells, dtype=np.int64).reshape(-1, 3)
    return bytes(rows[np.lexsort(rows.T[::-1])].tobytes())


@lru_cache(maxsize=4096)
def _shared(grid: bytes, result: bytes) -> int:
    """How many of the result's symmetries map the piece's voxels ``grid`` onto themselves
    (up to translation)."""
    found = _symmetries(result)
    if not found:
        return 0
    g = np.frombuffer(grid, dtype=np.int64).reshape(-1, 3)
    mats = np.stack([m for m, _ in found])
    return _normals(_images(mats, g)).count(_normal(g))


@lru_cache(maxsize=256)
def _symmetries(cells: bytes) -> tuple[Symmetry, ...]:
    rows = np.frombuffer(cells, dtype=np.int64).reshape(-1, 3)
    base = rows.min(axis=0)
    want = _normal(rows)
    imgs = _images(_SYMMETRY_STACK, rows)
    found = [
        (np.asarray(m, dtype=np.int64), base - img.min(axis=0))
        for m, img, key in zip(SYMMETRIES, imgs, _normals(imgs), strict=True)
        if key == want
    ]
    for m, shift in found:
        m.setflags(write=False)
        shift.setflags(write=False)
    return tuple(found)


_MATS = [np.asarray(m, dtype=np.int64) for m in TRANSFORMS_BT]
_MAT_STACK = np.stack(_MATS)
_INDEX = {m.tobytes(): i for i, m in enumerate(_MATS)}


@lru_cache(maxsize=64)
def _compose(matrix: bytes) -> list[int]:
    """Per rotation ``t``: the index among the 48 transforms of ``matrix @ ROTATIONS_BT[t]``."""
    m = np.frombuffer(matrix, dtype=np.int64).reshape(3, 3)
    return [_INDEX[(m @ _MATS[t]).tobytes()] for t in range(24)]


@lru_cache(maxsize=4096)
def _piece_tables(
    grid: bytes, size: int
) -> tuple[dict[bytes, tuple[int, np.ndarray]], list[tuple[int, np.ndarray]]]:
    """A shape's tables (voxels ``grid`` in its own grid, ``size`` of them): its normal form per
    rotation -> (the first rotation giving it, that rotation's min corner); and per transform
    A of the 48, that first rotation (-1: none, A mirrors a chiral shape) and the shift from
    A's min corner to the rotation's. Cached: a problem's shapes recur in every analysis."""
    imgs = _images(_MAT_STACK, np.frombuffer(grid, dtype=np.int64).reshape(size, 3))
    lows = imgs.min(axis=1)
    keys = _normals(imgs)
    first: dict[bytes, tuple[int, np.ndarray]] = {}
    for t in range(24):
        first.setdefault(keys[t], (t, lows[t]))
    table = []
    for key, low in zip(keys, lows, strict=True):
        hit = first.get(key)
        if hit is None:
            table.append((-1, np.zeros(3, dtype=np.int64)))
        else:
            table.append((hit[0], low - hit[1]))
    return first, table


class BTImage:
    """Chooses BurrTools' image of assemblies of one problem (the shapes, parts and result
    symmetries fixed; tables built once, about 1 ms an assembly).

    ``grids``: each piece's voxels in its shape's own grid (every piece that may occur);
    ``symmetries``: the result's (proper and improper; improper ones are used only when every
    piece is its own mirror image); ``result``: the result's cells (for the pivot)."""

    def __init__(
        self,
        grids: Mapping[str, np.ndarray],
        symmetries: Sequence[Symmetry],
        result: np.ndarray,
    ) -> None:
        names = list(grids)
        self.find: dict[str, dict[bytes, tuple[int, np.ndarray]]] = {}
        self.norm: dict[str, list[tuple[int, np.ndarray]]] = {}
        for n in names:
            g = np.ascontiguousarray(grids[n], dtype=np.int64)
            self.find[n], self.norm[n] = _piece_tables(g.tobytes(), g.shape[0])
        achiral = all(t >= 0 for n in names for t, _ in self.norm[n])
        proper = [s for s in symmetries if round(float(np.linalg.det(s[0]))) > 0]
        self.symmetries = list(symmetries) if achiral else proper
        self.compose = [
            _compose(np.ascontiguousarray(m, dtype=np.int64).tobytes()) for m, _ in self.symmetries
        ]
        # Symmetries a piece shares with the result (the pivot has fewest).
        whole = _set_key(result)
        self.shared: dict[str, int] = {}
        for n in names:
            g = np.ascontiguousarray(grids[n], dtype=np.int64)
            self.shared[n] = _shared(g.tobytes(), whole)

    def __call__(
        self, placed: Mapping[str, Shape], parts: Sequence[Sequence[str]]
    ) -> tuple[dict[str, Shape], np.ndarray]:
        """The image of ``placed`` BurrTools disassembles, pieces in its order, and the
        symmetry's matrix (the identity when the assembly stays as it is). ``parts``: the
        pieces of each part of the problem in order (copies of a shape together)."""
        names = [n for p in parts for n in p]
        eye = np.eye(3, dtype=np.int64)
        if len(names) < 2 or len(self.symmetries) < 2:
            return {n: placed[n] for n in names}, eye
        counts = [self.shared[p[0]] for p in parts]
        at = int(np.argmin(counts))
        pivot = sum(len(p) for p in parts[:at]) if all(len(p) == 1 for p in parts) else -1
        t0 = []
        pos0 = np.empty((len(names), 3), dtype=np.int64)
        for i, n in enumerate(names):
            vox = placed[n].voxels
            hit = self.find[n].get(_normal(vox))
            if hit is None:
                raise ValueError(f"piece {n} is not its shape (rotated)")
            t0.append(hit[0])
            pos0[i] = vox.min(axis=0) - hit[1]
        best: tuple[list[Key], int] | None = None
        for g, (m, shift) in enumerate(self.symmetries):
            pos = pos0 @ np.asarray(m).T + shift
            keys: list[Key] = []
            i = 0
            for part in parts:
                got = []
                for n in part:
                    t, off = self.norm[n][self.compose[g][t0[i]]]
                    p = pos[i] + off
                    got.append((t, int(p[0]), int(p[1]), int(p[2])))
                    i += 1
                keys.extend(sorted(got))
            if pivot >= 0:
                keys = [keys[pivot], *keys[:pivot], *keys[pivot + 1 :]]
            if best is None or keys < best[0]:
                best = (keys, g)
        assert best is not None
        m, shift = self.symmetries[best[1]]
        image: dict[str, Shape] = {}
        for part in parts:
            moved = [placed[n].voxels @ np.asarray(m).T + shift for n in part]
            ranked = sorted(moved, key=lambda v: self.placement_key(part[0], v))
            for n, v in zip(part, ranked, strict=True):
                image[n] = Shape(v)
        return image, np.asarray(m, dtype=np.int64)

    def placement_keys(self, name: str, stack: np.ndarray) -> np.ndarray:
        """:meth:`placement_key` of each voxel set of a stack ``(n, k, 3)``, as rows
        ``(t, x, y, z)`` (one sort for all: a type's orientations)."""
        found = self.find[name]
        hits = [found[key] for key in _normals(stack)]
        low = np.array([h[1] for h in hits], dtype=np.int64).reshape(-1, 3)
        rot = np.array([h[0] for h in hits], dtype=np.int64).reshape(-1, 1)
        return np.hstack([rot, stack.min(axis=1) - low])

    def placement_key(self, name: str, vox: np.ndarray) -> Key:
        """BurrTools' placement of a piece: its first rotation giving the voxels, and where the
        shape's origin lands."""
        t, low = self.find[name][_normal(vox)]
        p = vox.min(axis=0) - low
        return (t, int(p[0]), int(p[1]), int(p[2]))
