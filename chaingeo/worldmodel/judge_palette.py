"""The colour classes of a video with no level (the palette step of the video judge).

Shading is a change of light intensity at a constant colour: our shaded renderer (and, near
enough, a video model's lighting) scales a face's sRGB colour and adds white where it shines.
So colours are clustered on chromaticity, (r, g) = (R, G) / (R + G + B), which scaling leaves
alone, and two clusters on one ray from white are one colour seen with a highlight. Only the
flat inside of faces votes (a pixel whose neighbourhood hardly changes): the blends along edges
between two pieces (anti-aliasing, blur, JPEG's halved chroma) would otherwise fill the valley
between two colours and fuse them, or form a colour of their own. The number of colours is the
number of density peaks kept by that valley criterion. Dark faces are classified too, with a
reach that grows as their chromaticity gets noisier, and a dark colour vivid enough votes
for its own peak (a piece with no face in the light still has its class).
"""

from __future__ import annotations

from typing import Final

import numpy as np
import numpy.typing as npt

from chaingeo.core.arrays import F64, U8, Bools
from chaingeo.kernels.jit import njit
from chaingeo.worldmodel.judge_segment import (
    ColorModel,
    _names,
    _table_index,
    _table_lab,
    _table_rgb,
)

#: Video palette (no level): a pixel is chromatic when its channel spread is this share of its
#: brightest channel and that channel this bright; chromaticity peaks hold at least PEAK_SHARE
#: of the chromatic pixels of the video within PEAK_RADIUS, are CHROMA_SEP apart, and a colour
#: joins the nearest peak within JOIN_RADIUS.
MIN_SATURATION: Final = 0.28
MIN_BRIGHT: Final = 45
CHROMA_BINS: Final = 64
PEAK_SHARE: Final = 0.006
PEAK_RADIUS: Final = 0.035
CHROMA_SEP: Final = 0.04
VALLEY: Final = 0.6
LIT_VALLEY: Final = 0.1
RAY_DEGREES: Final = 4.5
JOIN_RADIUS: Final = 0.075
#: A peak is another's colour overexposed when a scaling by up to OVEREXPOSE, clipped, brings
#: it within EXPOSURE_TOL.
OVEREXPOSE: Final = 1.3
WASHED: Final = 1.5
EXPOSURE_TOL: Final = 0.015
#: Frames sampled for the palette (evenly over the video); a colour is a piece's when it covers
#: SEEN_SHARE of the picture in SEEN_FRAMES of them (not a blip of one frame).
PALETTE_FRAMES: Final = 24
SEEN_FRAMES: Final = 1
SEEN_SHARE: Final = 0.002
#: A pixel votes for the palette when no channel changes by more than this (levels) across its
#: 3 x 3 neighbourhood: the flat inside of a face, not an edge's blend.
FLAT_RANGE: Final = 24
#: A dark pixel (brightest channel from DARK_VOTE_BRIGHT to MIN_BRIGHT) votes for a peak when
#: its channel spread is DARK_VOTE_SATURATION of that channel: a forest green with every face
#: in shade has no bright face to make its peak, while grey shadows and a tinted ground's dark
#: pixels are far less saturated.
DARK_VOTE_BRIGHT: Final = 25
DARK_VOTE_SATURATION: Final = 0.6
#: Dark colours (brightest channel from DARK_BRIGHT to MIN_BRIGHT) join a peak within
#: JOIN_RADIUS * MIN_BRIGHT / brightest channel (their chromaticity is noisier), and only the
#: nearest peak when the next nearest is DARK_MARGIN times as far.
DARK_BRIGHT: Final = 20
DARK_MARGIN: Final = 1.5
#: A lit face (a highlight overexposes a colour and adds white) often lies past JOIN_RADIUS
#: of its peak: a chromatic colour joins the peak whose lit colours (see :func:`_lit`) it is
#: within LIT_TOL of, LIT_MARGIN times nearer than any other peak's, and not within
#: JOIN_RADIUS of the ground; chromaticities are looked up on a LIT_GRID-square grid.
LIT_TOL: Final = 0.02
LIT_MARGIN: Final = 2.0
LIT_GRID: Final = 128


