"""Pictures of voxel pieces for agents and people: numpy + Pillow, no GUI, no OpenGL.

Every view is an orthographic projection: shaded unit cubes coloured by piece with black edges,
the box (or, without one, the scene's bounding box) as a wire frame over a gridded floor and
back walls, and 1-based cell indices along labelled axes, so a model can read coordinates off
the picture. The axis views (front, side, top) also print, on every visible face, the 1-based
coordinate along the line of sight ("y=2"), which turns three flat views into a readable map.

Hidden faces: exact painter's algorithm over the visible cube faces (see
:mod:`chaingeo.pictures.raster`).

Input is plain data (piece name -> (Shape, colour)), so this module knows nothing of the state
machines; PNG bytes are deterministic (fixed encoder settings, no metadata, no timestamps).
Coordinates are 0-based in code; only the printed labels are 1-based.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from functools import lru_cache
from typing import TYPE_CHECKING, Final

import numpy as np
import numpy.typing as npt
from PIL import Image, ImageDraw

from chaingeo.core.arrays import F64
from chaingeo.core.geometry import Shape
from chaingeo.pictures.labels import (
    AXIS_NAMES,
    TEXT,
    depth_label_steps,
    run_steps,
    tick_steps,
    title_steps,
)
from chaingeo.pictures.legend import draw_legend, legend_layout
from chaingeo.pictures.raster import (
    EDGE,
    RGB,
    Camera,
    ColorLike,
    Faces,
    Flat,
    Posed,
    Projector,
    box_spans,
    box_sums,
    centre_at,
    draw_faces,
    draw_faces_fast,
    draw_flat,
    fit,
    frame_corners,
    line,
    oblique_camera,
    parse_color,
    png_bytes,
    posed_faces,
    put_text,
    scaled,
    sheet_grid,
    text_length,
    visible_faces,
)

if TYPE_CHECKING:
    from chaingeo.core.level import Level

#: A scene: piece name -> (its cells where they are, its colour).
PieceMap = Mapping[str, tuple[Shape, ColorLike]]

VIEWS: Final[tuple[str, ...]] = ("front", "side", "top", "iso")
DEFAULT_SIZE: Final = 512
MIN_SIZE: Final = 128
_SUPERSAMPLE: Final = 2  # polygons are drawn at twice the size and box-filtered (anti-aliasing)

_BACKGROUND: Final[RGB] = (255, 255, 255)
_FLOOR: Final[RGB] = (232, 232, 228)
_WALL: Final[RGB] = (244, 244, 241)
_GRID: Final[RGB] = (185, 185, 180)
_FRAME: Final[RGB] = (90, 90, 90)
_TEXT: Final[RGB] = TEXT
_AXIS_NAMES: Final = AXIS_NAMES

#: Azimuth and elevation of the oblique view (camera at +x, -y, +z, like matplotlib's default
#: but slightly off the true isometric so that no two cube corners project onto one point).
ISO_AZIMUTH: Final = -58.0
ISO_ELEVATION: Final = 32.0

CAMERAS: Final[dict[str, Camera]] = {
    "front": Camera(
        "front",
        "FRONT: looking along +y (x right, z up)",
        (1.0, 0.0, 0.0),
        (0.0, 0.0, 1.0),
        (0.0, -1.0, 0.0),
        1,
        ((0, ("*", "lo", "lo")), (2, ("lo", "lo", "*"))),
    ),
    "side": Camera(
        "side",
        "SIDE: looking along -x (y right, z up)",
        (0.0, 1.0, 0.0),
        (0.0, 0.0, 1.0),
        (1.0, 0.0, 0.0),
        0,
        ((1, ("hi", "*", "lo")), (2, ("hi", "lo", "*"))),
    ),
    "top": Camera(
        "top",
        "TOP: looking down along -z (x right, y up)",
        (1.0, 0.0, 0.0),
        (0.0, 1.0, 0.0),
        (0.0, 0.0, 1.0),
        2,
        ((0, ("*", "lo", "hi")), (1, ("lo", "*", "hi"))),
    ),
    "iso": oblique_camera("iso", "3D view from front-right-above", ISO_AZIMUTH, ISO_ELEVATION),
}


# ---------------------------------------------------------------------------------------------
# Input checking
# ---------------------------------------------------------------------------------------------


def _check_size(size: int) -> None:
    if size < MIN_SIZE:
        raise ValueError(f"image size must be at least {MIN_SIZE} pixels, got {size}")


def _check_views(views: Sequence[str]) -> None:
    unknown = [v for v in views if v not in CAMERAS]
    if unknown:
        raise ValueError(f"unknown view(s) {unknown}; known: {list(CAMERAS)}")


@dataclass(frozen=True)
class _Scene:
    """Every filled cell with its piece's colour, and the frame the axes are drawn on."""

    cells: npt.NDArray[np.int64]  # (n, 3)
    colors: npt.NDArray[np.float64]  # (n, 3) rgb of each cell's piece
    lo: tuple[int, int, int]
    hi: tuple[int, int, int]  # exclusive
    has_box: bool
    legend: tuple[tuple[str, RGB], ...] = ()  # (name, colour) of every piece, by name


