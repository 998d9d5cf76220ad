"""The figures ``chain analyze`` prints for one puzzle, from a level file or a BurrTools file."""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

from chaingeo.geometry import Shape
from chaingeo.kinematics import SearchLimitError
from chaingeo.rules import PuzzleRules
from solvers.assemble import count_solutions
from solvers.disassemble import analyze
from solvers.partsearch import SearchLimits
from solvers.problem import PieceSpec


def disassembly_figures(
    shapes: Mapping[str, Shape],
    *,
    max_group: int | None,
    limits: SearchLimits,
    optimal: bool,
) -> dict[str, Any]:
    """``level``, ``moves`` and ``optimal_steps`` of one assembly (None where unknown); if the
    optimal search hits a cap, ``optimal_error`` says which."""
    out: dict[str, Any] = {}
    first = analyze(shapes, max_group=max_group, limits=limits, optimal=False)
    out.update(level=first.level, moves=first.moves, optimal_steps=None)
    if optimal and first.disassemblable:
        try:
            out["optimal_steps"] = analyze(
                shapes, max_group=max_group, limits=limits, optimal=True
            ).optimal_steps
        except SearchLimitError as e:
            out["optimal_error"] = str(e)
    return out


def analyze_level_file(
    path: str | os.PathLike[str], limits: SearchLimits, optimal: bool, assemble: bool
) -> dict[str, Any]:
    from chaingeo.level import load_level

    level = load_level(path)
    if level.family != "puzzle":
        raise ValueError(f"{path}: a {level.family} level; analyze takes puzzle levels")
    max_group = level.rules.max_group if isinstance(level.rules, PuzzleRules) else None
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
        disassembly_figures(level.shapes, max_group=max_group, limits=limits, optimal=optimal)
    )
    return out


def analyze_xmpuzzle(
    path: str | os.PathLike[str], problem: int, limits: SearchLimits, optimal: bool, assemble: bool
) -> dict[str, Any]:
    from chaingeo.formats.burrtools import read_xmpuzzle

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
