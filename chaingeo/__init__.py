"""CHAIN-geo: exact discrete geometry for interlocking-puzzle and 3D-stacking benchmarks.

The public API, all from ``import chaingeo``::

    level = chaingeo.load_level("puzzle-easy-07-burr3")  # a shipped id or a level file
    state = chaingeo.new_state(level)                    # the state machine at the start
    figures = chaingeo.analyze(level)                    # level, moves, o_i (PuzzleFigures)
    chaingeo.count_packings(pieces, (3, 3, 3))           # exact cover
    puzzle = chaingeo.read_burrtools("file.xmpuzzle")    # BurrTools' files

Every name is imported on first use (PEP 562, :mod:`chaingeo.core.lazy`), so ``import
chaingeo`` loads neither numpy nor numba: a script pays only for what it touches.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Final

from chaingeo.core.lazy import lazy_exports

__version__ = "0.1.0"

if TYPE_CHECKING:  # the real types for mypy and editors; at run time see _LAZY
    from chaingeo.core.errors import ChainGeoError
    from chaingeo.core.formats.burrtools import BTPuzzle
    from chaingeo.core.formats.burrtools import read_xmpuzzle as read_burrtools
    from chaingeo.core.geometry import Shape
    from chaingeo.core.level import Level
    from chaingeo.core.piecesets import PIECESETS
    from chaingeo.core.suite import EXAMPLES, UnknownLevelError, load_level, shipped_levels
    from chaingeo.envs.machines import new_state
    from chaingeo.envs.observation import Observation, observe
    from chaingeo.solvers.analysis import analyze
    from chaingeo.solvers.cover.packings import count_packings, iter_packings
    from chaingeo.solvers.figures import PuzzleFigures
    from chaingeo.solvers.limits import SearchLimits

#: Public name -> "module:attribute".
_LAZY: Final = {
    "BTPuzzle": "chaingeo.core.formats.burrtools:BTPuzzle",
    "ChainGeoError": "chaingeo.core.errors:ChainGeoError",
    "EXAMPLES": "chaingeo.core.suite:EXAMPLES",
    "Level": "chaingeo.core.level:Level",
    "Observation": "chaingeo.envs.observation:Observation",
    "PIECESETS": "chaingeo.core.piecesets:PIECESETS",
    "PuzzleFigures": "chaingeo.solvers.figures:PuzzleFigures",
    "SearchLimits": "chaingeo.solvers.limits:SearchLimits",
    "Shape": "chaingeo.core.geometry:Shape",
    "UnknownLevelError": "chaingeo.core.suite:UnknownLevelError",
    "analyze": "chaingeo.solvers.analysis:analyze",
    "count_packings": "chaingeo.solvers.cover.packings:count_packings",
    "iter_packings": "chaingeo.solvers.cover.packings:iter_packings",
    "load_level": "chaingeo.core.suite:load_level",
    "new_state": "chaingeo.envs.machines:new_state",
    "observe": "chaingeo.envs.observation:observe",
    "read_burrtools": "chaingeo.core.formats.burrtools:read_xmpuzzle",
    "shipped_levels": "chaingeo.core.suite:shipped_levels",
}

__all__ = [
    "EXAMPLES",
    "PIECESETS",
    "BTPuzzle",
    "ChainGeoError",
    "Level",
    "Observation",
    "PuzzleFigures",
    "SearchLimits",
    "Shape",
    "UnknownLevelError",
    "__version__",
    "analyze",
    "count_packings",
    "iter_packings",
    "load_level",
    "new_state",
    "observe",
    "read_burrtools",
    "shipped_levels",
]

if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, _LAZY)
