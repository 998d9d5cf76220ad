"""Drawing machinery for :mod:`chaingeo.pictures.scene`: orthographic cameras, the visible faces
of a set of unit cubes in exact painter's order, small Pillow drawing helpers and a PNG writer.

Painter's order is exact for lattice cubes and an orthographic camera: if cube A hides part of
cube B, the two differ by at least one in some coordinate and every such difference points away
from the viewer, so A's centre is strictly nearer; cubes at equal depth never overlap on screen,
and the visible faces of one cube never overlap each other. Only faces not shared by two filled
cells and turned toward the camera are drawn.
"""

from __future__ import annotations

import math
import struct
import zlib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Final

import numpy as np
import numpy.typing as npt
from PIL import Image, ImageDraw, ImageFont
from zlib_ng import zlib_ng

from chaingeo.core.arrays import F64

RGB = tuple[int, int, int]
#: A colour as ``"#rrggbb"`` or an ``(r, g, b)`` triple.
ColorLike = str | tuple[int, int, int]
#: (x0, y0, x1, y1) in pixels, the end exclusive.
Box = tuple[int, int, int, int]
#: Deflate level for PNG (zlib-ng): fast, and fixed so the same picture gives the same bytes.
PNG_COMPRESS_LEVEL: Final = 2
EDGE: Final[RGB] = (0, 0, 0)

#: The six face normals, and for each the four corners of that face of the unit cube at the
#: origin, in order around the face.
NORMALS: Final = np.array(
    [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)], dtype=np.int64
)
FACE_CORNERS: Final = np.array(
    [
        [(1, 0, 0), (1, 1, 0), (1, 1, 1), (1, 0, 1)],
        [(0, 0, 0), (0, 0, 1), (0, 1, 1), (0, 1, 0)],
        [(0, 1, 0), (0, 1, 1), (1, 1, 1), (1, 1, 0)],
        [(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1)],
        [(0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)],
        [(0, 0, 0), (0, 1, 0), (1, 1, 0), (1, 0, 0)],
    ],
    dtype=np.float64,
)
#: Brightness per face normal in the oblique views (light from above, front, left): three
#: clearly different tones on the three visible sides, none dark enough to change a colour name.
SHADE: Final = np.array([0.72, 0.80, 0.78, 0.87, 1.0, 0.62])


@dataclass(frozen=True)
class Camera:
    """An orthographic camera: screen right and up, and the unit vector toward the viewer."""

    name: str
    title: str
    right: tuple[float, float, float]
    up: tuple[float, float, float]
    toward_viewer: tuple[float, float, float]
    depth_axis: int | None  # axis views: the axis along the line of sight (printed on faces)
    #: Per displayed axis: (axis, which frame edge carries its ticks as lo/hi per axis).
    tick_edges: tuple[tuple[int, tuple[str, str, str]], ...]


def _oblique(azimuth_deg: float, elevation_deg: float) -> tuple[F64, F64, F64]:
    a, e = math.radians(azimuth_deg), math.radians(elevation_deg)
    v = np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])
    r = np.cross(np.array([0.0, 0.0, 1.0]), v)
    r /= np.linalg.norm(r)
    return r, np.cross(v, r), v


def oblique_camera(name: str, title: str, azimuth: float, elevation: float) -> Camera:
    r, u, v = _oblique(azimuth, elevation)
    return Camera(
        name,
        title,
        (float(r[0]), float(r[1]), float(r[2])),
        (float(u[0]), float(u[1]), float(u[2])),
        (float(v[0]), float(v[1]), float(v[2])),
        None,
        ((0, ("*", "lo", "lo")), (1, ("hi", "*", "lo")), (2, ("lo", "lo", "*"))),
    )


def parse_color(color: ColorLike) -> RGB:
    """``"#rrggbb"`` or an (r, g, b) triple of 0..255 integers; ``ValueError`` otherwise."""
    if isinstance(color, str):
        h = color.lstrip("#")
        if len(h) != 6 or any(ch not in "0123456789abcdefABCDEF" for ch in h):
            raise ValueError(f"colour {color!r} is not #rrggbb")
        return int(h[0:2], 16), int(h[2:4], 16), int(h[4:6], 16)
    if len(color) == 3 and all(isinstance(c, int) and 0 <= c <= 255 for c in color):
        return int(color[0]), int(color[1]), int(color[2])
    raise ValueError(f"colour {color!r} is not an (r, g, b) triple of 0..255")


