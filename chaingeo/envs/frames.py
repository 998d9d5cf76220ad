"""Observation pictures as ``uint8`` arrays straight from the renderer, without PNG in between.

The Gymnasium environments hand out pixels, not files: encoding every picture to PNG and
decoding it back cost about a third of the time spent on an observation's pictures.
:func:`render_frames` takes the images :func:`chaingeo.envs.observation.render_state` encodes
(drawn by :mod:`chaingeo.pictures.scene_kernel`, byte-equal to :mod:`chaingeo.pictures.scene`) as
arrays; PNG is lossless, so they are pixel-equal to decoding the PNG (tested).
PNG stays where bytes are wanted (the harness' logs and agents call ``render_state``);
:func:`png_frames` keeps the round trip callable as the reference of ``chain bench env``.

A picture depends only on what it shows, so :class:`FrameCache` keeps recent ones: the four views
by the cells drawn, the tray by the pieces still in it, a puzzle's target by the level alone. A
refused action, an undo or a position seen before then costs a copy, not a render. This module
does not change how pictures look.
"""

from __future__ import annotations

import io
from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import Final

import numpy as np
import numpy.typing as npt
from PIL import Image

from chaingeo.envs.machines.stacking import StackingState
from chaingeo.envs.machines.state import BaseState
from chaingeo.envs.observation import (
    VIEWS,
    PieceMap,
    extra_image,
    extra_picture_of,
    render_state,
    scene,
    state_images,
)

Frame = npt.NDArray[np.uint8]
#: Bytes of pictures one :class:`FrameCache` keeps (about 40 positions at 256 px).
CACHE_BYTES: Final = 32 * 1024 * 1024


def picture_names(family: str) -> tuple[str, ...]:
    """The pictures of every observation of a family, in order: the four views, then ``tray``
    (stacking) or ``target`` (puzzles). Fixed per family, so a Gymnasium space can name them."""
    return (*VIEWS, extra_picture_of(family))


def _array(image: Image.Image) -> Frame:
    rgb = image if image.mode == "RGB" else image.convert("RGB")
    return np.array(rgb, dtype=np.uint8)


def _views(state: BaseState, size: int) -> dict[str, Frame]:
    pieces, box, _ = scene(state)
    return _draw_views(pieces, box, size)


def _draw_views(pieces: PieceMap, box: tuple[int, int, int] | None, size: int) -> dict[str, Frame]:
    import chaingeo.pictures.scene_kernel as scene_kernel

    return scene_kernel.render_arrays(pieces, box, VIEWS, size)


def _extra(state: BaseState, size: int, tray: PieceMap | None = None) -> Frame:
    """The tray (stacking: ``tray``, else the state's) or the target (puzzles), as
    :func:`render_state` draws it."""
    if isinstance(state, StackingState):
        from chaingeo.pictures.sheet import tray_pixels

        return tray_pixels(scene(state)[2] if tray is None else tray, size)
    return _array(extra_image(state, size))


def render_frames(state: BaseState, size: int) -> dict[str, Frame]:
    """Every picture of ``state`` as a ``(size, size, 3)`` array, named by
    :func:`picture_names`."""
    frames = _views(state, size)
    frames[picture_names(state.level.family)[-1]] = _extra(state, size)
    return frames


def decode_png(data: bytes) -> Frame:
    """The RGB pixels of PNG bytes."""
    with Image.open(io.BytesIO(data)) as img:
        return np.asarray(img.convert("RGB"), dtype=np.uint8).copy()


def reference_frames(state: BaseState, size: int) -> dict[str, Frame]:
    """:func:`render_frames` drawn by :mod:`chaingeo.pictures.scene` itself (the reference of
    :mod:`chaingeo.pictures.scene_kernel`: the same pixels, slower), no PNG."""
    return {v: _array(img) for v, img in state_images(state, size, reference=True).items()}


def png_frames(state: BaseState, size: int) -> dict[str, Frame]:
    """The same arrays the long way: encode every picture to PNG and decode it back (what the
    environments did before :func:`render_frames`; the benchmark's reference)."""
    return {v: decode_png(png) for v, png in render_state(state, size, reference=True).items()}


class FrameCache:
    """Recent pictures of one environment at one size, least recently used first out.

    :meth:`frames` returns fresh writable copies, so a caller may keep or change them."""

    def __init__(self, size: int, max_bytes: int = CACHE_BYTES) -> None:
        self.size = size
        self.capacity = max(3, max_bytes // (size * size * 3))  # in pictures
        self._store: OrderedDict[Hashable, tuple[Frame, ...]] = OrderedDict()
        self._pictures = 0
        self.hits = 0
        self.misses = 0

    def _get(self, key: Hashable, draw: Callable[[], tuple[Frame, ...]]) -> tuple[Frame, ...]:
        found = self._store.get(key)
        if found is not None:
            self._store.move_to_end(key)
            self.hits += 1
            return found
        self.misses += 1
        made = draw()
        for frame in made:
            frame.flags.writeable = False
        self._store[key] = made
        self._pictures += len(made)
        while self._pictures > self.capacity and len(self._store) > 1:
            _, old = self._store.popitem(last=False)
            self._pictures -= len(old)
        return made

    def frames(self, state: BaseState) -> dict[str, Frame]:
        """Every picture of ``state`` (as :func:`render_frames` draws them), copied."""
        level = state.level.id
        pieces, box, tray = scene(state)
        # Keyed by what is drawn, not by state.key(): a puzzle's key holds each part up to
        # translation, while the views draw (and label) where the largest part really is.
        drawn = tuple(sorted((n, shape.cells, str(color)) for n, (shape, color) in pieces.items()))
        views = self._get(
            ("views", level, box, drawn),
            lambda: tuple(_draw_views(pieces, box, self.size).values()),
        )
        if isinstance(state, StackingState):
            extra_key: Hashable = ("tray", level, tuple(sorted(state.tray)))
        else:
            extra_key = ("target", level)
        (extra,) = self._get(extra_key, lambda: (_extra(state, self.size, tray),))
        names = picture_names(state.level.family)
        return {n: f.copy() for n, f in zip(names, (*views, extra), strict=True)}

    def clear(self) -> None:
        """Forget every picture (levels were replaced under the same ids), and the layouts
        :mod:`chaingeo.pictures.scene_kernel` keeps in this process."""
        import chaingeo.pictures.scene_kernel as scene_kernel

        self._store.clear()
        self._pictures = 0
        scene_kernel.clear()