def _chromaticity(rgb: F64) -> tuple[F64, Bools]:
    """(r, g) = (R, G) / (R + G + B) of sRGB colours, which a change of light intensity leaves
    alone (sRGB is close to a power of linear light: scaling scales all three channels alike),
    and whether each colour is saturated and bright enough to have a reliable one."""
    hi, lo = rgb.max(axis=1), rgb.min(axis=1)
    total = rgb.sum(axis=1) + 1e-9
    chroma = np.stack([rgb[:, 0] / total, rgb[:, 1] / total], axis=1)
    ok = (hi >= MIN_BRIGHT) & (hi - lo >= MIN_SATURATION * hi)
    return chroma, ok


def _table(rgb: F64, centres: F64, ground: F64 | None = None) -> U8:
    """The class of every table colour: its nearest centre if it joins it, else the peak it
    is a lit (whitened) face of (0: none)."""
    chroma, ok = _chromaticity(rgb)
    dist = np.sqrt(((chroma[:, None, :] - centres[None, :, :]) ** 2).sum(axis=2))
    table: U8 = (np.argmin(dist, axis=1) + 1).astype(np.uint8)
    joined = _joins(rgb, dist)
    table[~joined] = 0
    if ground is not None:
        free = ~joined & ok & (np.hypot(*(chroma - ground).T) > JOIN_RADIUS)
        table[free] = _lit(chroma[free], centres)
    return table