def _scene(pieces: PieceMap, box: Sequence[int] | None) -> _Scene:
    chunks: list[npt.NDArray[np.int64]] = []
    colors: list[npt.NDArray[np.float64]] = []
    for name in sorted(pieces):
        shape, color = pieces[name]
        rgb = parse_color(color)
        chunks.append(shape.voxels)
        colors.append(np.tile(np.array(rgb, dtype=np.float64), (len(shape), 1)))
    cells = np.concatenate(chunks) if chunks else np.zeros((0, 3), dtype=np.int64)
    rgbs = np.concatenate(colors) if colors else np.zeros((0, 3))
    if len(set(map(tuple, cells.tolist()))) != len(cells):  # np.unique(axis=0): ~10x slower
        owners: dict[tuple[int, int, int], str] = {}
        for name in sorted(pieces):
            for c in pieces[name][0]:
                if c in owners:
                    raise ValueError(f"pieces {owners[c]} and {name} overlap at {list(c)}")
                owners[c] = name
    if box is not None:
        if len(box) != 3 or any(int(b) < 1 for b in box):
            raise ValueError(f"box must be three positive sizes, got {list(box)}")
        lo = np.zeros(3, dtype=np.int64)
        hi = np.array([int(b) for b in box], dtype=np.int64)
        if len(cells):
            lo = np.minimum(lo, cells.min(axis=0))
            hi = np.maximum(hi, cells.max(axis=0) + 1)
    elif len(cells):
        lo, hi = cells.min(axis=0), cells.max(axis=0) + 1
    else:
        lo, hi = np.zeros(3, dtype=np.int64), np.ones(3, dtype=np.int64)
    return _Scene(
        cells,
        rgbs,
        (int(lo[0]), int(lo[1]), int(lo[2])),
        (int(hi[0]), int(hi[1]), int(hi[2])),
        box is not None,
        tuple((n, parse_color(pieces[n][1])) for n in sorted(pieces)),
    )


