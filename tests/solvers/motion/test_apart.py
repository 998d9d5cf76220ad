"""Groups that lie apart (:mod:`chaingeo.solvers.motion.apart`): a group stuck alone settles its
part, and the any-separation search says the same with that shortcut as without it, and as the
reference kinematics, on seeded puzzles made of two clusters set apart."""

from __future__ import annotations

import numpy as np
import pytest

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import reference_optimal_disassembly
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion import disassemble
from chaingeo.solvers.motion.apart import apart_groups
from chaingeo.solvers.motion.disassemble import Separation, _Solver
from chaingeo.solvers.motion.partsearch import PieceTable
from tests.support.puzzle_strategies import random_partition

#: States a part's search may take here (the plain search of a few cases meets it).
CAP = 3000


def closed_pair(cavity: int) -> dict[str, Shape]:
    """A closed tube with a cube in its cavity ``cavity`` cells long: neither ever comes out;
    with a cavity of 2 they walk off along x under single moves (the tube a step, then the
    cube) without end, with 1 nothing moves."""
    box = {(x, y, z) for x in range(2 + cavity) for y in range(3) for z in range(3)}
    cavity_cells = {(1 + i, 1, 1) for i in range(cavity)}
    return {"tube": Shape(sorted(box - cavity_cells)), "cube": Shape([(1, 1, 1)])}


def two_clusters(seed: int) -> dict[str, Shape]:
    """Two clusters set off along x by a gap of 0 to 2 cells (0: they touch, one group): small
    boxes cut into pieces (the first maybe one piece), the second one time in three a
    :func:`closed_pair` of either kind."""
    rng = np.random.default_rng(seed)
    shapes: dict[str, Shape] = {}
    shift = 0
    for c in range(2):
        kind = int(rng.integers(3)) if c == 1 else 0
        if kind:
            cut = closed_pair(kind)
        else:
            dims = (int(rng.integers(2, 4)), 2, int(rng.integers(1, 3)))
            pieces = int(rng.integers(1 if c == 0 else 2, 4))
            cut = random_partition(dims, pieces, int(rng.integers(2**32)))
        width = 0
        for name, shape in cut.items():
            shapes[f"c{c}{name}"] = Shape(shape.voxels + np.array([shift, 0, 0]))
            width = max(width, int(shape.voxels[:, 0].max()) + 1)
        shift += width + int(rng.integers(3))
    return shapes


def _tree(shapes: dict[str, Shape], max_group: int, apart: bool) -> Separation | str | None:
    """The any-separation tree of the Python search (the shortcut on or off), or a cap's text."""
    n = len(shapes)
    solver = _Solver(shapes, max_group, SearchLimits(max_states=CAP))
    mp = pytest.MonkeyPatch()
    if not apart:
        mp.setattr(_Solver, "stuck_apart", lambda *_: False)
    try:
        return solver.greedy(tuple(range(n)), np.zeros((n, 3), dtype=np.int64))
    except disassemble.SearchLimitError as e:
        return str(e)
    finally:
        mp.undo()


@pytest.mark.parametrize("seed", range(40))
def test_groups_apart_partition_the_part_and_cannot_touch(seed: int) -> None:
    shapes = two_clusters(seed)
    table = PieceTable(shapes)
    n = len(shapes)
    groups = apart_groups(table.lo, table.hi, tuple(range(n)), np.zeros((n, 3), dtype=np.int64))
    assert sorted(i for g in groups for i in g) == list(range(n))
    where = {i: k for k, g in enumerate(groups) for i in g}
    cells = [{tuple(v) for v in table.voxels[i].tolist()} for i in range(n)]
    steps = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    for i in range(n):
        near = {(x + a, y + b, z + c) for x, y, z in cells[i] for a, b, c in steps}
        for j in range(n):
            if where[i] != where[j]:
                assert not near & cells[j]


@pytest.mark.parametrize("seed", range(40))
@pytest.mark.parametrize("max_group", [1, 2])
def test_the_shortcut_keeps_every_verdict_and_tree(seed: int, max_group: int) -> None:
    shapes = two_clusters(seed)
    plain = _tree(shapes, max_group, apart=False)
    short = _tree(shapes, max_group, apart=True)
    if isinstance(plain, str):  # the plain search met its cap: the shortcut may decide
        assert short is None or short == plain
    else:
        assert short == plain
    if len(shapes) <= 4 and not isinstance(plain, str):
        ref = reference_optimal_disassembly(shapes, max_group, max_states=CAP)
        assert (ref is not None) == (plain is not None)
