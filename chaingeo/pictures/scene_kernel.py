"""The renderer's pictures, byte for byte, drawn on arrays by kernels and partly kept.
The reference it must equal is :mod:`chaingeo.pictures.scene`.

A view is the frame's background (walls, floor grid, back frame edges), the pieces' faces, the
front frame edges, then titles, axis ticks, depth labels and the legend. Here every shape and
every label is drawn by kernels (:mod:`chaingeo.pictures.raster_kernel`: Pillow's own algorithms
in numba; :mod:`chaingeo.pictures.texts`: runs of labels and swatches in one call each) on a
numpy array. A layout's plan (projector, packed walls and edges, label steps) is kept long, its
pixels shorter. In a box (stacking) the frame stays put, so all but the faces, depth labels and
legend are kept per layout (the background at drawing scale, and the picture without pieces):
a step draws the faces on a work copy of the background and reduces and takes only the
rectangle they (and their labels) cover, redrawing the labels that overlap it. A puzzle's frame
follows its pieces, so its views are drawn in one pass (on a recent background: a frame recurs
within an episode; its plan also when the level is played again).
Every drawing call is the one :mod:`chaingeo.pictures.scene` makes, in the same order, so the
pictures are the same bytes (tested over the shipped levels); ``render`` stays the reference
(and draws where the kernels do not apply: lines wide enough for round joints, or
``CHAINGEO_JIT=python``).
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Hashable, Sequence
from dataclasses import dataclass
from typing import Final, TypeVar

import numpy as np
import numpy.typing as npt

from chaingeo.core.arrays import F64
from chaingeo.kernels.jit import mode as jit_mode
from chaingeo.pictures import raster_kernel
from chaingeo.pictures.labels import (
    Step,
    depth_labels,
    grouped,
    overlaps,
    paint_steps,
    texts_step,
    tick_marks,
    titles,
)
from chaingeo.pictures.legend import clear_memo, legend_layout, paint_legend
from chaingeo.pictures.raster import (
    EDGE,
    RGB,
    Box,
    Camera,
    Faces,
    Flat,
    Projector,
    scaled,
)
from chaingeo.pictures.raster_faces_kernel import visible_faces
from chaingeo.pictures.scene import (
    _BACKGROUND,
    _FRAME,
    _GRID,
    _SUPERSAMPLE,
    CAMERAS,
    DEFAULT_SIZE,
    VIEWS,
    PieceMap,
    _check_size,
    _check_views,
    _frame_edges,
    _Layout,
    _Scene,
    _scene,
    _view_projector,
    _view_titles,
    wall_pixels,
)
from chaingeo.pictures.scene import (
    _render_view as render_view,
)

#: Layouts kept per process (each about 1 MB at 256 px: the iso background is drawn at 2x).
CAPACITY: Final = 48
_EDGE: Final = np.array(EDGE, dtype=np.uint8)
Pixels = npt.NDArray[np.uint8]
_T = TypeVar("_T")


@dataclass(frozen=True)
class _Plan:
    """A layout's frame and labels as shapes and steps, before any pixel is drawn."""

    proj: Projector
    k: int  # drawing scale
    walls: raster_kernel.Packed  # walls, floor grid and back frame edges, at drawing scale
    front: raster_kernel.Packed | None  # the front frame edges
    steps: tuple[Step, ...]  # titles and ticks, in drawing order


@dataclass(frozen=True)
class _Back:
    """A view's frame drawn without pieces: at drawing scale, before the front edges."""

    plan: _Plan
    big: Pixels


@dataclass(frozen=True)
class _Static:
    """What a view shows without pieces, for one frame, camera, size and legend height."""

    back: _Back
    plain: Pixels  # the finished picture without pieces, depth labels or legend


_STORE: OrderedDict[Hashable, _Static] = OrderedDict()
#: A frame that follows the pieces (a puzzle's): its background, kept only while recent (a
#: frame recurs within an episode, seldom later; no finished picture is kept).
_FOLLOW: OrderedDict[Hashable, _Back] = OrderedDict()
FOLLOW_CAPACITY: Final = 16
#: Plans are a few kilobytes (a background at 256 px is 200 kB to 800 kB), so many more are
#: kept: a frame that follows the pieces recurs when its level is played again, and a box
#: layout when its legend does.
_PLANS: OrderedDict[Hashable, _Plan] = OrderedDict()
PLAN_CAPACITY: Final = 512
_SCRATCH: dict[tuple[int, int], Pixels] = {}


def clear() -> None:
    """Forget every kept layout."""
    _STORE.clear()
    _FOLLOW.clear()
    _PLANS.clear()
    clear_memo()


def _kept(store: OrderedDict[Hashable, _T], key: Hashable) -> _T | None:
    """``store[key]``, now the most recent, or None."""
    found = store.get(key)
    if found is not None:
        store.move_to_end(key)
    return found


def _keep(store: OrderedDict[Hashable, _T], key: Hashable, value: _T, capacity: int) -> _T:
    """Keep ``value`` as the most recent, the least recent out past ``capacity``."""
    store[key] = value
    while len(store) > capacity:
        store.popitem(last=False)
    return value


