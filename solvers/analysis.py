"""One way to analyse a puzzle: the level (BurrTools' notation), the moves and o_i.

Everything that analyses a puzzle level goes through here: ``chain analyze``, the generator
(:func:`generator.puzzle.puzzle_level`), the suite tests and the bench. A level that carries
the structure a proven bound needs (``stats["blocks"]``: towers of burr units moved one piece
at a time) is analysed with the block bound of :mod:`solvers.blockbound`, everywhere; every
other puzzle with the plain optimal search of :mod:`solvers.disassemble`.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from typing import Any

from chaingeo.core.formats.burrtools import read_xmpuzzle
from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import SearchLimitError
from chaingeo.core.level import Level
from chaingeo.core.rules import PuzzleRules
from solvers.assemble import count_solutions
from solvers.blockbound import analyze_by_blocks
from solvers.disassemble import Analysis, Rods, analyze
from solvers.partsearch import SearchLimits
from solvers.problem import PieceSpec

#: The key of a level's ``stats`` naming the blocks of a tower (piece names, one list per unit
#: of a stack along z), written by the generator and read here.
BLOCKS_KEY = "blocks"


def level_blocks(level: Level) -> list[list[str]] | None:
    """The blocks a level carries for the block bound, or None. Raises ValueError when they are
    malformed or the level allows multi-piece moves (the bound holds for single-piece moves)."""
    raw = level.stats.get(BLOCKS_KEY)
    if raw is None:
        return None
    names = {p.name for p in level.pieces}
    if not isinstance(raw, list) or not all(
        isinstance(b, list) and b and all(isinstance(n, str) and n in names for n in b) for b in raw
    ):
        raise ValueError(f"{level.id}: stats.{BLOCKS_KEY} must be lists of piece names")
    if level_max_group(level) != 1:
        raise ValueError(f"{level.id}: blocks prove o_i for single-piece moves (max_group 1) only")
    return [list(b) for b in raw]


def level_max_group(level: Level) -> int | None:
    return level.rules.max_group if isinstance(level.rules, PuzzleRules) else None


def analyze_puzzle(
    shapes: Mapping[str, Shape],
    *,
    max_group: int | None,
    limits: SearchLimits | None = None,
    blocks: Sequence[Sequence[str]] | None = None,
    turns: bool = False,
    rods: Rods | None = None,
) -> Analysis:
    """Level, moves, o_i and an optimal plan of an assembled puzzle. With ``blocks`` (single-piece
    moves only) o_i is proven by the block bound instead of searched, and a
    :class:`SearchLimitError` says when no quick plan meets it. With ``turns`` groups may also
    turn (``rods``: the pieces' round rods)."""
    if blocks is not None:
        if max_group != 1 or turns:
            raise ValueError("blocks prove o_i for single-piece moves (max_group=1) only")
        return analyze_by_blocks(shapes, blocks, limits=limits, stacked=True, search=False)
    return analyze(shapes, max_group=max_group, limits=limits, optimal=True, turns=turns, rods=rods)


def level_turns(level: Level) -> bool:
    return isinstance(level.rules, PuzzleRules) and level.rules.turns


def analyze_level(level: Level, limits: SearchLimits | None = None) -> Analysis:
    """:func:`analyze_puzzle` of a puzzle level, with the blocks it carries."""
    if level.family != "puzzle":
        raise ValueError(f"{level.id}: a {level.family} level; only puzzles are analysed")
    return analyze_puzzle(
        level.shapes,
        max_group=level_max_group(level),
        limits=limits,
        blocks=level_blocks(level),
        turns=level_turns(level),
        rods=level.rods,
    )


def disassembly_figures(
    shapes: Mapping[str, Shape],
    *,
    max_group: int | None,
    limits: SearchLimits,
    optimal: bool,
    blocks: Sequence[Sequence[str]] | None = None,
    turns: bool = False,
    rods: Rods | None = None,
) -> dict[str, Any]:
    """``level``, ``moves`` and ``optimal_steps`` of one assembly (None where unknown); if the
    optimal search hits a cap, ``optimal_error`` says which (the level is still reported)."""
    out: dict[str, Any] = {}
    first = analyze(
        shapes, max_group=max_group, limits=limits, optimal=False, turns=turns, rods=rods
    )
    out.update(level=first.level, moves=first.moves, optimal_steps=None)
    if optimal and first.disassemblable:
        try:
            out["optimal_steps"] = analyze_puzzle(
                shapes, max_group=max_group, limits=limits, blocks=blocks, turns=turns, rods=rods
            ).optimal_steps
        except SearchLimitError as e:
            out["optimal_error"] = str(e)
    return out


def level_figures(
    level: Level, limits: SearchLimits, optimal: bool, assemble: bool
) -> dict[str, Any]:
    """What ``chain analyze`` prints for one of our puzzle levels."""
    if level.family != "puzzle":
        raise ValueError(f"{level.id}: a {level.family} level; analyze takes puzzle levels")
    max_group = level_max_group(level)
    out: dict[str, Any] = {"assemblies": None, "solutions": None}
    if assemble:
        target = Shape([c for p in level.pieces for c in p.shape.cells])
        rep = count_solutions(
            [PieceSpec(p.shape.normalized(), p.name) for p in level.pieces],
            target,
            max_group=max_group,
            limits=limits,
        )
        out.update(assemblies=rep.assemblies, solutions=rep.solutions)
    out.update(
        disassembly_figures(
            level.shapes,
            max_group=max_group,
            limits=limits,
            optimal=optimal,
            blocks=level_blocks(level),
            turns=level_turns(level),
            rods=level.rods,
        )
    )
    return out


def xmpuzzle_figures(
    path: str | os.PathLike[str], problem: int, limits: SearchLimits, optimal: bool, assemble: bool
) -> dict[str, Any]:
    """What ``chain analyze`` prints for one problem of a BurrTools file."""
    puzzle = read_xmpuzzle(path)
    prob = puzzle.problem(problem)
    out: dict[str, Any] = {"assemblies": None, "solutions": None}
    shapes: dict[str, Shape] | None = None
    if assemble:
        result = puzzle.shapes[prob.result]
        pieces = [
            PieceSpec(puzzle.shapes[sid].filled, f"s{sid}", lo, hi) for sid, lo, hi in prob.pieces
        ]
        rep = count_solutions(pieces, result.cells, optional=result.variable, limits=limits)
        out.update(assemblies=rep.assemblies, solutions=rep.solutions)
        shapes = rep.first_solution
    else:
        stored = puzzle.assemblies(problem)
        if stored:
            shapes = {f"p{slot}": s for slot, s in stored[0].items()}
    if shapes is None:
        out.update(level=None, moves=None, optimal_steps=None)
    else:
        out.update(disassembly_figures(shapes, max_group=None, limits=limits, optimal=optimal))
    return out