@dataclass(frozen=True)
class Faces:
    """Visible cube faces, far to near: screen corners (n, 4, 2), fill colours, their cells."""

    corners: F64
    fills: npt.NDArray[np.uint8]
    cells: npt.NDArray[np.int64]
    normals: npt.NDArray[np.int64]  # index into NORMALS


def no_faces() -> Faces:
    """No faces at all (an empty scene)."""
    return Faces(
        np.zeros((0, 4, 2)),
        np.zeros((0, 3), np.uint8),
        np.zeros((0, 3), np.int64),
        np.zeros(0, np.int64),
    )


def visible_faces(cells: npt.NDArray[np.int64], colors: F64, cam: Camera) -> Faces:
    """Faces not shared by two filled cells and turned toward the camera, sorted far to near."""
    v = np.array(cam.toward_viewer)
    facing = np.flatnonzero(NORMALS @ v > 1e-9)
    if len(cells) == 0:
        return no_faces()
    lo = cells.min(axis=0) - 1
    dims = cells.max(axis=0) - lo + 2
    grid = np.zeros(tuple(int(d) for d in dims), dtype=np.bool_)
    local = cells - lo
    grid[local[:, 0], local[:, 1], local[:, 2]] = True
    cell_idx: list[npt.NDArray[np.int64]] = []
    face_idx: list[npt.NDArray[np.int64]] = []
    for f in facing:
        nb = local + NORMALS[f]
        open_side = ~grid[nb[:, 0], nb[:, 1], nb[:, 2]]
        hit = np.flatnonzero(open_side)
        cell_idx.append(hit)
        face_idx.append(np.full(len(hit), f, dtype=np.int64))
    ci = np.concatenate(cell_idx)
    fi = np.concatenate(face_idx)
    centre_depth = (cells[ci] + 0.5) @ v  # larger = nearer the viewer
    c = cells[ci]
    order = np.lexsort((fi, c[:, 2], c[:, 1], c[:, 0], centre_depth))
    ci, fi = ci[order], fi[order]
    corners3 = cells[ci][:, None, :] + FACE_CORNERS[fi]
    proj = np.stack([corners3 @ np.array(cam.right), corners3 @ np.array(cam.up)], axis=-1)
    shade = np.ones(len(fi)) if cam.depth_axis is not None else SHADE[fi]
    fills = np.clip(np.rint(colors[ci] * shade[:, None]), 0, 255).astype(np.uint8)
    return Faces(proj, fills, cells[ci], fi)


@lru_cache(maxsize=64)
def font(px: int) -> ImageFont.FreeTypeFont | ImageFont.ImageFont:
    """Pillow's bundled font (the same glyphs everywhere Pillow is installed)."""
    return ImageFont.load_default(size=max(6, px))


@lru_cache(maxsize=4096)
def text_length(text: str, px: int) -> float:
    """Advance width of ``text`` in :func:`font` ``(px)`` (labels recur; measuring is costly)."""
    return float(font(px).getlength(text))


def text_color(fill: Iterable[int]) -> RGB:
    r, g, b = fill
    return (0, 0, 0) if 0.299 * r + 0.587 * g + 0.114 * b > 140 else (255, 255, 255)


@lru_cache(maxsize=1024)
def text_color_of(fill: RGB) -> RGB:
    """:func:`text_color` of a colour triple, kept (a view prints dozens of labels on faces of
    a few colours)."""
    return text_color(fill)


@lru_cache(maxsize=4096)
def text_glyph(text: str, px: int, anchor: str) -> tuple[npt.NDArray[np.uint8], int, int]:
    """:func:`_text_mask`'s glyphs as a read-only array (for the kernels), and its offset from
    the anchor point."""
    mask, dx, dy = _text_mask(text, px, anchor)
    out = np.array(mask, dtype=np.uint8)
    out.flags.writeable = False
    return out, dx, dy


