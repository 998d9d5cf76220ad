"""Pieces of a video frame by their hinted colours (the segmentation step of the video judge).

A frame is shrunk to a working size, and every pixel is given a colour class by one lookup in a
table over 5-bit RGB (32,768 entries), built once per video in CIELAB: with a level, a pixel is
a piece when it lies within :data:`DELTA_E` (CIEDE2000) of that piece's colour under some
shading (faces are drawn darker or lighter, so each colour is tried at several brightnesses);
without one, the chromatic colours of the first frame are clustered by hue (shading changes
lightness and chroma, hardly hue), deterministically, from a histogram. Grey backgrounds,
shadows, black edges and white text have no chroma and fall to the background.

Each class's mask is then cleaned (an opening drops anti-aliasing slivers and compression
specks, a closing bridges the drawn cube edges), and its connected components below a minimum
area relative to the frame are dropped (legend swatches, axis arrows).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Final

import numpy as np
import numpy.typing as npt
from PIL import Image

from chaingeo.core.arrays import F64, U8, Bools
from chaingeo.core.colors import PALETTE, ciede2000, srgb_to_lab
from chaingeo.kernels.jit import njit
from chaingeo.pictures.raster import SHADE

#: Longer side of a frame once shrunk: enough for pieces, cheap for every later step.
WORK_SIZE: Final = 320
#: Pixels from the picture's edge within which a piece touches the border (cleaning may eat
#: the outer column): a piece there may be entering or leaving the picture.
BORDER: Final = 3
#: CIEDE2000 distance within which a pixel takes a level colour (the palette's colours are at
#: least 12 apart, and the nearest one always wins).
DELTA_E: Final = 11.0
#: Brightness factors a level colour is tried at (the renderer shades faces 0.62-1.0; video
#: models light them more freely).
SHADES: Final = tuple(float(s) for s in np.linspace(0.45, 1.15, 15))
#: Brightness factors of our own renderer's faces (its SHADE, 0.62-1.0, a little widened for
#: GIF quantisation and anti-aliasing): used with a level, so a shaded white is not a grey.
RENDER_SHADES: Final = tuple(
    float(s) for s in np.linspace(float(SHADE.min()) - 0.05, float(SHADE.max()) + 0.03, 11)
)
#: Two level colours closer than this (CIEDE2000) under some pair of RENDER_SHADES cannot be
#: told apart reliably: identity changes between them are undecided, not violations.
CONFUSABLE: Final = 6.0
#: Least CIELAB chroma of a piece pixel without a level (grey backgrounds are below 8).
MIN_CHROMA: Final = 14.0
#: Hue clusters: a peak holds at least this share of the chromatic pixels of the first frame,
#: peaks closer than MERGE_DEGREES are one colour, and a pixel joins a peak within HUE_RADIUS.
MIN_PEAK_SHARE: Final = 0.03
MERGE_DEGREES: Final = 25.0
HUE_RADIUS: Final = 30.0
#: Least area of a component, as a share of the working frame.
MIN_AREA_SHARE: Final = 0.002
#: Chroma distance (CIELAB a*, b*) from the background's within which a colour is background.
BACKGROUND_CHROMA: Final = 12.0
#: Unknown pixels are dark (a piece's face in its own shade; a pale or half-transparent blend
#: of a piece with the ground, as video models draw a ghost, is no occluder).
UNKNOWN_LIGHTNESS: Final = 40.0
#: A dark pixel is the ground's only if its chromaticity, (R, G) / (R + G + B), is within
#: GROUND_CHROMATICITY of the ground's, a reach growing as its brightest channel falls below
#: DARK_FACE (noisier); below DARKEST (levels) a pixel has no reliable chromaticity at all.
GROUND_CHROMATICITY: Final = 0.05
DARK_FACE: Final = 45.0
DARKEST: Final = 16.0


@dataclass(frozen=True)
class ColorModel:
    """The colour classes of a video: names (class i + 1 is ``names[i]``), their CIELAB
    colours, and the class of every 5-bit RGB colour (0: background)."""

    names: tuple[str, ...]
    lab: F64
    table: U8
    source: str  # "level" or "first frame"


def _table_rgb() -> F64:
    q = np.arange(32768)
    return np.stack([(q >> 10) & 31, (q >> 5) & 31, q & 31], axis=1) * 8.0 + 4.0


@lru_cache(maxsize=1)
def _table_lab() -> F64:
    """CIELAB of every table colour (the same for every model: computed once)."""
    return srgb_to_lab(_table_rgb())


def _table_index(rgb: U8) -> npt.NDArray[np.uint16]:
    """The 5-bit RGB index of each pixel (15 bits: 16-bit arithmetic suffices)."""
    c = (rgb >> 3).astype(np.uint16)
    ten, five = np.uint16(10), np.uint16(5)
    out: npt.NDArray[np.uint16] = (c[..., 0] << ten) | (c[..., 1] << five) | c[..., 2]
    return out


Colors = list[tuple[str, tuple[int, int, int]]]


def palette_model(colors: Colors, shades: tuple[float, ...] = SHADES) -> ColorModel:
    """Classes for a level's piece colours (name, RGB), tried at every brightness of
    ``shades`` (the nearest shaded colour wins)."""
    return _palette_model(tuple(colors), shades)


def _shaded_lab(rgb: tuple[int, int, int], shades: tuple[float, ...]) -> F64:
    lit = np.array(rgb, dtype=np.float64)[None, :] * np.array(shades)[:, None]
    return srgb_to_lab(np.clip(lit, 0, 255))


def confusable(colors: Colors, shades: tuple[float, ...] = RENDER_SHADES) -> set[int]:
    """Indices of the colours that come within CONFUSABLE of another colour under some pair
    of ``shades`` (a shaded white is a grey): their identity cannot be read reliably."""
    labs = [_shaded_lab(rgb, shades) for _, rgb in colors]
    out: set[int] = set()
    for i in range(len(labs)):
        for j in range(i + 1, len(labs)):
            if ciede2000(labs[i][:, None, :], labs[j][None, :, :]).min() < CONFUSABLE:
                out |= {i, j}
    return out


@lru_cache(maxsize=8)
def _palette_model(
    colors: tuple[tuple[str, tuple[int, int, int]], ...], shades: tuple[float, ...]
) -> ColorModel:
    if not colors or len(colors) > 255:
        raise ValueError(f"1 to 255 piece colours, got {len(colors)}")
    lab_table = _table_lab()
    best = np.full(len(lab_table), np.inf)
    label = np.zeros(len(lab_table), dtype=np.uint8)
    for i, (_, rgb) in enumerate(colors):
        d = ciede2000(lab_table[:, None, :], _shaded_lab(rgb, shades)[None, :, :]).min(axis=1)
        closer = d < best
        best[closer] = d[closer]
        label[closer] = i + 1
    label[best > DELTA_E] = 0
    names = tuple(n for n, _ in colors)
    return ColorModel(names, srgb_to_lab(np.array([c for _, c in colors])), label, "level")


def _hue_chroma(lab: F64) -> tuple[F64, F64]:
    return np.degrees(np.arctan2(lab[..., 2], lab[..., 1])) % 360, np.hypot(
        lab[..., 1], lab[..., 2]
    )


def _hue_peaks(hues: F64) -> list[float]:
    """Peaks of a circular hue histogram (5 degree bins, smoothed), strongest first, each
    holding MIN_PEAK_SHARE of the pixels within MERGE_DEGREES / 2, none closer than that."""
    hist = np.bincount((hues // 5).astype(np.int64) % 72, minlength=72).astype(np.float64)
    smooth = np.zeros(72)
    for k, s in zip((1.0, 2.0, 3.0, 2.0, 1.0), range(-2, 3), strict=True):
        smooth += k * np.roll(hist, s)
    window = round(MERGE_DEGREES / 10)
    mass = np.zeros(72)
    for s in range(-window, window + 1):
        mass += np.roll(hist, s)
    peaks: list[float] = []
    for b in np.argsort(-smooth, kind="stable").tolist():
        if smooth[b] < smooth[(b - 1) % 72] or smooth[b] < smooth[(b + 1) % 72]:
            continue
        if mass[b] < MIN_PEAK_SHARE * len(hues):
            continue
        centre = b * 5 + 2.5
        if all(_angle(centre, p) >= MERGE_DEGREES for p in peaks):
            peaks.append(centre)
    return peaks


def _angle(a: float | F64, b: float) -> F64:
    d = np.abs((np.asarray(a, dtype=np.float64) - b + 180.0) % 360.0 - 180.0)
    return d


def clustered_model(frame: U8) -> ColorModel:
    """Classes from the first frame's chromatic colours, clustered by hue; named after the
    nearest palette colour (made unique by a number)."""
    lab = srgb_to_lab(_table_rgb()[_table_index(frame).ravel()])
    hue, chroma = _hue_chroma(lab)
    chromatic = chroma >= MIN_CHROMA
    peaks = _hue_peaks(hue[chromatic]) if chromatic.any() else []
    if not peaks:
        raise ValueError("the first frame shows no coloured piece (nothing has chroma)")
    t_hue, t_chroma = _hue_chroma(_table_lab())
    dist = np.stack([_angle(t_hue, p) for p in peaks], axis=1)
    table = (np.argmin(dist, axis=1) + 1).astype(np.uint8)
    table[(dist.min(axis=1) > HUE_RADIUS) | (t_chroma < MIN_CHROMA)] = 0
    labels = table[_table_index(frame).ravel()]
    centres = np.array([lab[labels == i + 1].mean(axis=0) for i in range(len(peaks))])
    return ColorModel(_names(centres), centres, table, "first frame")


def _names(centres: F64) -> tuple[str, ...]:
    pal = srgb_to_lab(np.array([c.rgb for c in PALETTE]))
    names: list[str] = []
    for lab in centres:
        base = PALETTE[int(np.argmin(ciede2000(pal, lab[None, :])))].name
        n = base if base not in names else f"{base}-{sum(x.startswith(base) for x in names) + 1}"
        names.append(n)
    return tuple(names)


def shrink(frame: U8) -> U8:
    """The frame at WORK_SIZE on its longer side (box filter; smaller frames are kept)."""
    h, w = frame.shape[:2]
    k = WORK_SIZE / max(h, w)
    if k >= 1:
        return frame
    size = (max(1, round(w * k)), max(1, round(h * k)))
    return np.asarray(Image.fromarray(frame).resize(size, Image.Resampling.BOX), dtype=np.uint8)


# ---------------------------------------------------------------------------------------------
# Masks: morphology and connected components
# ---------------------------------------------------------------------------------------------


def _spread(mask: Bools, r: int, grow: bool) -> Bools:
    """Dilation (grow) or erosion by a (2r+1)-square, separably; outside counts as empty.
    (A kernel: the judge spreads masks some hundred thousand times a video.)"""
    if r <= 0:
        return mask.copy()
    h, w = mask.shape
    flat = np.ascontiguousarray(mask, dtype=np.bool_).ravel().view(np.uint8)
    out: Bools = _spread_kernel(flat, h, w, r, grow).view(np.bool_).reshape(h, w)
    return out


@njit(cache=True)
def _copy(dst: U8, src: U8) -> None:
    """``dst[:] = src`` as a plain loop (cheaper than numba's slice assignment, row by row)."""
    for k in range(len(dst)):
        dst[k] = src[k]


@njit(cache=True)
def _merge(dst: U8, src: U8, grow: bool) -> None:
    """``dst`` |= ``src`` (grow) or &= (shrink), elementwise: a loop the compiler vectorises."""
    if grow:
        for k in range(len(dst)):
            dst[k] |= src[k]
    else:
        for k in range(len(dst)):
            dst[k] &= src[k]


@njit(cache=True)
def _spread_kernel(flat: U8, h: int, w: int, r: int, grow: bool) -> U8:
    """Square spread of a flat (h, w) 0/1 mask. The mask is laid in a frame of r empty pixels
    (what lies outside: erosion's AND takes them as empty, dilation's OR ignores them), so each
    pass is 2r + 1 whole-array ORs (ANDs) of the frame with itself shifted by whole rows, then
    by single pixels (a shift across a row's end reads only the frame)."""
    ww = w + 2 * r
    size = (h + 2 * r) * ww
    pad = np.zeros(size, dtype=np.uint8)
    for y in range(h):
        _copy(pad[(y + r) * ww + r : (y + r) * ww + r + w], flat[y * w : (y + 1) * w])
    lo, hi = r * ww, (h + r) * ww  # the picture's rows in the frame
    cols = np.zeros(size, dtype=np.uint8)
    _copy(cols[lo:hi], pad[lo - r * ww : hi - r * ww])
    for d in range(-r + 1, r + 1):
        _merge(cols[lo:hi], pad[lo + d * ww : hi + d * ww], grow)
    both = np.zeros(size, dtype=np.uint8)
    _copy(both[lo:hi], cols[lo - r : hi - r])
    for d in range(-r + 1, r + 1):
        _merge(both[lo:hi], cols[lo + d : hi + d], grow)
    out = np.empty(h * w, dtype=np.uint8)
    for y in range(h):
        _copy(out[y * w : (y + 1) * w], both[(y + r) * ww + r : (y + r) * ww + r + w])
    return out


def dilate(mask: Bools, r: int) -> Bools:
    return _spread(mask, r, True)


def erode(mask: Bools, r: int) -> Bools:
    out: Bools = ~dilate(~mask, r)
    return out


def on_border(mask: Bools, margin: int = BORDER) -> bool:
    """Whether ``mask`` has a pixel within ``margin`` pixels of the picture's edge."""
    b = margin
    return bool(mask[:b].any() or mask[-b:].any() or mask[:, :b].any() or mask[:, -b:].any())


def close(mask: Bools, r: int = 2) -> Bools:
    """Closing: gaps narrower than about 2r pixels filled."""
    return _spread(dilate(mask, r), r, False) | mask


def clean(mask: Bools) -> Bools:
    """Opening (radius 1: slivers and specks go) then closing (radius 2)."""
    return close(dilate(_spread(mask, 1, False), 1))


@njit(cache=True)
def _label_kernel(flat: npt.NDArray[np.uint8], h: int, w: int) -> npt.NDArray[np.int32]:
    """8-connected components of a flat mask: two passes over a union-find forest (one
    provisional label at most a set pixel)."""
    parent = np.arange(np.count_nonzero(flat) + 1, dtype=np.int32)
    lab = np.zeros(h * w, dtype=np.int32)
    nxt = 1
    roots = np.zeros(4, dtype=np.int32)  # one buffer: an allocation a pixel cost the most
    for i in range(h * w):
        if flat[i] == 0:
            continue
        y, x = i // w, i % w
        k = 0
        for dy, dx in ((-1, -1), (-1, 0), (-1, 1), (0, -1)):
            yy, xx = y + dy, x + dx
            if yy >= 0 and 0 <= xx < w and lab[yy * w + xx] > 0:
                r = lab[yy * w + xx]
                while parent[r] != r:
                    r = parent[r]
                roots[k] = r
                k += 1
        if k == 0:
            lab[i] = nxt
            nxt += 1
            continue
        m = roots[:k].min()
        lab[i] = m
        for j in range(k):
            parent[roots[j]] = m
    out = np.zeros(h * w, dtype=np.int32)
    ids = np.zeros(nxt, dtype=np.int32)
    count = 0
    for i in range(h * w):
        if lab[i] == 0:
            continue
        r = lab[i]
        while parent[r] != r:
            r = parent[r]
        if ids[r] == 0:
            count += 1
            ids[r] = count
        out[i] = ids[r]
    return out


def components(mask: Bools, min_area: int) -> list[Bools]:
    """The 8-connected components of ``mask`` of at least ``min_area`` pixels, in scan order."""
    h, w = mask.shape
    lab = _label_kernel(mask.astype(np.uint8).ravel(), h, w).reshape(h, w)
    areas = np.bincount(lab.ravel())
    return [lab == i for i in range(1, len(areas)) if areas[i] >= min_area]


def min_area(shape: tuple[int, ...]) -> int:
    return max(12, round(MIN_AREA_SHARE * shape[0] * shape[1]))


def classify(frame: U8, model: ColorModel) -> U8:
    """Class per pixel (0: background), before cleaning."""
    if frame.dtype != np.uint8 or frame.ndim != 3 or frame.shape[2] != 3:
        out: U8 = model.table[_table_index(frame)]
        return out
    flat = np.ascontiguousarray(frame).ravel()
    return _classify_kernel(flat, model.table).reshape(frame.shape[:2])


@njit(cache=True)
def _classify_kernel(flat: U8, table: U8) -> U8:
    """The table's class of each RGB triple of a flat frame (the index and the look-up in
    one pass: the judge classifies every frame)."""
    out = np.empty(len(flat) // 3, dtype=np.uint8)
    for i in range(len(out)):
        r, g, b = np.int64(flat[3 * i]), np.int64(flat[3 * i + 1]), np.int64(flat[3 * i + 2])
        out[i] = table[((r >> 3) << 10) | ((g >> 3) << 5) | (b >> 3)]
    return out


def class_masks(frame: U8, model: ColorModel) -> list[Bools]:
    """One cleaned mask per class (index i: class i + 1) of a working-size frame."""
    raw = classify(frame, model)
    return [clean(raw == i + 1) for i in range(len(model.names))]


def ground_and_unknown(frame: U8, masks: list[Bools]) -> tuple[Bools, Bools]:
    """Two readings of one frame's pixels of no piece class. Ground: whose chroma is the
    background's (open ground, its shadows, white; not a piece of a colour the palette missed).
    Unknown: not the background's and dark (a piece's face too dark to classify; a gap through
    such pixels is no break). The background is what the picture's border shows: colours within
    BACKGROUND_CHROMA of its median chroma (CIELAB a*, b*), at any lightness."""
    lab = _table_lab()[_table_index(frame)]
    near, piece = _near_ground(lab, masks, frame)
    return near & ~piece, ~near & ~piece & (lab[..., 0] <= UNKNOWN_LIGHTNESS)


def _near_ground(lab: F64, masks: list[Bools], frame: U8) -> tuple[Bools, Bools]:
    ring = np.zeros(lab.shape[:2], dtype=bool)
    ring[:3], ring[-3:], ring[:, :3], ring[:, -3:] = True, True, True, True
    piece = np.logical_or.reduce(masks) if masks else np.zeros_like(ring)
    edge = ring & ~piece
    a0, b0 = (float(np.median(lab[..., c][edge])) if edge.any() else 0.0 for c in (1, 2))
    near: Bools = np.hypot(lab[..., 1] - a0, lab[..., 2] - b0) <= BACKGROUND_CHROMA
    # a dark face has little CIELAB chroma at any hue, so it passes the test above; its
    # chromaticity (which shade leaves alone) still differs from the ground's
    red, green, blue = (frame[..., c].astype(np.float32) for c in range(3))  # per channel
    total = red + green + blue + np.float32(1e-6)
    r0, g0 = (float(np.median((c / total)[edge])) if edge.any() else 1 / 3 for c in (red, green))
    ask = near & ~piece  # only these can change
    rr, gg, tt = red[ask] / total[ask], green[ask] / total[ask], total[ask]
    hi = np.maximum(np.maximum(red[ask], green[ask]), blue[ask])
    reach = GROUND_CHROMATICITY * np.maximum(1.0, DARK_FACE / np.maximum(hi, 1.0))
    near[ask] = (np.hypot(rr - r0, gg - g0) <= reach) | (hi < DARKEST) | (tt <= 0)
    return near, piece
