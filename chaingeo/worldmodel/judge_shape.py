"""Splits read from a piece's silhouette against the ground, whatever lies between the parts.

No pixel inside a rigid piece's silhouette ever shows the ground: each shows the piece or
something in front of it. A rigid piece's silhouette only translates between frames (our camera
is orthographic), so some translation lays the piece's pixels of one frame on no ground of a
frame a few later, and its pixels then, laid back, on no ground before. A piece that breaks in
two has no such translation: whichever half the shift follows, the other half lands on ground,
or comes out of it.

The tracker (:mod:`chaingeo.worldmodel.judge_track`) reads a break from a gap of background
between the parts; when another piece shows in that gap it takes the parts for one piece seen
round an occluder. This reading needs no gap: a colour seen in two parts or more, :data:`LAG`
frames after a frame where no translation lays the two silhouettes on each other's non-ground
within :data:`CONFLICT` of the least area, is a ``split``. It is not read where the colour
touches the picture's border meanwhile (a piece carried in), where one silhouette is much
smaller than the other (a piece mostly hidden pins no translation), nor on ground seen for
fewer than :data:`STEADY` frames (a dark piece passing reads as ground a moment). Two pieces
the palette put in one colour class also part that way when one slides from the other; the
halves of a broken piece keep one chromaticity, two pieces do not (:data:`SAME_HUE`).
"""

from __future__ import annotations

from typing import Final

import numpy as np

from chaingeo.core.arrays import U8, Bools
from chaingeo.worldmodel.judge_segment import components, erode, on_border
from chaingeo.worldmodel.judge_track import Event

#: Frames between the two silhouettes compared (a break that drifts apart over a few frames
#: shows whole).
LAG: Final = 3
#: Erosion (pixels) of silhouettes and ground before they are laid on each other: an edge's
#: blend and a whole-pixel shift's rounding.
EDGE: Final = 1
#: Least pixels (share of the least area) on ground at the best translation.
CONFLICT: Final = 1.0
#: Share of the best overlap (piece pixels laid on piece pixels) a translation must reach to
#: be weighed: far shifts can lay a silhouette on other pieces' pixels alone.
OVERLAP: Final = 0.5
#: Frames a pixel must be ground in (before the first silhouette, from the second on): a dark
#: piece passing can read as ground for a frame.
STEADY: Final = 3
#: Least ratio of the two silhouettes' areas: a piece mostly hidden in one frame leaves too
#: little silhouette to pin its translation.
SEEN: Final = 0.5
#: Largest distance between two parts' median chromaticities (r, g) for them to be one piece's.
SAME_HUE: Final = 0.03


def _box(m: Bools) -> tuple[int, int, int, int]:
    ys, xs = np.nonzero(m)
    return int(ys.min()), int(ys.max()), int(xs.min()), int(xs.max())