@lru_cache(maxsize=4096)
def _text_mask(text: str, px: int, anchor: str) -> tuple[Image.Image, int, int]:
    """The glyphs of ``text`` as an 8-bit mask and its offset from the anchor point (cached:
    the same few labels recur in every picture, and rasterising them is the costly part)."""
    f = font(px)
    left, top, right, bottom = (int(v) for v in f.getbbox(text, anchor=anchor))
    mask = Image.new("L", (max(1, right - left), max(1, bottom - top)), 0)
    ImageDraw.Draw(mask).text((-left, -top), text, fill=255, font=f, anchor=anchor)
    return mask, left, top


def _text_at(xy: Sequence[float] | F64, text: str, px: int, anchor: str) -> tuple[Image.Image, Box]:
    mask, dx, dy = _text_mask(text, px, anchor)
    x, y = round(float(xy[0])) + dx, round(float(xy[1])) + dy
    return mask, (x, y, x + mask.size[0], y + mask.size[1])


def text_box(xy: Sequence[float] | F64, text: str, px: int, anchor: str = "mm") -> Box:
    """The pixels :func:`put_text` may change (end exclusive)."""
    return _text_at(xy, text, px, anchor)[1]


def put_text(
    image: Image.Image,
    xy: Sequence[float] | F64,
    text: str,
    px: int,
    fill: RGB,
    anchor: str = "mm",
) -> None:
    """Draw ``text`` at ``xy`` (``anchor`` as in Pillow: "mm" centre, "la" top left).

    Calls the core paste ``Image.paste(fill, box, mask)`` ends in, without its checks."""
    mask, box = _text_at(xy, text, px, anchor)
    if image.readonly:
        image.paste(fill, box, mask)
        return
    image.load()
    mask.load()
    image.im.paste(fill, box, mask.im)


@dataclass(frozen=True)
class Projector:
    """World point -> screen pixel (final resolution) for one camera and one image layout."""

    right: F64
    up: F64
    scale: float
    origin: tuple[float, float]

    def __call__(self, p: npt.ArrayLike) -> F64:
        q = np.asarray(p, dtype=np.float64)
        if q.ndim == 1:  # one point (labels): the same arithmetic on scalars, 5x faster
            x1 = float(q @ self.right) * self.scale + self.origin[0]
            y1 = -float(q @ self.up) * self.scale + self.origin[1]
            return np.array([x1, y1])
        x = q @ self.right * self.scale + self.origin[0]
        y = -(q @ self.up) * self.scale + self.origin[1]
        return np.stack([x, y], axis=-1)

    def screen(self, xy2: F64) -> F64:
        """Camera-plane coordinates (right, up) -> pixels."""
        out = np.empty_like(xy2)
        out[..., 0] = xy2[..., 0] * self.scale + self.origin[0]
        out[..., 1] = -xy2[..., 1] * self.scale + self.origin[1]
        return out


def frame_corners(lo: Sequence[int], hi: Sequence[int]) -> F64:
    return np.array(
        [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])],
        dtype=np.float64,
    )


def fit(points: F64, cam: Camera, box: tuple[float, float, float, float]) -> Projector:
    """Scale and centre ``points`` (world) into the pixel rectangle ``box`` (x0, y0, x1, y1)."""
    r, u = np.array(cam.right), np.array(cam.up)
    w = max(float(np.ptp(points @ r)), 1e-9)
    h = max(float(np.ptp(points @ u)), 1e-9)
    scale = min((box[2] - box[0]) / w, (box[3] - box[1]) / h)
    return Projector(r, u, scale, fit_centre(points, cam, box, scale))


def scaled(p: Projector, k: int) -> Projector:
    return Projector(p.right, p.up, p.scale * k, (p.origin[0] * k, p.origin[1] * k))


def polygon(draw: ImageDraw.ImageDraw, pts: F64, **kw: object) -> None:
    draw.polygon([(float(x), float(y)) for x, y in pts], **kw)  # type: ignore[arg-type]


