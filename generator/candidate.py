"""One puzzle design under improvement, and the solver's verdict on it.

Shared by the layout search (:mod:`chaingeo.generator.puzzle`) and the cube search
(:mod:`chaingeo.generator.cubes`): a candidate is a list of pieces (assembled position) with the
BurrTools-style analysis of :func:`chaingeo.solvers.motion.disassemble.analyze_assembly`, scored by
(level,
total moves).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import SearchLimitError
from chaingeo.generator.config import PuzzleConfig
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.disassemble import Analysis, analyze_assembly
from chaingeo.solvers.motion.partsearch import PartSearch, PieceTable

Score = tuple[int, int]


class Candidate:
    """One puzzle being improved: its pieces and how well it scores."""

    def __init__(self, shapes: list[Shape], analysis: Analysis) -> None:
        self.shapes = shapes
        self.analysis = analysis

    @property
    def score(self) -> Score:
        a = self.analysis
        return (a.first_level or 0, a.moves or 0)


def probe_limits(config: PuzzleConfig) -> SearchLimits:
    """The caps of one evaluation while climbing (state caps: the same on every machine)."""
    return SearchLimits(
        max_states=config.probe_states,
        seconds=config.seconds,
        max_total_states=10 * config.probe_states,
    )


def probe_search(table: PieceTable, pieces: int, config: PuzzleConfig) -> PartSearch:
    """The breadth-first search of the whole assembly's configurations (every piece one part,
    at rest) under the probe caps, as the climbing generators score a design."""
    limits = probe_limits(config)
    return PartSearch(
        table,
        tuple(range(pieces)),
        np.zeros((pieces, 3), dtype=np.int64),
        max_group=config.max_group,
        limits=limits,
        deadline=Deadline(limits.seconds),
    )


def piece_names(shapes: Sequence[Shape]) -> dict[str, Shape]:
    """Working names ``p00, p01, ...`` (sorted like the pieces) for the solver."""
    return {f"p{i:02d}": s for i, s in enumerate(shapes)}


def evaluate(shapes: Sequence[Shape], config: PuzzleConfig) -> Analysis | None:
    """The BurrTools-style analysis, or None if a piece is broken or the puzzle is stuck."""
    if any(len(s) == 0 or not s.is_connected() for s in shapes):
        return None
    try:
        result = analyze_assembly(
            piece_names(shapes),
            max_group=config.max_group,
            limits=probe_limits(config),
            optimal=False,
            separations="any",  # the climb's score as it always was: the suite stays put
        )
    except SearchLimitError:
        return None
    return result if result.disassemblable else None