def _offsets(n: int) -> np.ndarray:
    """The shift each index of a cross-correlation of length ``n`` (two sides of n/2) stands for."""
    i = np.arange(n)
    out: np.ndarray = np.where(i >= n // 2, i - n, i)
    return out


def least_on_ground(
    was: Bools, now: Bools, ground_was: Bools, ground_now: Bools
) -> tuple[int, int, int]:
    """The translation (dy, dx) that lays ``was`` on ``ground_now`` and ``now`` (laid back) on
    ``ground_was`` with the fewest pixels, and that count; only shifts keeping both silhouettes
    inside the picture count (a piece off the border stays in it)."""
    h, w = was.shape
    size = (2 * h, 2 * w)

    def spec(m: Bools) -> np.ndarray:
        return np.fft.rfft2(m.astype(np.float64), size)

    # sum over x of was(x) ground_now(x + s), and of ground_was(x) now(x + s)
    sw, sn = spec(was), spec(now)
    corr = np.fft.irfft2(np.conj(sw) * spec(ground_now) + np.conj(spec(ground_was)) * sn, size)
    overlap = np.fft.irfft2(np.conj(sw) * sn, size)
    dy, dx = _offsets(2 * h), _offsets(2 * w)
    (ay, by, ax, bx), (cy, ey, cx, ex) = _box(was), _box(now)
    ok_y = (dy >= max(-ay, ey - (h - 1))) & (dy <= min(h - 1 - by, cy))
    ok_x = (dx >= max(-ax, ex - (w - 1))) & (dx <= min(w - 1 - bx, cx))
    ok = ok_y[:, None] & ok_x[None, :]
    ok &= overlap >= OVERLAP * overlap[ok].max() - 0.5
    score = np.where(ok, np.round(corr), np.inf)
    i = int(np.argmin(score))
    y, x = divmod(i, 2 * w)
    return int(dy[y]), int(dx[x]), int(score.flat[i])


def _chromaticity(frame: U8, m: Bools) -> tuple[float, float]:
    px = frame[m].astype(np.float64)
    total = px.sum(axis=1) + 1e-6
    return float(np.median(px[:, 0] / total)), float(np.median(px[:, 1] / total))


def _one_hue(frame: U8, parts: list[Bools]) -> bool:
    hues = [_chromaticity(frame, m) for m in parts]
    return all(
        float(np.hypot(a[0] - b[0], a[1] - b[1])) <= SAME_HUE
        for i, a in enumerate(hues)
        for b in hues[i + 1 :]
    )


def broken_pieces(
    frames: list[U8] | tuple[U8, ...],
    kept: list[list[Bools]],
    grounds: list[Bools],
    parts: list[list[int]],
    names: tuple[str, ...],
    least: int,
) -> list[Event]:
    """The splits of the module docstring: ``kept[t][k]`` a colour's piece pixels in frame
    ``t``, ``parts[t][k]`` how many components of at least ``least`` pixels they have, and
    ``grounds[t]`` the frame's ground."""
    out: list[Event] = []
    for k, name in enumerate(names):
        t = LAG
        while t < len(kept):
            e = _break(frames, kept, grounds, parts, k, t, least)
            if e is None:
                t += 1
                continue
            out.append(Event("split", e[0], name, None, _detail(name, e), e[2], last=t))
            t += 2 * LAG  # the same break, seen from the next frames
    return out


Found = tuple[int, int, tuple[Bools, ...]]


def _break(
    frames: list[U8] | tuple[U8, ...],
    kept: list[list[Bools]],
    grounds: list[Bools],
    parts: list[list[int]],
    k: int,
    t: int,
    least: int,
) -> Found | None:
    """(frame it came apart at, pixels on ground, the silhouettes before and then) of a break
    of colour ``k`` seen between frames ``t - LAG`` and ``t``, or None; it came apart where
    the colour's parts grew in number (or, if they did not, right after ``t - LAG``)."""
    u = t - LAG
    if parts[t][k] < 2:
        return None
    if any(on_border(kept[v][k]) for v in range(u, t + 1)):
        return None
    was, now = erode(kept[u][k], EDGE), erode(kept[t][k], EDGE)
    if not was.any() or not now.any():
        return None
    if min(int(was.sum()), int(now.sum())) < SEEN * max(int(was.sum()), int(now.sum())):
        return None
    gu = erode(_steady(grounds, range(u - STEADY + 1, u + 1)), EDGE)
    gt = erode(_steady(grounds, range(t, t + STEADY)), EDGE)
    if _laid_at_rest(was, now, gu, gt, CONFLICT * least):
        return None
    n = least_on_ground(was, now, gu, gt)[2]
    if n < CONFLICT * least or not _one_hue(frames[t], components(kept[t][k], least)):
        return None
    first = next((v for v in range(u + 1, t + 1) if parts[v][k] > parts[u][k]), u + 1)
    return first, n, (kept[first - 1][k], kept[first][k])


def _laid_at_rest(
    was: Bools, now: Bools, ground_was: Bools, ground_now: Bools, most: float
) -> bool:
    """Whether the zero shift (a piece at rest, the common case) already lays the silhouettes
    with fewer than ``most`` pixels on ground, and overlaps them as well as
    :func:`least_on_ground` asks of any shift: then its least is below ``most`` too, and
    the correlations need not be computed."""
    if float((was & now).sum()) < OVERLAP * min(float(was.sum()), float(now.sum())):
        return False
    return int((was & ground_now).sum() + (now & ground_was).sum()) < most


def _steady(grounds: list[Bools], frames: range) -> Bools:
    """Pixels that are ground in every one of ``frames`` within the clip."""
    got = [grounds[v] for v in frames if 0 <= v < len(grounds)]
    out: Bools = np.logical_and.reduce(got)
    return out


def _detail(name: str, found: Found) -> str:
    return (
        f"the {name} piece came apart: no translation lays its silhouettes {LAG} frames apart "
        f"on each other without {found[1]} px on open ground"
    )