def line(draw: ImageDraw.ImageDraw, a: F64, b: F64, fill: RGB, width: int) -> None:
    draw.line([(float(a[0]), float(a[1])), (float(b[0]), float(b[1]))], fill=fill, width=width)


#: A flat shape: (0 polygon fill or 1 polyline, its points in pixels, colour, line width).
Flat = tuple[int, F64, RGB, int]


def draw_flat(draw: ImageDraw.ImageDraw, shapes: Sequence[Flat]) -> None:
    """Flat shapes with Pillow (``polygon``'s and ``line``'s core calls, without their checks)."""
    for kind, pts, rgb, width in shapes:
        ink = draw.draw.draw_ink(rgb)
        ring = [(x, y) for x, y in pts.tolist()]
        if kind == 0:
            draw.draw.draw_polygon(ring, ink, 1)
        else:
            draw.draw.draw_lines(ring, ink, width)


def arrow_points(a: F64, b: F64, width: int) -> list[list[float]] | None:
    """The arrow from ``a`` to ``b``: the shaft's two ends, then the head's three corners
    (None when too short to draw). Plain float arithmetic in the order the array expressions
    of the first version took (the same numbers: ticks make three arrows per picture)."""
    ax, ay, bx, by = float(a[0]), float(a[1]), float(b[0]), float(b[1])
    dx, dy = bx - ax, by - ay
    n = float(np.hypot(dx, dy))
    if n < 1e-6:
        return None
    dx, dy = dx / n, dy / n
    head = max(4.0, 3.2 * width)
    base_x, base_y = bx - dx * head, by - dy * head
    px, py = -dy * head * 0.55, dx * head * 0.55
    left, right = [base_x + px, base_y + py], [base_x - px, base_y - py]
    return [[ax, ay], [base_x, base_y], [bx, by], left, right]


def arrow_shapes(a: F64, b: F64, fill: RGB, width: int) -> list[Flat]:
    """A line from ``a`` to ``b`` with a filled head at ``b`` (the font has no arrow glyphs)."""
    pts = arrow_points(a, b, width)
    if pts is None:
        return []
    return [(1, np.array(pts[:2]), fill, width), (0, np.array(pts[2:]), fill, 0)]


def arrow(draw: ImageDraw.ImageDraw, a: F64, b: F64, fill: RGB, width: int) -> None:
    draw_flat(draw, arrow_shapes(a, b, fill, width))


def draw_faces(draw: ImageDraw.ImageDraw, faces: Faces, proj: Projector, width: int) -> None:
    # Pillow's polygon(width > 1) rasterises a full-size mask per call; fill then stroke is ~10x
    # faster and looks the same.
    pix = proj.screen(faces.corners).tolist()
    for pts, fill in zip(pix, faces.fills.tolist(), strict=True):
        ring = [(p[0], p[1]) for p in pts]
        draw.polygon(ring, fill=(fill[0], fill[1], fill[2]))
        draw.line([*ring, ring[0]], fill=EDGE, width=width, joint="curve")


def draw_faces_fast(draw: ImageDraw.ImageDraw, faces: Faces, proj: Projector, width: int) -> F64:
    """:func:`draw_faces` calling the core drawing methods ``ImageDraw.polygon`` and ``line``
    end in, without their per-call checks (same pixels); returns the faces' screen corners."""
    pix: F64 = proj.screen(faces.corners)
    if width > 4:  # wide lines get round joints, drawn by ImageDraw.line itself
        draw_faces(draw, faces, proj, width)
        return pix
    core = draw.draw
    edge = core.draw_ink(EDGE)
    inks: dict[tuple[int, int, int], int] = {}
    for pts, fill in zip(pix.tolist(), faces.fills.tolist(), strict=True):
        ring = [(p[0], p[1]) for p in pts]
        key = (fill[0], fill[1], fill[2])
        ink = inks.get(key)
        if ink is None:
            ink = inks[key] = core.draw_ink(key)
        core.draw_polygon(ring, ink, 1)
        core.draw_lines([*ring, ring[0]], edge, width)
    return pix


