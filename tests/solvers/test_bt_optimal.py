"""o_i of BurrTools' own designs (``$CHAIN_BURRTOOLS_EXAMPLES``; skipped without them): an
integer within ``chain analyze``'s default limits, the plan replays to every piece apart, and
the search asked for anything shorter proves there is none (the lower bound meets the plan).
CubeInCage, whose cage is a piece group, is checked in tests/solvers/assembly."""

from __future__ import annotations

import numpy as np
import pytest

from chaingeo.core.formats.burrtools import read_xmpuzzle
from chaingeo.core.kinematics import replay_disassembly
from chaingeo.solvers.analysis import _stored_assembly, analyze
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.disassemble import _Solver, analyze_assembly, translations
from tests.solvers.bt_example_files import example

#: File, BurrTools' level, o_i.
DESIGNS = [
    ("PelikanBurr", "98.2.4.2", 107),
    ("DraculasDentalDesaster", "3.5.16.6.4", 37),
    ("AlPackino", "1.1.1.1.1.2.1.3.1.2.1.2", 17),
]


@pytest.mark.slow
@pytest.mark.parametrize(("name", "level", "steps"), DESIGNS)
def test_o_i_replays_and_meets_its_bound(name: str, level: str, steps: int) -> None:
    found = _stored_assembly(read_xmpuzzle(example(name)), 0)
    assert found is not None
    shapes, groups = found
    assert not groups.any()
    best = analyze_assembly(shapes, limits=SearchLimits(seconds=60))
    assert (best.level, best.optimal_steps, len(best.plan)) == (level, steps, steps)
    assert replay_disassembly(shapes, translations(best.plan)).is_separated()
    solver = _Solver(shapes, None, SearchLimits(seconds=60))
    n = len(shapes)
    value, plan = solver.optimal(tuple(range(n)), np.zeros((n, 3), dtype=np.int64), steps)
    assert plan is None and value >= steps  # nothing shorter


@pytest.mark.slow
@pytest.mark.parametrize(("name", "level", "steps"), DESIGNS)
def test_chain_analyze_gives_o_i_by_default(name: str, level: str, steps: int) -> None:
    figures = analyze(example(name), jobs=1)
    assert (figures.level, figures.optimal_steps, figures.optimal_error) == (level, steps, None)