# ---------------------------------------------------------------------------------------------
# One view
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Layout:
    size: int
    title_px: int
    tick_px: int

    @staticmethod
    def of(size: int) -> _Layout:
        return _Layout(size, max(11, size // 34), max(10, size // 30))

    def edge_px(self, scale: int) -> int:
        """Cube edge width when drawing at ``scale`` times the final size."""
        return max(1, round(self.size * scale / 340))


def _plane_is_back(axis: int, side: str, cam: Camera) -> bool:
    """A frame wall is behind the scene when its inward normal points toward the viewer."""
    inward = 1.0 if side == "lo" else -1.0
    return inward * cam.toward_viewer[axis] > 1e-9


def _wall_corners(scene: _Scene, axis: int, side: str) -> F64:
    lo, hi = scene.lo, scene.hi
    b, c = [i for i in range(3) if i != axis]
    fixed = lo[axis] if side == "lo" else hi[axis]
    pts = []
    for ub, uc in ((lo[b], lo[c]), (hi[b], lo[c]), (hi[b], hi[c]), (lo[b], hi[c])):
        p = [0.0, 0.0, 0.0]
        p[axis], p[b], p[c] = fixed, ub, uc
        pts.append(p)
    return np.array(pts)


def _grid_ends(scene: _Scene, axis: int, side: str) -> F64:
    """The ends of a wall's grid lines, two rows a line: across the wall at every cell
    boundary along one of its axes, then along the other."""
    b, c = [i for i in range(3) if i != axis]
    blocks = []
    for along, across in ((b, c), (c, b)):
        t = np.arange(scene.lo[along], scene.hi[along] + 1, dtype=np.float64).repeat(2)
        block = np.empty((len(t), 3))
        block[:, axis] = scene.lo[axis] if side == "lo" else scene.hi[axis]
        block[:, along] = t
        block[0::2, across] = scene.lo[across]
        block[1::2, across] = scene.hi[across]
        blocks.append(block)
    return np.concatenate(blocks)


def wall_pixels(scene: _Scene, cam: Camera, proj: Projector) -> list[tuple[RGB, F64, F64]]:
    """Each back wall and the floor: its colour, its corners and its grid lines' ends (two rows
    a line) in pixels, in drawing order."""
    out = []
    for axis in (2, 0, 1):
        for side in ("lo", "hi"):
            if _plane_is_back(axis, side, cam):
                fill = _FLOOR if axis == 2 and side == "lo" else _WALL
                corners = proj(_wall_corners(scene, axis, side))
                out.append((fill, corners, proj(_grid_ends(scene, axis, side))))
    return out


def _wall_shapes(scene: _Scene, cam: Camera, proj: Projector, width: int) -> list[Flat]:
    """Back walls and floor with a line per cell boundary, so empty cells can be counted."""
    out: list[Flat] = []
    for fill, corners, pix in wall_pixels(scene, cam, proj):
        out.append((0, corners, fill, 0))
        out.extend((1, pix[i : i + 2], _GRID, width) for i in range(0, len(pix), 2))
    return out


def _draw_walls(
    draw: ImageDraw.ImageDraw, scene: _Scene, cam: Camera, proj: Projector, width: int
) -> None:
    draw_flat(draw, _wall_shapes(scene, cam, proj, width))


def _frame_edges(scene: _Scene, cam: Camera, back: bool) -> list[tuple[F64, F64]]:
    """The 12 frame edges that lie between two back walls (``back``) or the others."""
    out = []
    lo, hi = scene.lo, scene.hi
    for axis in range(3):
        b, c = [i for i in range(3) if i != axis]
        for sb in ("lo", "hi"):
            for sc in ("lo", "hi"):
                is_back = _plane_is_back(b, sb, cam) and _plane_is_back(c, sc, cam)
                if is_back != back:
                    continue
                p = np.zeros(3)
                p[b] = lo[b] if sb == "lo" else hi[b]
                p[c] = lo[c] if sc == "lo" else hi[c]
                q = p.copy()
                p[axis], q[axis] = lo[axis], hi[axis]
                out.append((p, q))
    return out


def _draw_ticks(
    image: Image.Image, scene: _Scene, cam: Camera, proj: Projector, lay: _Layout
) -> None:
    run_steps(image, tick_steps(scene.lo, scene.hi, cam, proj, lay.tick_px))


def _title(image: Image.Image, lines: Sequence[str], lay: _Layout) -> None:
    run_steps(image, title_steps(lines, lay.size, lay.title_px))


def _view_titles(cam: Camera, scene: _Scene) -> list[str]:
    what = "box" if scene.has_box else "frame = bounding box"
    if cam.depth_axis is None:
        return [cam.title, f"cells numbered from 1; {what}"]
    return [
        cam.title,
        f"labels on faces: {_AXIS_NAMES[cam.depth_axis]} of the visible cube; {what}",
    ]


def _view_projector(scene: _Scene, cam: Camera, lay: _Layout) -> Projector:
    """The frame fitted into the picture, leaving room for the title, the axis labels and the
    legend."""
    top = lay.title_px * 2.6 + lay.tick_px * 1.9 + 8
    side = lay.tick_px * 2.8
    bottom = lay.size - lay.tick_px * 2.8 - legend_layout(scene.legend, lay.size)[1]
    content = (side, top, lay.size - side, bottom)
    return fit(frame_corners(scene.lo, scene.hi), cam, content)


def _render_view(
    scene: _Scene,
    cam: Camera,
    size: int,
    faces: Faces | None = None,
    title: str | None = None,
    outline: _Scene | None = None,
    fast: bool = False,
) -> Image.Image:
    """One view; ``faces`` (else the scene's cells) are drawn, ``title`` replaces the camera's
    first title line, ``outline`` is a box drawn as a wire frame inside the frame; ``fast``
    draws the faces with :func:`draw_faces_fast` (the same pixels)."""
    lay = _Layout.of(size)
    # Axis views have only axis-parallel edges: no aliasing, so no supersampling needed.
    k = _SUPERSAMPLE if cam.depth_axis is None else 1
    proj = _view_projector(scene, cam, lay)
    big_proj = scaled(proj, k)
    big = Image.new("RGB", (size * k, size * k), _BACKGROUND)
    draw = ImageDraw.Draw(big)
    _draw_walls(draw, scene, cam, big_proj, k)
    for p, q in _frame_edges(scene, cam, back=True):
        line(draw, big_proj(p), big_proj(q), _FRAME, k)
    for p, q in _frame_edges(outline, cam, back=True) if outline else ():
        line(draw, big_proj(p), big_proj(q), _FRAME, 2 * k)
    if faces is None:
        faces = visible_faces(scene.cells, scene.colors, cam)
    (draw_faces_fast if fast else draw_faces)(draw, faces, big_proj, lay.edge_px(k))
    for p, q in _frame_edges(scene, cam, back=False) if scene.has_box else ():
        line(draw, big_proj(p), big_proj(q), _FRAME, k)
    for p, q in _frame_edges(outline, cam, back=False) if outline else ():
        line(draw, big_proj(p), big_proj(q), _FRAME, 2 * k)
    image = big.reduce(k) if k > 1 else big
    titles = _view_titles(cam, scene)
    _title(image, titles if title is None else [title, *titles[1:]], lay)
    _draw_ticks(image, scene, cam, proj, lay)
    if cam.depth_axis is not None and len(faces.cells):
        run_steps(image, depth_label_steps(faces, cam, proj))
    draw_legend(image, scene.legend)
    return image


# ---------------------------------------------------------------------------------------------
# The tray
# ---------------------------------------------------------------------------------------------


#: The piece sheet draws each piece from the iso corner and from the opposite one, so that
#: every face of a piece (and every notch in it) is seen once.
BACK_CAMERA: Final = oblique_camera(
    "iso-back", "3D view from back-left-below", ISO_AZIMUTH + 180.0, -ISO_ELEVATION
)
SHEET_CAMERAS: Final[tuple[Camera, Camera]] = (CAMERAS["iso"], BACK_CAMERA)
TRAY_TITLE: Final = "TRAY: pieces not yet placed"
PIECES_TITLE: Final = "PIECES: the puzzle's parts"
_SHEET_NOTE: Final = "each from front-right-above (left) and back-left-below (right)"


_AXES: Final = tuple((np.array(c.right), np.array(c.up)) for c in SHEET_CAMERAS)


@lru_cache(maxsize=512)
def _sheet_faces(cells: tuple[tuple[int, int, int], ...], rgb: RGB, cam: int) -> Faces:
    """One piece's faces on the sheet (they depend only on its shape, colour and camera)."""
    voxels = np.array(cells, dtype=np.int64).reshape(-1, 3)
    colors = np.tile(np.array(rgb, dtype=np.float64), (len(cells), 1))
    return visible_faces(voxels, colors, SHEET_CAMERAS[cam])


def _sheet_pieces(
    drawn: Sequence[tuple[Faces, Projector]], size: int, width: int, fast: bool
) -> Image.Image:
    """The sheet's pieces drawn at twice the size and reduced (``fast``: by
    :func:`draw_faces_fast`; :mod:`chaingeo.pictures.sheet` draws them by the kernels)."""
    k = _SUPERSAMPLE
    image = Image.new("RGB", (size * k, size * k), _BACKGROUND)
    draw = ImageDraw.Draw(image)
    for faces, proj in drawn:
        (draw_faces_fast if fast else draw_faces)(draw, faces, proj, width)
    return image.reduce(k)


@dataclass(frozen=True)
class _Sheet:
    """The piece sheet's faces and projectors (drawing scale), labels and grid of cells."""

    drawn: list[tuple[Faces, Projector]]
    slots: list[tuple[str, RGB, float, float]]
    cols: int
    rows: int
    cell_w: float
    cell_h: float
    title_h: float
    label_px: int


def _sheet_layout(pieces: PieceMap, size: int, fast: bool) -> _Sheet | None:
    """The layout of :func:`_render_tray` (None without pieces)."""
    lay = _Layout.of(size)
    k = _SUPERSAMPLE
    names = sorted(pieces)
    title_h = lay.title_px * 2.85 + 6
    if not names:
        return None
    label_px = max(9, min(lay.tick_px, size // 40))
    label_h = label_px * 1.7
    shapes = {n: pieces[n][0].normalized() for n in names}
    spans = np.array([1e-9, 1e-9])
    for n in names:
        spans = np.maximum(spans, box_spans(shapes[n].extent, SHEET_CAMERAS))
    cols = sheet_grid(len(names), size, title_h, label_h, spans)
    rows = math.ceil(len(names) / cols)
    cell_w, cell_h = size / cols, (size - title_h) / rows
    scale = min(cell_w / 2 * 0.84 / spans[0], (cell_h - label_h) * 0.84 / spans[1])
    drawn: list[tuple[Faces, Projector]] = []
    slots: list[tuple[str, RGB, float, float]] = []
    for i, n in enumerate(names):
        col, row = i % cols, i // cols
        x0, y0 = col * cell_w, title_h + row * cell_h
        rgb = parse_color(pieces[n][1])
        for j, cam in enumerate(SHEET_CAMERAS):
            box = (x0 + j * cell_w / 2, y0, x0 + (j + 1) * cell_w / 2, y0 + cell_h - label_h)
            sums = box_sums(shapes[n].extent, cam)
            proj = Projector(_AXES[j][0], _AXES[j][1], scale, centre_at(sums, box, scale))
            if fast:
                faces = _sheet_faces(shapes[n].cells, rgb, j)
            else:
                colors = np.tile(np.array(rgb, dtype=np.float64), (len(shapes[n]), 1))
                faces = visible_faces(shapes[n].voxels, colors, cam)
            drawn.append((faces, scaled(proj, k)))
        cubes = len(shapes[n])
        label = f"{n} ({cubes} cube{'s' if cubes != 1 else ''})"
        slots.append((label, rgb, x0 + cell_w / 2, y0 + cell_h - label_h / 2))
    return _Sheet(drawn, slots, cols, rows, cell_w, cell_h, title_h, label_px)


def _render_tray(pieces: PieceMap, size: int, title: str, fast: bool = False) -> Image.Image:
    """Every piece in its own cell, drawn twice (see :data:`SHEET_CAMERAS`) at one common
    scale, labelled with a colour swatch, its name and its number of cubes."""
    lay = _Layout.of(size)
    sheet = _sheet_layout(pieces, size, fast)
    if sheet is None:
        image = Image.new("RGB", (size, size), _BACKGROUND)
        _title(image, [title], lay)
        put_text(image, (size / 2, size / 2), "(no pieces)", lay.tick_px, _TEXT)
        return image
    label_px, title_h, cell_w = sheet.label_px, sheet.title_h, sheet.cell_w
    image = _sheet_pieces(sheet.drawn, size, lay.edge_px(_SUPERSAMPLE), fast)
    small = ImageDraw.Draw(image)
    _title(image, [title, _SHEET_NOTE], lay)
    for text, rgb, x, y in sheet.slots:
        width = text_length(text, label_px)
        left = x - (width + label_px * 1.4) / 2
        small.rectangle(
            [left, y - label_px / 2, left + label_px, y + label_px / 2], fill=rgb, outline=EDGE
        )
        put_text(image, (left + label_px * 1.4, y), text, label_px, _TEXT, anchor="lm")
    for c in range(1, sheet.cols):
        small.line([(c * cell_w, title_h), (c * cell_w, size)], fill=_GRID, width=1)
    for rr in range(1, sheet.rows):
        y = title_h + rr * sheet.cell_h
        small.line([(0, y), (size, y)], fill=_GRID, width=1)
    return image


# ---------------------------------------------------------------------------------------------
# Public API
# ---------------------------------------------------------------------------------------------


def render_images(
    pieces: PieceMap,
    box: Sequence[int] | None = None,
    views: Sequence[str] = VIEWS,
    size: int = DEFAULT_SIZE,
    title: str | None = None,
) -> dict[str, Image.Image]:
    """The pictures of a scene (pieces at their cells) as RGB images, one per view name;
    ``title`` replaces each view's first title line (say, to call it the target)."""
    _check_size(size)
    _check_views(views)
    scene = _scene(pieces, box)
    return {v: _render_view(scene, CAMERAS[v], size, title=title) for v in views}


def render_views(
    pieces: PieceMap,
    box: Sequence[int] | None = None,
    views: Sequence[str] = VIEWS,
    size: int = DEFAULT_SIZE,
    title: str | None = None,
) -> dict[str, bytes]:
    """PNG bytes per view of a scene; ``box`` is drawn as a wire frame (stacking) if given."""
    images = render_images(pieces, box, views, size, title)
    return {v: png_bytes(img) for v, img in images.items()}


def render_frame(
    parts: Sequence[Posed],
    legend: Sequence[tuple[str, RGB]],
    frame: tuple[Sequence[int], Sequence[int]],
    view: str = "iso",
    size: int = DEFAULT_SIZE,
    title: str | None = None,
    box: Sequence[int] | None = None,
) -> Image.Image:
    """One picture of rigid parts at real poses inside a fixed frame (``lo``, ``hi``: a video's
    camera does not follow the pieces), with ``box`` (from the origin) as a wire frame. At
    lattice poses it is the still picture of the same cells in the same frame
    (:func:`chaingeo.pictures.raster.posed_faces`)."""
    _check_size(size)
    _check_views([view])
    lo, hi = (tuple(int(v) for v in frame[0]), tuple(int(v) for v in frame[1]))
    if len(lo) != 3 or len(hi) != 3 or any(a >= b for a, b in zip(lo, hi, strict=True)):
        raise ValueError(f"a frame is two corners lo < hi, got {list(lo)} and {list(hi)}")
    empty = np.zeros((0, 3), dtype=np.int64)
    scene = _Scene(empty, np.zeros((0, 3)), lo, hi, False, tuple(legend))
    corner = (0, 0, 0) if box is None else (int(box[0]), int(box[1]), int(box[2]))
    outline = None if box is None else replace(scene, lo=(0, 0, 0), hi=corner)
    cam = CAMERAS[view]
    return _render_view(scene, cam, size, posed_faces(parts, cam), title, outline)


def view_projector(
    pieces: PieceMap, box: Sequence[int] | None, view: str, size: int = DEFAULT_SIZE
) -> Projector:
    """Where world points land in the picture of ``view`` (pixels of the final image), for
    anyone who annotates the pictures or checks them."""
    _check_size(size)
    _check_views([view])
    return _view_projector(_scene(pieces, box), CAMERAS[view], _Layout.of(size))


def render_tray_image(
    pieces: PieceMap, size: int = DEFAULT_SIZE, title: str = TRAY_TITLE
) -> Image.Image:
    """The piece sheet: each piece (only its shape matters, not where it is) from two opposite
    corners, labelled; titled the tray (stacking) or :data:`PIECES_TITLE` (puzzles)."""
    return render_tray_image_with(pieces, size, title, fast=False)


def render_tray_image_with(pieces: PieceMap, size: int, title: str, fast: bool) -> Image.Image:
    """:func:`render_tray_image`; ``fast`` keeps each piece's faces and skips Pillow's per-call
    checks (the same pixels; :mod:`chaingeo.pictures.scene_kernel`)."""
    _check_tray(pieces, size)
    return _render_tray(pieces, size, title, fast)


def _check_tray(pieces: PieceMap, size: int) -> None:
    _check_size(size)
    for shape, color in pieces.values():
        parse_color(color)
        if len(shape) == 0:
            raise ValueError("a piece needs at least one cell")


def render_tray(pieces: PieceMap, size: int = DEFAULT_SIZE, title: str = TRAY_TITLE) -> bytes:
    """PNG bytes of the piece sheet."""
    return png_bytes(render_tray_image(pieces, size, title))


def solution_pieces(level: Level) -> dict[str, tuple[Shape, ColorLike]]:
    """A level's pieces where its solution puts them: packed in the box (stacking) or assembled
    (puzzle). For pictures of a finished level; an observation must never show this."""
    from chaingeo.core.level import StackingSolution

    if isinstance(level.solution, StackingSolution):
        placed = level.solution.placements
        return {p.name: (placed[p.name], p.rgb) for p in level.pieces}
    return {p.name: (p.shape, p.rgb) for p in level.pieces}


def handed_pieces(level: Level) -> dict[str, tuple[Shape, ColorLike]]:
    """A level's pieces as handed to the agent (their file orientation)."""
    return {p.name: (p.shape, p.rgb) for p in level.pieces}


def render_solution_views(
    level: Level, views: Sequence[str] = VIEWS, size: int = DEFAULT_SIZE
) -> dict[str, bytes]:
    """PNG per view of the level solved (generators and documentation use this)."""
    return render_views(solution_pieces(level), level.box, views, size)


def render_level_tray(level: Level, size: int = DEFAULT_SIZE) -> bytes:
    """PNG of all of a level's pieces as handed out: the tray a stacking level starts with, or
    a puzzle's pieces (a puzzle has no tray)."""
    title = TRAY_TITLE if level.family == "stacking" else PIECES_TITLE
    return render_tray(handed_pieces(level), size, title)