def fit_centre(
    points: F64, cam: Camera, box: tuple[float, float, float, float], scale: float
) -> tuple[float, float]:
    """Origin that centres ``points`` in ``box`` at a given scale."""
    return centre_at(extreme_sums(points, cam), box, scale)


def extreme_sums(points: F64, cam: Camera) -> tuple[float, float]:
    """Along screen right and up: the largest plus the smallest coordinate of ``points``."""
    sx, sy = points @ np.array(cam.right), points @ np.array(cam.up)
    return float(sx.max() + sx.min()), float(sy.max() + sy.min())


@lru_cache(maxsize=512)
def box_spans(extent: tuple[int, int, int], cams: tuple[Camera, ...]) -> tuple[float, float]:
    """The widest screen extents of the box ``extent`` (from the origin) over ``cams``."""
    corners = frame_corners((0, 0, 0), extent)
    r = [float(np.ptp(corners @ np.array(c.right))) for c in cams]
    u = [float(np.ptp(corners @ np.array(c.up))) for c in cams]
    return max(r), max(u)


@lru_cache(maxsize=1024)
def box_sums(extent: tuple[int, int, int], cam: Camera) -> tuple[float, float]:
    """:func:`extreme_sums` of the box ``extent`` (from the origin): pieces recur."""
    return extreme_sums(frame_corners((0, 0, 0), extent), cam)


def centre_at(
    sums: tuple[float, float], box: tuple[float, float, float, float], scale: float
) -> tuple[float, float]:
    """:func:`fit_centre` from :func:`extreme_sums` (kept where the points recur)."""
    cx = (box[0] + box[2]) / 2 - sums[0] / 2 * scale
    cy = (box[1] + box[3]) / 2 + sums[1] / 2 * scale
    return cx, cy


def _png_chunk(tag: bytes, data: bytes) -> bytes:
    crc = zlib.crc32(tag + data) & 0xFFFFFFFF
    return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", crc)


def png_bytes(image: Image.Image) -> bytes:
    """An 8-bit RGB PNG: IHDR, one IDAT, IEND; no metadata, no timestamps.

    Written here rather than by Pillow because Pillow tries five row filters on every row of an
    RGB image (12 ms for a 512 px view); flat-shaded pictures compress as well unfiltered
    (filter 0), and zlib-ng deflates them in about 0.4 ms (stock zlib: 1.3 ms). The bytes depend
    only on the pixels and on the zlib-ng version, at a fixed level.
    """
    rgb = image if image.mode == "RGB" else image.convert("RGB")
    w, h = rgb.size
    rows = np.empty((h, w * 3 + 1), dtype=np.uint8)
    rows[:, 0] = 0  # each row starts with its filter type: 0, none
    rows[:, 1:] = np.frombuffer(rgb.tobytes(), dtype=np.uint8).reshape(h, w * 3)
    header = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    return b"".join(
        (
            b"\x89PNG\r\n\x1a\n",
            _png_chunk(b"IHDR", header),
            _png_chunk(b"IDAT", zlib_ng.compress(rows.data, PNG_COMPRESS_LEVEL)),
            _png_chunk(b"IEND", b""),
        )
    )


def sheet_grid(n: int, size: float, title_h: float, label_h: float, spans: F64) -> int:
    """Columns of the piece grid that draw the pieces largest (fewest columns on a tie)."""
    best, best_scale = 1, -1.0
    for cols in range(1, n + 1):
        rows = math.ceil(n / cols)
        cell_w, cell_h = size / cols, (size - title_h) / rows
        scale = min(cell_w / 2 * 0.84 / spans[0], (cell_h - label_h) * 0.84 / spans[1])
        if scale > best_scale + 1e-9:
            best, best_scale = cols, scale
    return best


@dataclass(frozen=True)
class Posed:
    """A rigid part drawn at a real pose: its cells (frame of the part), one fill colour, and
    the map ``p -> rotation @ p + translation`` of world points (cube corners)."""

    cells: npt.NDArray[np.int64]
    color: RGB
    rotation: F64  # (3, 3)
    translation: F64  # (3,)