def _layout_key(scene: _Scene, cam: Camera, size: int, title: str | None) -> Hashable:
    legend_h = legend_layout(scene.legend, size)[1]
    return (cam.name, size, scene.lo, scene.hi, title, legend_h, scene.has_box)


def _plan(scene: _Scene, cam: Camera, size: int, title: str | None, key: Hashable) -> _Plan:
    """The shapes ``render._render_view`` draws around the pieces, and its label steps (kept
    by layout ``key``)."""
    found = _kept(_PLANS, key)
    if found is not None:
        return found
    lay = _Layout.of(size)
    k = _SUPERSAMPLE if cam.depth_axis is None else 1
    proj = _view_projector(scene, cam, lay)
    big_proj = scaled(proj, k)
    back_edges = [np.stack([big_proj(p), big_proj(q)]) for p, q in _frame_edges(scene, cam, True)]
    walls = _packed_walls(wall_pixels(scene, cam, big_proj), back_edges, k)
    edges = _frame_edges(scene, cam, back=False) if scene.has_box else []
    front: list[Flat] = [(1, np.stack([big_proj(p), big_proj(q)]), _FRAME, k) for p, q in edges]
    steps = _label_steps(scene, cam, size, proj, title)
    made = _Plan(proj, k, walls, raster_kernel.pack(front) if front else None, steps)
    return _keep(_PLANS, key, made, PLAN_CAPACITY)


def _back(plan: _Plan, size: int) -> _Back:
    """The plan's background drawn by the kernels: walls, grid, back frame edges."""
    big = raster_kernel.blank(size * plan.k, _BACKGROUND).copy()
    raster_kernel.paint_packed(big, plan.walls)
    return _Back(plan, big)


def _packed_walls(
    walls: list[tuple[RGB, F64, F64]], edges: list[F64], k: int
) -> raster_kernel.Packed:
    """``_wall_shapes`` and then the back frame edges, packed from their pixel arrays as they
    come (a frame that follows the pieces draws its walls anew on most pictures)."""
    pts: list[F64] = []
    meta: list[tuple[int, int, int]] = []
    colors: list[RGB] = []
    for fill, corners, ends in walls:
        lines = len(ends) // 2
        pts += [corners, ends]
        meta += [(0, 4, 0), *[(1, 2, k)] * lines]
        colors += [fill, *[_GRID] * lines]
    pts += edges
    meta += [(1, 2, k)] * len(edges)
    colors += [_FRAME] * len(edges)
    return raster_kernel.Packed(
        np.array(meta, dtype=np.int64), np.concatenate(pts), np.array(colors, dtype=np.uint8)
    )


def _finish(back: _Back, big: Pixels) -> Pixels:
    raster_kernel.paint_packed(big, back.plan.front)
    return raster_kernel.reduce2(big) if back.plan.k > 1 else big


def _label_steps(
    scene: _Scene, cam: Camera, size: int, proj: Projector, title: str | None
) -> tuple[Step, ...]:
    lay = _Layout.of(size)
    heads = _view_titles(cam, scene)
    lines = heads if title is None else [title, *heads[1:]]
    return tuple(
        grouped(
            [
                *titles(lines, size, lay.title_px),
                *tick_marks(scene.lo, scene.hi, cam, proj, lay.tick_px),
            ]
        )
    )


def _static(scene: _Scene, cam: Camera, size: int, title: str | None) -> _Static | None:
    """The layout's static parts when the frame is a box (it stays put); None for a frame that
    follows the pieces (a puzzle's: its layouts seldom recur, so keeping them costs more than
    it saves)."""
    if not scene.has_box:
        return None
    key = _layout_key(scene, cam, size, title)
    found = _kept(_STORE, key)
    if found is not None:
        return found
    back = _back(_plan(scene, cam, size, title, key), size)
    plain = _finish(back, back.big.copy())
    paint_steps(plain, back.plan.steps)
    plain.flags.writeable = False
    return _keep(_STORE, key, _Static(back, plain), CAPACITY)


def _union(a: Box, b: Box) -> Box:
    return min(a[0], b[0]), min(a[1], b[1]), max(a[2], b[2]), max(a[3], b[3])


def _touched(pix: F64, margin: int, k: int, size: int) -> Box:
    """Final pixels the faces at drawing pixels ``pix`` may change (fill, edges, reduction)."""
    lo = pix.reshape(-1, 2).min(axis=0) - margin
    hi = pix.reshape(-1, 2).max(axis=0) + margin
    x0, y0 = math.floor(lo[0]) // k, math.floor(lo[1]) // k
    x1, y1 = math.ceil(hi[0]) // k + 1, math.ceil(hi[1]) // k + 1
    return max(0, x0), max(0, y0), min(size, x1), min(size, y1)


