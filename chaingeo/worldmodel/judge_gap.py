"""Whether two parts of one colour are one piece seen round an occluder: the straight gap
between their nearest points lies mostly on other pieces (a beam behind a crossing beam shows
as two parts), not on background (a break)."""

from __future__ import annotations

from typing import Final

import numpy as np
import numpy.typing as npt

from chaingeo.core.arrays import Bools
from chaingeo.kernels.jit import njit

#: Share of the gap between two same-coloured parts that other pieces must cover for the parts
#: to count as one occluded piece.
OCCLUDED_GAP: Final = 0.6


def _boundary_points(mask: Bools, limit: int = 300) -> np.ndarray:
    edge = mask & ~(
        np.roll(mask, 1, 0) & np.roll(mask, -1, 0) & np.roll(mask, 1, 1) & np.roll(mask, -1, 1)
    )
    pts = np.argwhere(edge if edge.any() else mask)
    step = max(1, len(pts) // limit)
    return pts[::step]


def gap_covered(a: Bools, b: Bools, others: Bools) -> bool:
    """Whether the gap between ``a`` and ``b`` (the pixels within half their distance plus a
    little of both) lies mostly on other pieces (an occluder) rather than on background."""
    pa, pb = _boundary_points(a), _boundary_points(b)
    gap = float(np.sqrt(((pa[:, None, :] - pb[None, :, :]) ** 2).sum(axis=2).min()))
    if gap <= 4:
        return True
    r = int(gap) + 3
    ys, xs = np.nonzero(a | b)
    y0, y1 = max(0, int(ys.min()) - r), int(ys.max()) + r + 1
    x0, x1 = max(0, int(xs.min()) - r), int(xs.max()) + r + 1
    da, db = _distances(a[y0:y1, x0:x1], r), _distances(b[y0:y1, x0:x1], r)
    lens = (da > 0) & (db > 0) & (da + db <= int(np.ceil(gap)) + 2)
    if not lens.any():
        return False
    return float((lens & others[y0:y1, x0:x1]).sum()) >= OCCLUDED_GAP * float(lens.sum())


def _distances(mask: Bools, r: int) -> np.ndarray:
    """Chessboard distance to ``mask`` (0 on it), capped at r + 1: what growing the mask a
    pixel at a time within the picture gives (a shortest chessboard path stays within the
    box of its ends), in two passes instead of r growths."""
    h, w = mask.shape
    flat = np.ascontiguousarray(mask, dtype=np.bool_).ravel()
    return _chessboard_kernel(flat, h, w, r + 1).reshape(h, w)


@njit(cache=True)
def _chessboard_kernel(flat: Bools, h: int, w: int, cap: int) -> npt.NDArray[np.int64]:
    """Two-pass chamfer over the 8 neighbours, all steps 1: exact for the chessboard metric."""
    out = np.full(h * w, cap, dtype=np.int64)
    for i in range(h * w):
        if flat[i]:
            out[i] = 0
    for y in range(h):
        for x in range(w):
            d = out[y * w + x]
            if x > 0:
                d = min(d, out[y * w + x - 1] + 1)
            if y > 0:
                for xx in range(max(0, x - 1), min(w, x + 2)):
                    d = min(d, out[(y - 1) * w + xx] + 1)
            out[y * w + x] = d
    for y in range(h - 1, -1, -1):
        for x in range(w - 1, -1, -1):
            d = out[y * w + x]
            if x < w - 1:
                d = min(d, out[y * w + x + 1] + 1)
            if y < h - 1:
                for xx in range(max(0, x - 1), min(w, x + 2)):
                    d = min(d, out[(y + 1) * w + xx] + 1)
            out[y * w + x] = d
    return out
