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

from chaingeo.core.formats.bt_model import TRANSFORMS_BT
from chaingeo.core.geometry import SYMMETRIES, Shape

Key = tuple[int, int, int, int]
#: A symmetry of the result: ``cell -> matrix @ cell + shift``.
Symmetry = tuple[np.ndarray, np.ndarray]


def _normal(cells: np.ndarray) -> bytes:
    c = cells - cells.min(axis=0)
    return bytes(c[np.lexsort(c.T[::-1])].tobytes())


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
        mats = [np.asarray(m, dtype=np.int64) for m in TRANSFORMS_BT]
        index = {m.tobytes(): i for i, m in enumerate(mats)}
        achiral = True
        # Per piece: its voxels' normal form per rotation -> (rotation, min corner), and per
        # transform A (of the 48): the first rotation giving A's orientation and the shift
        # from A's min corner to that rotation's.
        self.find: dict[str, dict[bytes, tuple[int, np.ndarray]]] = {}
        self.norm: dict[str, list[tuple[int, np.ndarray]]] = {}
        done: dict[bytes, str] = {}  # copies of a shape share one grid: tables built once
        for n in names:
            g = np.asarray(grids[n], dtype=np.int64)
            same = done.setdefault(g.tobytes(), n)
            if same != n:
                self.find[n], self.norm[n] = self.find[same], self.norm[same]
                continue
            first: dict[bytes, tuple[int, np.ndarray]] = {}
            for t in range(24):
                rot = g @ mats[t].T
                first.setdefault(_normal(rot), (t, rot.min(axis=0)))
            table = []
            for m in mats:
                img = g @ m.T
                hit = first.get(_normal(img))
                if hit is None:
                    table.append((-1, np.zeros(3, dtype=np.int64)))
                    achiral = False
                else:
                    table.append((hit[0], img.min(axis=0) - hit[1]))
            self.find[n], self.norm[n] = first, table
        proper = [s for s in symmetries if round(float(np.linalg.det(s[0]))) > 0]
        self.symmetries = list(symmetries) if achiral else proper
        self.compose = [
            [index[(np.asarray(m, dtype=np.int64) @ mats[t]).tobytes()] for t in range(24)]
            for m, _ in self.symmetries
        ]
        res_syms = symmetries_of(result)
        self.shared: dict[str, int] = {}  # symmetries a piece shares with the result: the pivot has fewest
        for n in names:
            same = done[np.asarray(grids[n], dtype=np.int64).tobytes()]
            if same not in self.shared:
                g = np.asarray(grids[same], dtype=np.int64)
                self.shared[same] = sum(_normal(g @ m.T) == _normal(g) for m, _ in res_syms)
            self.shared[n] = self.shared[same]

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
            ranked = sorted(moved, key=lambda v: self._key(part[0], v))
            for n, v in zip(part, ranked, strict=True):
                image[n] = Shape(v)
        return image, np.asarray(m, dtype=np.int64)

    def _key(self, name: str, vox: np.ndarray) -> Key:
        t, low = self.find[name][_normal(vox)]
        p = vox.min(axis=0) - low
        return (t, int(p[0]), int(p[1]), int(p[2]))