def _lit(chroma: F64, centres: F64) -> U8:
    """The peak (1-based; 0: none) each chromaticity is a lit face of: within LIT_TOL of the
    colours the peak's takes overexposed by up to WASHED with white added (clipped; see
    :func:`_washed`), and LIT_MARGIN times nearer those than any other peak's."""
    idx = np.clip((chroma * LIT_GRID).astype(np.int64), 0, LIT_GRID - 1)
    flat = idx[:, 0] * LIT_GRID + idx[:, 1]
    used, back = np.unique(flat, return_inverse=True)
    cells = (np.stack([used // LIT_GRID, used % LIT_GRID], axis=1) + 0.5) / LIT_GRID
    dist = np.stack([_locus_distance(cells, c) for c in centres], axis=1)
    best = np.argmin(dist, axis=1)
    near = dist[np.arange(len(dist)), best]
    second = np.sort(dist, axis=1)[:, 1] if dist.shape[1] > 1 else np.full(len(dist), np.inf)
    ok = (near <= LIT_TOL) & (second >= LIT_MARGIN * near)
    out: U8 = np.where(ok, best + 1, 0).astype(np.uint8)[back.ravel()]
    return out


def _locus_distance(points: F64, c: F64) -> F64:
    """Distance from each chromaticity to the lit colours of peak ``c`` (see :func:`_lit`)."""
    rgb = np.array([c[0], c[1], 1.0 - c[0] - c[1]])
    rgb = rgb / max(float(rgb.max()), 1e-9)
    k = np.linspace(1.0, WASHED, 11)[:, None, None]
    s = np.linspace(0.0, 0.6, 25)[None, :, None]
    lit = np.clip(rgb[None, None, :] * k + s, 0.0, 1.0).reshape(-1, 3)
    locus = np.unique(np.round(lit[:, :2] / lit.sum(axis=1, keepdims=True) * 4 * LIT_GRID), axis=0)
    locus /= 4 * LIT_GRID  # points closer than a quarter cell add nothing
    out: F64 = np.full(len(points), np.inf)
    for q in locus:
        np.minimum(out, (points[:, 0] - q[0]) ** 2 + (points[:, 1] - q[1]) ** 2, out=out)
    res: F64 = np.sqrt(out)
    return res


def _frames_seen(table: U8, frames: list[U8], n: int) -> npt.NDArray[np.int64]:
    """In how many of ``frames`` each of the ``n`` classes covers SEEN_SHARE of the picture."""
    out = np.zeros(n, dtype=np.int64)
    for f in frames:
        area = np.bincount(table[_table_index(f)].ravel(), minlength=n + 1)[1:]
        out += area >= SEEN_SHARE * f.shape[0] * f.shape[1]
    return out


def _votes(frame: U8, hist: F64, counts: F64) -> int:
    """Adds the flat inside of ``frame`` (see :func:`_vote_kernel`) to ``counts`` (per 5-bit
    table colour) and its chromatic pixels to the chromaticity histogram ``hist``; returns
    how many were chromatic."""
    h, w = frame.shape[:2]
    flat = np.ascontiguousarray(frame[..., :3]).ravel()
    return int(
        _vote_kernel(
            flat, h, w, FLAT_RANGE, CHROMA_BINS, MIN_BRIGHT, MIN_SATURATION, hist, counts,
            DARK_VOTE_BRIGHT, DARK_VOTE_SATURATION,
        )
    )  # fmt: skip


@njit(cache=True)
def _vote_kernel(
    flat: U8, h: int, w: int, flat_range: int, bins: int, bright: int, sat: float,
    hist: F64, counts: F64, dark: int, dark_sat: float,
) -> int:  # fmt: skip
    """One pass over a frame: a pixel votes when no channel changes by more than
    ``flat_range`` across its 3 x 3 neighbourhood (edges repeated), the flat inside of a face
    and not an edge's blend; a chromatic one (see :func:`_chromaticity`) lands in the
    histogram's cell of its own 8-bit chromaticity (the 5-bit table's colours would bend a
    dark colour's by their rounding); below ``bright``, only a vivid one (``dark_sat``)."""
    n = 0
    for y in range(h):
        for x in range(w):
            i = (y * w + x) * 3
            inside = True
            for c in range(3):
                hi = np.int64(flat[i + c])
                lo = hi
                for yy in range(max(y - 1, 0), min(y + 2, h)):
                    for xx in range(max(x - 1, 0), min(x + 2, w)):
                        v = np.int64(flat[(yy * w + xx) * 3 + c])
                        hi = max(hi, v)
                        lo = min(lo, v)
                if hi - lo > flat_range:
                    inside = False
                    break
            if not inside:
                continue
            r, g, b = np.int64(flat[i]), np.int64(flat[i + 1]), np.int64(flat[i + 2])
            counts[((r >> 3) << 10) | ((g >> 3) << 5) | (b >> 3)] += 1.0
            top, bottom = max(r, g, b), min(r, g, b)
            vivid = top >= dark and top - bottom >= dark_sat * top
            if (top < bright and not vivid) or top - bottom < sat * top:
                continue
            total = float(r + g + b) + 1e-9
            cy = min(int(r / total * bins), bins - 1)
            cx = min(int(g / total * bins), bins - 1)
            hist[cy * bins + cx] += 1.0
            n += 1
    return n


def _joins(rgb: F64, dist: F64) -> Bools:
    """Whether each table colour joins its nearest peak (``dist``: to every peak): a bright
    chromatic colour within JOIN_RADIUS, a dark one within a reach growing as it darkens and
    clearly nearer that peak than any other."""
    _, ok = _chromaticity(rgb)
    hi, lo = rgb.max(axis=1), rgb.min(axis=1)
    near = dist.min(axis=1)
    bright = ok & (near <= JOIN_RADIUS)
    dark = (hi >= DARK_BRIGHT) & (hi < MIN_BRIGHT) & (hi - lo >= MIN_SATURATION * hi)
    reach = JOIN_RADIUS * MIN_BRIGHT / np.maximum(hi, 1.0)
    second = np.sort(dist, axis=1)[:, 1] if dist.shape[1] > 1 else np.full(len(dist), np.inf)
    dark &= (near <= reach) & (second >= DARK_MARGIN * near)
    out: Bools = bright | dark
    return out


def _smoothed(hist: F64) -> F64:
    out = hist.copy()
    for axis in (0, 1):
        acc = np.zeros_like(out)
        for d, w in ((-2, 1.0), (-1, 2.0), (0, 3.0), (1, 2.0), (2, 1.0)):
            acc += w * np.roll(out, d, axis=axis)
        out = acc / 9.0
    return out


def _ridge(smooth: F64, a: tuple[float, float], b: tuple[float, float]) -> float:
    """The least smoothed density on the straight way from peak ``a`` to peak ``b``."""
    n = CHROMA_BINS
    ts = np.linspace(0.0, 1.0, 17)
    ys = np.clip(((a[0] + ts * (b[0] - a[0])) * n).astype(np.int64), 0, n - 1)
    xs = np.clip(((a[1] + ts * (b[1] - a[1])) * n).astype(np.int64), 0, n - 1)
    return float(smooth[ys, xs].min())


def _on_ray(a: tuple[float, float], b: tuple[float, float]) -> bool:
    """Whether two chromaticities lie on one ray from white (within RAY_DEGREES): one colour
    seen with more or less white light on it (a lit face's highlight)."""
    ta = np.degrees(np.arctan2(a[1] - 1 / 3, a[0] - 1 / 3))
    tb = np.degrees(np.arctan2(b[1] - 1 / 3, b[0] - 1 / 3))
    return bool(abs((ta - tb + 180.0) % 360.0 - 180.0) <= RAY_DEGREES)


def _overexposed(a: tuple[float, float], b: tuple[float, float]) -> bool:
    """Whether chromaticity ``b`` is ``a``'s colour lit past full scale (each channel scaled
    by up to OVEREXPOSE, then clipped: a lit face of a bright colour loses its brightest
    channel's lead), within EXPOSURE_TOL, or the reverse. (White added on top is the ray test;
    both at once would take a rust to an orange.)"""
    return _reached(a, b) or _reached(b, a)


def _reached(a: tuple[float, float], b: tuple[float, float]) -> bool:
    rgb = np.array([a[0], a[1], 1.0 - a[0] - a[1]])
    rgb = rgb / max(float(rgb.max()), 1e-9)
    lit = np.clip(rgb[None, :] * np.linspace(1.0, OVEREXPOSE, 13)[:, None], 0.0, 1.0)
    chroma = lit[:, :2] / lit.sum(axis=1, keepdims=True)
    return bool(np.hypot(chroma[:, 0] - b[0], chroma[:, 1] - b[1]).min() <= EXPOSURE_TOL)


def _same(smooth: F64, c: tuple[float, float], p: tuple[float, float], v: float) -> bool:
    """Whether peak ``c`` (height ``v``) is kept peak ``p``'s colour: joined to it by a ridge
    without a valley, or lit differently (on its ray from white, or overexposed) and joined
    by a ridge that never drops to nothing (a highlight fades smoothly; two pieces of
    colours on one ray, a green and a forest green, leave empty chromaticities between)."""
    ridge = _ridge(smooth, c, p)
    lit = _on_ray(c, p) or _overexposed(c, p) or _washed(c, p)
    return ridge >= VALLEY * v or (lit and ridge >= LIT_VALLEY * v)


def _washed(c: tuple[float, float], p: tuple[float, float]) -> bool:
    """Whether the weaker peak ``c`` is ``p``'s colour overexposed by up to WASHED and with
    white added (a lit face in a highlight), within EXPOSURE_TOL: only toward white, so a
    more saturated colour (a rust beside an orange) is never the lit face of a paler one."""
    white = 1 / 3
    if np.hypot(c[0] - white, c[1] - white) > np.hypot(p[0] - white, p[1] - white):
        return False
    rgb = np.array([p[0], p[1], 1.0 - p[0] - p[1]])
    rgb = rgb / max(float(rgb.max()), 1e-9)
    k = np.linspace(1.0, WASHED, 11)[:, None, None]
    s = np.linspace(0.0, 0.6, 25)[None, :, None]
    lit = np.clip(rgb[None, None, :] * k + s, 0.0, 1.0).reshape(-1, 3)
    chroma = lit[:, :2] / lit.sum(axis=1, keepdims=True)
    return bool(np.hypot(chroma[:, 0] - c[0], chroma[:, 1] - c[1]).min() <= EXPOSURE_TOL)


def _peaks(hist: F64, total: float) -> list[tuple[float, float]]:
    """Local maxima of the smoothed chromaticity histogram holding PEAK_SHARE of ``total``
    within PEAK_RADIUS, strongest first; a weaker peak joined to a kept one by a ridge without
    a valley (density never below VALLEY of its own) is the same colour (a highlight or a shadow
    drags a colour's pixels toward grey): the number of colours is what this criterion keeps."""
    n = CHROMA_BINS
    smooth = _smoothed(hist)
    r = max(1, round(PEAK_RADIUS * n))
    mass = np.zeros_like(hist)
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            if dx * dx + dy * dy <= r * r:
                mass += np.roll(np.roll(hist, dy, axis=0), dx, axis=1)
    order = np.argsort(-smooth.ravel(), kind="stable")
    out: list[tuple[float, float]] = []
    heights: list[float] = []
    for idx in order.tolist():
        y, x = divmod(idx, n)
        v = float(smooth[y, x])
        if v <= 0:
            break
        if mass[y, x] < PEAK_SHARE * total:
            continue
        if v < smooth[max(0, y - 1) : y + 2, max(0, x - 1) : x + 2].max():
            continue
        c = ((y + 0.5) / n, (x + 0.5) / n)
        if any(np.hypot(c[0] - a, c[1] - b) < CHROMA_SEP for a, b in out):
            continue
        if any(_same(smooth, c, p, v) for p in out):
            continue
        out.append(c)
        heights.append(v)
    return out


def _border_chromaticity(frames: list[U8]) -> F64:
    """The median chromaticity of the pictures' outer rows and columns: the background (a
    tinted ground is saturated enough to pass for a piece colour, and its shadows share its
    chromaticity)."""
    ring = np.concatenate(
        [np.concatenate([f[:3].reshape(-1, 3), f[-3:].reshape(-1, 3), f[:, :3].reshape(-1, 3),
                         f[:, -3:].reshape(-1, 3)]) for f in frames]
    ).astype(np.float64)  # fmt: skip
    chroma, _ = _chromaticity(ring)
    out: F64 = np.median(chroma, axis=0)
    return out


def video_model(frames: list[U8] | tuple[U8, ...]) -> ColorModel:
    """Classes from the chromatic colours of frames sampled over the whole video (a piece
    brought in later has its colour too), clustered by chromaticity, the number of colours
    chosen by the peak criterion of :func:`_peaks`; named after the nearest palette colour."""
    picks = np.unique(np.linspace(0, len(frames) - 1, min(PALETTE_FRAMES, len(frames))).round())
    counts = np.zeros(32768, dtype=np.float64)
    votes = np.zeros(CHROMA_BINS * CHROMA_BINS, dtype=np.float64)
    total = float(sum(_votes(frames[i], votes, counts) for i in picks.astype(int).tolist()))
    hist = votes.reshape(CHROMA_BINS, CHROMA_BINS)
    rgb = _table_rgb()
    ground = _border_chromaticity([frames[i] for i in picks.astype(int).tolist()])
    peaks = [c for c in _peaks(hist, total) if np.hypot(*(np.array(c) - ground)) > JOIN_RADIUS]
    if not peaks:
        raise ValueError("the video shows no coloured piece (nothing is saturated)")
    table = _table(rgb, np.array(peaks))
    seen = _frames_seen(table, [frames[i] for i in picks.astype(int).tolist()], len(peaks))
    kept = [c for c, n in zip(peaks, seen, strict=True) if n >= min(SEEN_FRAMES, len(picks))]
    if not kept:
        raise ValueError("the video shows no coloured piece (nothing is saturated)")
    if len(kept) < len(peaks):  # names from the colours proper, not lit faces
        peaks = kept
        table = _table(rgb, np.array(peaks))
    lab = _table_lab()
    labs = []
    for i in range(len(peaks)):
        w = np.where(table == i + 1, counts, 0.0)
        bright = lab[:, 0] >= np.percentile(lab[w > 0, 0], 50) if (w > 0).any() else w > 0
        w = np.where(bright, w, 0.0)
        labs.append((lab * w[:, None]).sum(axis=0) / max(w.sum(), 1e-9))
    table = _table(rgb, np.array(peaks), ground)
    return ColorModel(_names(np.array(labs)), np.array(labs), table, "video")