def _pieces(back: _Back, faces: Faces, size: int) -> tuple[Pixels, F64]:
    """The picture with the faces drawn (before labels), and their drawing pixels."""
    k = back.plan.k
    if k > 1:  # drawn on a kept work picture: only the reduction is handed out
        big = _scratch(size * k, 0)
        np.copyto(big, back.big)
    else:
        big = back.big.copy()
    pix = scaled(back.plan.proj, k).screen(faces.corners)
    width = _Layout.of(size).edge_px(k)
    raster_kernel.draw_faces(big, pix, faces.fills, _EDGE, width)
    return _finish(back, big), pix


def _depth_steps(faces: Faces, cam: Camera, proj: Projector) -> list[Step]:
    """The depth labels of an axis view as one step (none: an oblique view, or cells too
    small to label)."""
    if cam.depth_axis is None:
        return []
    items = depth_labels(faces, cam, proj)
    return [texts_step(items)] if items else []


def _scratch(side: int, slot: int) -> Pixels:
    """A work picture kept for reuse (its pixels are whatever its last user left)."""
    key = (side, slot)
    if key not in _SCRATCH:
        _SCRATCH[key] = np.empty((side, side, 3), dtype=np.uint8)
    return _SCRATCH[key]


def _with_faces(st: _Static, faces: Faces, cam: Camera, size: int) -> Pixels:
    """The picture without pieces, and inside the rectangle the faces and their labels cover:
    the faces on the background, the front edges, the reduction (of that rectangle only),
    then every label that overlaps it. Only that rectangle of the background is copied to the
    work picture: fills and lines do not read what they cover, so pixels outside it may hold
    anything."""
    back, plan = st.back, st.back.plan
    k = plan.k
    pix = scaled(plan.proj, k).screen(faces.corners)
    width = _Layout.of(size).edge_px(k)
    labels = _depth_steps(faces, cam, plan.proj)
    box = _touched(pix, width + 2, k, size)
    for step in labels:
        box = _union(box, step.box)
    x0, y0, x1, y1 = max(0, box[0]), max(0, box[1]), min(size, box[2]), min(size, box[3])
    out = st.plain.copy()
    if x0 >= x1 or y0 >= y1:
        return out
    big = _scratch(size * k, 0)
    big[y0 * k : y1 * k, x0 * k : x1 * k] = back.big[y0 * k : y1 * k, x0 * k : x1 * k]
    raster_kernel.draw_faces(big, pix, faces.fills, _EDGE, width)
    raster_kernel.paint_packed(big, plan.front)
    image = big
    if k > 1:
        image = _scratch(size, 1)
        raster_kernel.reduce2_into(big, image, x0, y0, x1, y1)
    rect = (x0, y0, x1, y1)
    paint_steps(image, [s for s in plan.steps if overlaps(s.box, rect)])
    paint_steps(image, labels)
    out[y0:y1, x0:x1] = image[y0:y1, x0:x1]
    return out


def _recent(scene: _Scene, cam: Camera, size: int, title: str | None) -> _Back:
    """The background of a frame that follows the pieces (kept while recent; its plan
    longer)."""
    key = _layout_key(scene, cam, size, title)
    found = _kept(_FOLLOW, key)
    if found is not None:
        return found
    back = _back(_plan(scene, cam, size, title, key), size)
    back.big.flags.writeable = False
    return _keep(_FOLLOW, key, back, FOLLOW_CAPACITY)


def _one_pass(scene: _Scene, cam: Camera, size: int, title: str | None, faces: Faces) -> Pixels:
    back = _recent(scene, cam, size, title)
    image = _pieces(back, faces, size)[0] if len(faces.fills) else _finish(back, back.big.copy())
    paint_steps(image, back.plan.steps)
    if len(faces.cells):
        paint_steps(image, _depth_steps(faces, cam, back.plan.proj))
    return image


def _view_pixels(scene: _Scene, cam: Camera, size: int, title: str | None) -> Pixels:
    """One finished view as a writable ``(size, size, 3)`` array."""
    if _Layout.of(size).edge_px(_SUPERSAMPLE) > 4 or jit_mode() != "numba":
        image = render_view(scene, cam, size, title=title, fast=True)  # round joints: Pillow
        return np.array(image, dtype=np.uint8)
    faces = visible_faces(scene.cells, scene.colors, cam)
    st = _static(scene, cam, size, title)
    if st is None:
        pixels = _one_pass(scene, cam, size, title, faces)
    elif len(faces.fills):
        pixels = _with_faces(st, faces, cam, size)
    else:
        pixels = st.plain.copy()
    paint_legend(pixels, scene.legend)
    return pixels


def render_arrays(
    pieces: PieceMap,
    box: Sequence[int] | None = None,
    views: Sequence[str] = VIEWS,
    size: int = DEFAULT_SIZE,
    title: str | None = None,
) -> dict[str, Pixels]:
    """:func:`render_images` as writable ``(size, size, 3)`` arrays (no image in between)."""
    _check_size(size)
    _check_views(views)
    scene = _scene(pieces, box)
    return {v: _view_pixels(scene, CAMERAS[v], size, title) for v in views}
