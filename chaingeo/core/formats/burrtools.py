"""BurrTools ``.xmpuzzle`` files (gzip-compressed XML), cube grid only: read and write.

One import for the whole format: the model (:mod:`chaingeo.core.formats.bt_model`: shapes
with colours and variable voxels, problems with part ranges, piece groups, colour rules and a
hole cap, stored solutions), the reader (:mod:`chaingeo.core.formats.bt_read`) and the writer
(:mod:`chaingeo.core.formats.bt_write`). A transform ``t < 24`` is the rotation
``ROTATIONS_BT[t]`` (applied as ``M @ v``, then shifted by ``(x, y, z)``); ``t >= 24`` is the
mirror through ``x = 0`` followed by rotation ``t - 24``. Anything else (another grid, a
malformed voxel string, a transform out of range, a size past :mod:`chaingeo.core.limits`)
raises :class:`BurrToolsError` naming the file and the element.
"""

from __future__ import annotations

from chaingeo.core.formats.bt_model import (
    MAX_COLORS,
    MIRROR_X,
    ROTATIONS_BT,
    TRANSFORMS_BT,
    BTPart,
    BTPlacement,
    BTProblem,
    BTPuzzle,
    BTShape,
    BTSolution,
    BurrToolsError,
    colored_shape,
)
from chaingeo.core.formats.bt_read import parse_xmpuzzle, read_xmpuzzle
from chaingeo.core.formats.bt_write import (
    assembled_puzzle,
    voxel_string,
    write_xmpuzzle,
    xmpuzzle_bytes,
    xmpuzzle_xml,
)

__all__ = [
    "MAX_COLORS",
    "MIRROR_X",
    "ROTATIONS_BT",
    "TRANSFORMS_BT",
    "BTPart",
    "BTPlacement",
    "BTProblem",
    "BTPuzzle",
    "BTShape",
    "BTSolution",
    "BurrToolsError",
    "assembled_puzzle",
    "colored_shape",
    "parse_xmpuzzle",
    "read_xmpuzzle",
    "voxel_string",
    "write_xmpuzzle",
    "xmpuzzle_bytes",
    "xmpuzzle_xml",
]
