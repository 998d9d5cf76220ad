"""The renderer's pictures, pixel for pixel, drawing again only what the pieces change.

A view is the frame's background (walls, floor grid, back frame edges), the pieces' faces, the
front frame edges, then titles, axis ticks, depth labels and the legend. All but the faces, the
depth labels and the legend depend only on the frame, the camera and the legend's height, which
a run of steps seldom changes; :func:`render_images` keeps them per layout (the background at
drawing scale, and the finished picture without pieces) and per step draws the faces on a copy
of the background, then takes from that only the rectangle the faces (and their labels) cover,
redrawing the labels that overlap it. Every drawing call is the one
:mod:`chaingeo.envs.render` makes, in the same order, on the same pixels, so the pictures are
the same bytes (tested over the shipped levels); ``render`` stays the reference.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Hashable, Sequence
from dataclasses import dataclass
from typing import Final

from PIL import Image, ImageDraw

from chaingeo.envs.labels import (
    Step,
    depth_label_steps,
    overlaps,
    run_steps,
    tick_steps,
    title_steps,
)
from chaingeo.envs.legend import draw_legend, legend_layout
from chaingeo.envs.raster import (
    Box,
    Camera,
    Faces,
    FloatArray,
    Projector,
    draw_faces_fast,
    line,
    scaled,
    visible_faces,
)
from chaingeo.envs.render import (
    _BACKGROUND,
    _FRAME,
    _SUPERSAMPLE,
    CAMERAS,
    DEFAULT_SIZE,
    TRAY_TITLE,
    VIEWS,
    PieceMap,
    _check_size,
    _check_views,
    _draw_walls,
    _frame_edges,
    _Layout,
    _Scene,
    _scene,
    _view_projector,
    _view_titles,
    render_tray_image_with,
)
from chaingeo.envs.render import (
    _render_view as render_view,
)

#: Layouts kept per process (each about 1 MB at 256 px: the iso background is drawn at 2x).
CAPACITY: Final = 48


@dataclass(frozen=True)
class _Static:
    """What a view shows without pieces, for one frame, camera, size and legend height."""

    proj: Projector
    k: int  # drawing scale (supersampling)
    big: Image.Image  # background at drawing scale, before the pieces
    front: tuple[tuple[FloatArray, FloatArray], ...]  # front frame edges, drawing pixels
    plain: Image.Image  # the finished picture without pieces, depth labels or legend
    steps: tuple[Step, ...]  # titles and ticks, in drawing order


_STORE: OrderedDict[Hashable, _Static] = OrderedDict()
_SEEN: OrderedDict[Hashable, None] = OrderedDict()


def clear() -> None:
    """Forget every kept layout."""
    _STORE.clear()
    _SEEN.clear()


def _static(scene: _Scene, cam: Camera, size: int, title: str | None) -> _Static | None:
    """The layout's static parts, drawn on first use in a box, else on the second (a puzzle's
    frame follows its pieces, so many of its layouts are seen once: keeping those would cost
    more than it saves)."""
    key = (cam.name, size, scene.lo, scene.hi, scene.has_box, title)
    key += (legend_layout(scene.legend, size)[1],)
    found = _STORE.get(key)
    if found is not None:
        _STORE.move_to_end(key)
        return found
    if key not in _SEEN and not scene.has_box:
        _SEEN[key] = None
        while len(_SEEN) > 16 * CAPACITY:
            _SEEN.popitem(last=False)
        return None
    made = _draw_static(scene, cam, size, title)
    _STORE[key] = made
    while len(_STORE) > CAPACITY:
        _STORE.popitem(last=False)
    return made


def _draw_static(scene: _Scene, cam: Camera, size: int, title: str | None) -> _Static:
    """The steps of ``render._render_view`` that do not depend on the pieces."""
    lay = _Layout.of(size)
    k = _SUPERSAMPLE if cam.depth_axis is None else 1
    proj = _view_projector(scene, cam, lay)
    big_proj = scaled(proj, k)
    big = Image.new("RGB", (size * k, size * k), _BACKGROUND)
    draw = ImageDraw.Draw(big)
    _draw_walls(draw, scene, cam, big_proj, k)
    for p, q in _frame_edges(scene, cam, back=True):
        line(draw, big_proj(p), big_proj(q), _FRAME, k)
    edges = _frame_edges(scene, cam, back=False) if scene.has_box else []
    front = tuple((big_proj(p), big_proj(q)) for p, q in edges)
    plain = big.copy()
    _front_edges(plain, front, k)
    plain = plain.reduce(k) if k > 1 else plain
    titles = _view_titles(cam, scene)
    lines = titles if title is None else [title, *titles[1:]]
    steps = (
        *title_steps(lines, size, lay.title_px),
        *tick_steps(scene.lo, scene.hi, cam, proj, lay.tick_px),
    )
    run_steps(plain, steps)
    return _Static(proj, k, big, front, plain, steps)


def _front_edges(big: Image.Image, front: Sequence[tuple[FloatArray, FloatArray]], k: int) -> None:
    draw = ImageDraw.Draw(big)
    for a, b in front:
        line(draw, a, b, _FRAME, k)


def _union(a: Box, b: Box) -> Box:
    return min(a[0], b[0]), min(a[1], b[1]), max(a[2], b[2]), max(a[3], b[3])


def _touched(pix: FloatArray, margin: int, k: int, size: int) -> Box:
    """Final pixels the faces at drawing pixels ``pix`` may change (fill, edges, reduction)."""
    lo = pix.reshape(-1, 2).min(axis=0) - margin
    hi = pix.reshape(-1, 2).max(axis=0) + margin
    x0, y0 = math.floor(lo[0]) // k, math.floor(lo[1]) // k
    x1, y1 = math.ceil(hi[0]) // k + 1, math.ceil(hi[1]) // k + 1
    return max(0, x0), max(0, y0), min(size, x1), min(size, y1)


def _with_faces(st: _Static, faces: Faces, cam: Camera, size: int) -> Image.Image:
    big = st.big.copy()
    width = _Layout.of(size).edge_px(st.k)
    pix = draw_faces_fast(ImageDraw.Draw(big), faces, scaled(st.proj, st.k), width)
    _front_edges(big, st.front, st.k)
    image = big.reduce(st.k) if st.k > 1 else big
    labels = depth_label_steps(faces, cam, st.proj) if cam.depth_axis is not None else []
    box = _touched(pix, width + 2, st.k, size)
    for step in labels:
        box = _union(box, step.box)
    box = max(0, box[0]), max(0, box[1]), min(size, box[2]), min(size, box[3])
    if box[0] >= box[2] or box[1] >= box[3]:
        return st.plain.copy()
    run_steps(image, [s for s in st.steps if overlaps(s.box, box)])
    run_steps(image, labels)
    out = st.plain.copy()
    out.paste(image.crop(box), box[:2])
    return out


def _render_view(scene: _Scene, cam: Camera, size: int, title: str | None) -> Image.Image:
    st = _static(scene, cam, size, title)
    if st is None:
        return render_view(scene, cam, size, title=title, fast=True)
    faces = visible_faces(scene.cells, scene.colors, cam)
    image = _with_faces(st, faces, cam, size) if len(faces.fills) else st.plain.copy()
    draw_legend(image, scene.legend)
    return image


def render_images(
    pieces: PieceMap,
    box: Sequence[int] | None = None,
    views: Sequence[str] = VIEWS,
    size: int = DEFAULT_SIZE,
    title: str | None = None,
) -> dict[str, Image.Image]:
    """:func:`chaingeo.envs.render.render_images`, the same pixels, faster."""
    _check_size(size)
    _check_views(views)
    scene = _scene(pieces, box)
    return {v: _render_view(scene, CAMERAS[v], size, title) for v in views}


def render_tray_image(
    pieces: PieceMap, size: int = DEFAULT_SIZE, title: str = TRAY_TITLE
) -> Image.Image:
    """:func:`chaingeo.envs.render.render_tray_image`, the same pixels, faster."""
    return render_tray_image_with(pieces, size, title, fast=True)
