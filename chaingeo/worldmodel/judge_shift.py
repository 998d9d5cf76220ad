"""A colour's translation between two frames, read from its pixels alone: the shift that lays
one frame's mask best on the next (FFT cross-correlation), and how well it fits. A rigid piece
keeps its silhouette while it moves, so a good fit is its displacement; the motion, identity
and class-unifying readings all follow pieces by it."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import numpy as np

from chaingeo.core.arrays import Bools

#: Overlap (pixels) a shift's each pixel of distance from the step before costs.
INERTIA: Final = 0.5
#: Least share of the smaller silhouette that the best translation must lay on the other.
FIT: Final = 0.7

Shift = tuple[int, int]


@dataclass(frozen=True)
class MaskShift:
    """A colour's best translation from one frame to the next and how well it fits (share
    of the smaller silhouette laid on the other); fit 0 when either frame lacks the colour."""

    dy: int
    dx: int
    fit: float

    @property
    def length(self) -> float:
        return float(np.hypot(self.dy, self.dx))


NONE: Final = MaskShift(0, 0, 0.0)


def best_shift(a: Bools, b: Bools, prior: Shift = (0, 0)) -> MaskShift:
    """The translation laying ``a`` best on ``b``, by FFT cross-correlation on the box holding
    both; each pixel of distance from ``prior`` (the step before: pieces keep their motion)
    costs INERTIA pixels of overlap, which decides between shifts a piece partly hidden as it
    moves fits equally well."""
    na, nb = int(a.sum()), int(b.sum())
    if na == 0 or nb == 0:
        return NONE
    ys, xs = np.nonzero(a | b)
    y0, y1, x0, x1 = int(ys.min()), int(ys.max()) + 1, int(xs.min()), int(xs.max()) + 1
    ca = a[y0:y1, x0:x1].astype(np.float64)
    cb = b[y0:y1, x0:x1].astype(np.float64)
    h, w = ca.shape
    size = (2 * h, 2 * w)
    corr = np.fft.irfft2(np.conj(np.fft.rfft2(ca, size)) * np.fft.rfft2(cb, size), size)
    dy = np.arange(2 * h)
    dy = np.where(dy >= h, dy - 2 * h, dy)
    dx = np.arange(2 * w)
    dx = np.where(dx >= w, dx - 2 * w, dx)
    dist = np.hypot(dy[:, None] - prior[0], dx[None, :] - prior[1])
    score = np.round(corr) - INERTIA * dist
    i = int(np.argmax(score))
    y, x = divmod(i, 2 * w)
    return MaskShift(int(dy[y]), int(dx[x]), float(np.round(corr[y, x])) / min(na, nb))


def moved(mask: Bools, dy: int, dx: int) -> Bools:
    """``mask`` translated by (dy, dx), what leaves the picture dropped."""
    h, w = mask.shape
    out = np.zeros_like(mask)
    if abs(dy) >= h or abs(dx) >= w:
        return out
    src = mask[max(0, -dy) : h - max(0, dy), max(0, -dx) : w - max(0, dx)]
    out[max(0, dy) : max(0, dy) + src.shape[0], max(0, dx) : max(0, dx) + src.shape[1]] = src
    return out
