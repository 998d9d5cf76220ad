"""Pictures written next to each generated level: the packed assembly and the piece tray.

The one place pictures are made, so switching to the project renderer (``chaingeo.render``)
touches nothing else. Until then: matplotlib voxels on the Agg canvas (no pyplot state, so
worker threads and processes can call it), PNG without a timestamp or version tag.
"""

from __future__ import annotations

import io
import math
from collections.abc import Mapping

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from mpl_toolkits.mplot3d.axes3d import Axes3D

from chaingeo.geometry import Shape
from chaingeo.level import Level, StackingSolution

PictureSet = dict[str, bytes]


def level_pictures(level: Level) -> PictureSet:
    """``{"assembly": png, "pieces": png}`` for a stacking level; puzzle levels show the
    assembled pieces as ``assembly`` only."""
    colours = {p.name: p.rgb for p in level.pieces}
    if isinstance(level.solution, StackingSolution):
        placed: Mapping[str, Shape] = level.solution.placements
        return {
            "assembly": _assembly_png(placed, colours, level.box, level.id),
            "pieces": _tray_png({p.name: p.shape for p in level.pieces}, colours),
        }
    return {"assembly": _assembly_png(level.shapes, colours, None, level.id)}


def _figure(width: float, height: float) -> Figure:
    fig = Figure(figsize=(width, height), dpi=100)
    FigureCanvasAgg(fig)
    return fig


def _draw(ax: Axes3D, shapes: Mapping[str, Shape], colours: Mapping[str, str]) -> None:
    cells = np.concatenate([s.voxels for s in shapes.values()])
    lo = cells.min(axis=0)
    size = cells.max(axis=0) - lo + 1
    filled = np.zeros(tuple(int(v) for v in size), dtype=bool)
    face = np.empty(filled.shape, dtype=object)
    for name, s in shapes.items():
        v = s.voxels - lo
        filled[v[:, 0], v[:, 1], v[:, 2]] = True
        face[v[:, 0], v[:, 1], v[:, 2]] = colours[name]
    ax.voxels(filled, facecolors=face, edgecolor="k", linewidth=0.5, shade=True)
    ax.set_box_aspect((int(size[0]), int(size[1]), int(size[2])))
    ax.set_axis_off()
    ax.view_init(elev=25, azim=-55)


def _png(fig: Figure) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    return buf.getvalue()


def _assembly_png(
    shapes: Mapping[str, Shape],
    colours: Mapping[str, str],
    box: tuple[int, int, int] | None,
    title: str,
) -> bytes:
    fig = _figure(5, 5)
    ax = fig.add_subplot(projection="3d")
    assert isinstance(ax, Axes3D)
    _draw(ax, shapes, colours)
    label = title if box is None else f"{title}  ({'x'.join(map(str, box))})"
    ax.set_title(label, fontsize=8)
    return _png(fig)


def _tray_png(shapes: Mapping[str, Shape], colours: Mapping[str, str]) -> bytes:
    n = len(shapes)
    cols = min(4, n)
    rows = math.ceil(n / cols)
    fig = _figure(2.4 * cols, 2.4 * rows)
    for k, (name, s) in enumerate(shapes.items(), start=1):
        ax = fig.add_subplot(rows, cols, k, projection="3d")
        assert isinstance(ax, Axes3D)
        _draw(ax, {name: s.normalized()}, colours)
        ax.set_title(name, fontsize=9)
    return _png(fig)
