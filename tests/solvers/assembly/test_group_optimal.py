"""o_i with BurrTools' piece groups: the plan replays to parts that are single pieces or all of
one group, and no shorter plan exists (the search with the plan's length as its budget finds
none)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from chaingeo.core.formats.burrtools import read_xmpuzzle
from chaingeo.core.kinematics import Move, replay_disassembly
from chaingeo.solvers.analysis import _stored_assembly, analyze
from chaingeo.solvers.assembly.btassemble import bt_packing_spec, piece_groups
from chaingeo.solvers.assembly.btcount import count_bt
from chaingeo.solvers.assembly.groups import GroupedSolver, PieceGroups, optimal_grouped
from chaingeo.solvers.cover.constrained import compile_packing
from chaingeo.solvers.limits import SearchLimits
from tests.solvers.bt_example_files import example
from tests.support.paths import ROOT


def _check(path: Path, steps: int) -> None:
    puzzle = read_xmpuzzle(path)
    found = _stored_assembly(puzzle, 0)
    if found is None:  # no stored assembly: the first solution the count meets
        packing = compile_packing(bt_packing_spec(puzzle, 0))
        first = count_bt(packing, mirrors="drop").first_packing
        assert first is not None
        found = first, piece_groups(packing)
    shapes, groups = found
    assert groups.any()
    best = optimal_grouped(shapes, groups, limits=SearchLimits(seconds=60))
    assert best.optimal_steps == len(best.plan) == steps
    end = replay_disassembly(shapes, [m for m in best.plan if isinstance(m, Move)])
    for part in end.parts:
        assert len(part) == 1 or groups.single_group(sorted(part))
    solver = GroupedSolver(shapes, groups, None, SearchLimits(seconds=60), separations="any")
    n = len(shapes)
    value, plan = solver.optimal(tuple(range(n)), np.zeros((n, 3), dtype=np.int64), steps)
    assert plan is None and value >= steps  # nothing shorter: the lower bound meets the plan


def test_linked_rings_o_i_with_a_group() -> None:
    _check(ROOT / "tests" / "data" / "burrtools" / "linked_rings.xmpuzzle", 2)


def test_cube_in_cage_o_i() -> None:
    """BurrTools' CubeInCage (level 4.9.3, 16 moves): the cage's three pieces are one group."""
    path = example("CubeInCage")
    _check(path, 16)
    figures = analyze(path, jobs=1)
    assert (figures.level, figures.optimal_steps, figures.convention) == ("4.9.3", 16, "burrtxt")


def test_classes_bound_the_removals() -> None:
    from chaingeo.core.geometry import Shape

    shapes = {n: Shape([(i, 0, 0)]) for i, n in enumerate("abcd")}
    groups = PieceGroups(
        {n: n for n in "abcd"}, {"a": ((1, 1),), "b": ((1, 1),), "c": (), "d": ((1, 1), (2, 1))}
    )
    solver = GroupedSolver(shapes, groups, None, SearchLimits())
    assert solver.min_removals((0, 1)) == 0  # a and b: one group
    assert solver.min_removals((0, 1, 2, 3)) == 2  # {a, b}, c, d (two groups: alone)


@pytest.mark.parametrize("name", ["linked_rings", "ring_maze"])
def test_group_files_report_o_i(name: str) -> None:
    figures = analyze(ROOT / "tests" / "data" / "burrtools" / f"{name}.xmpuzzle", jobs=1)
    assert figures.optimal_steps is not None and figures.optimal_error is None
    assert figures.optimal_steps <= (figures.moves or 0)