def _on_lattice(part: Posed) -> npt.NDArray[np.int64] | None:
    """The part's world cells when its pose keeps cubes on cubes (a signed permutation and a
    whole translation), else None."""
    r = np.rint(part.rotation)
    t = np.rint(part.translation)
    if np.abs(part.rotation - r).max() > 1e-9 or np.abs(part.translation - t).max() > 1e-9:
        return None
    if not np.array_equal(np.abs(r).sum(axis=0), np.ones(3)) or len(part.cells) == 0:
        return None
    centres = (part.cells + 0.5) @ r.T + t
    return np.asarray(np.rint(centres - 0.5), dtype=np.int64)


def _shade_of(normals: F64) -> F64:
    """Brightness of turned faces: the axis faces' :data:`SHADE` mixed by the squared normal
    components (a convex mix, exact on the axes, so a turn fades smoothly between tones)."""
    pos, neg = np.clip(normals, 0, None) ** 2, np.clip(-normals, 0, None) ** 2
    mix = np.stack([pos[:, 0], neg[:, 0], pos[:, 1], neg[:, 1], pos[:, 2], neg[:, 2]], axis=1)
    out: F64 = mix @ SHADE
    return out


def posed_faces(parts: Sequence[Posed], cam: Camera) -> Faces:
    """Visible faces of rigid parts at real poses, far to near.

    When every pose is on the lattice this is exactly :func:`visible_faces` of the world cells
    (so a still frame of a video is the still picture, bytes and all). Otherwise each part's
    outer faces are moved, turned-away ones dropped, and all sorted by the depth of their
    centres: not exact (two unit faces close together at an angle, as in the middle of a
    turn, can be drawn in the wrong order for a frame), which only in-between frames use.
    """
    lattice = [_on_lattice(p) for p in parts]
    if all(c is not None for c in lattice):
        cells = [c for c in lattice if c is not None]
        colors = [np.tile(np.array(p.color, dtype=np.float64), (len(p.cells), 1)) for p in parts]
        if not cells:
            return visible_faces(np.zeros((0, 3), np.int64), np.zeros((0, 3)), cam)
        return visible_faces(np.concatenate(cells), np.concatenate(colors), cam)
    v = np.array(cam.toward_viewer)
    chunks: list[tuple[F64, F64, F64, npt.NDArray[np.int64]]] = []
    for part in parts:
        if len(part.cells) == 0:
            continue
        own = set(map(tuple, part.cells.tolist()))
        for f in range(6):
            open_side = [
                i
                for i, c in enumerate(part.cells.tolist())
                if (c[0] + NORMALS[f][0], c[1] + NORMALS[f][1], c[2] + NORMALS[f][2]) not in own
            ]
            if not open_side:
                continue
            normal = part.rotation @ NORMALS[f].astype(np.float64)
            if float(normal @ v) <= 1e-9:
                continue
            local = part.cells[open_side][:, None, :] + FACE_CORNERS[f]
            world = local @ part.rotation.T + part.translation
            fill = np.tile(np.array(part.color, dtype=np.float64), (len(open_side), 1))
            tone = 1.0 if cam.depth_axis is not None else float(_shade_of(normal[None, :])[0])
            shade = np.full(len(open_side), tone)
            near = np.asarray(np.floor(world.mean(axis=1)), dtype=np.int64)
            chunks.append((world, fill * shade[:, None], np.full(len(open_side), f), near))
    if not chunks:
        return visible_faces(np.zeros((0, 3), np.int64), np.zeros((0, 3)), cam)
    world = np.concatenate([c[0] for c in chunks])
    fills = np.concatenate([c[1] for c in chunks])
    normals = np.concatenate([c[2] for c in chunks]).astype(np.int64)
    near = np.concatenate([c[3] for c in chunks])
    order = np.argsort(world.mean(axis=1) @ v, kind="stable")
    world, fills, normals, near = world[order], fills[order], normals[order], near[order]
    proj = np.stack([world @ np.array(cam.right), world @ np.array(cam.up)], axis=-1)
    return Faces(proj, np.clip(np.rint(fills), 0, 255).astype(np.uint8), near, normals)
