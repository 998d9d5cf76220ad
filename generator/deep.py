"""Deep and large generated puzzles: maze burrs (level grows with the maze) and towers of burr
units played with single-piece moves (o_i proven by the block bound).

Both give :class:`chaingeo.generator.candidate.Candidate` objects to
:func:`chaingeo.generator.puzzle.make`, which builds and verifies the level like any other.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace

import numpy as np

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import Move, SearchLimitError
from chaingeo.generator.candidate import Candidate, evaluate
from chaingeo.generator.config import PuzzleConfig
from chaingeo.generator.maze import maze_search, runs, with_exit
from chaingeo.solvers.motion.disassemble import analyze_assembly, translations

#: Towers of burr units; with single-piece moves (max_group=1) they are built unit by unit and
#: their o_i is proven with the block bound (:mod:`chaingeo.solvers.optimal.blockbound`), one block
#: per unit.
TOWERS = {"burr12": 2, "burr18": 3, "burr24": 4, "burr36": 6}

UnitSearch = Callable[[PuzzleConfig, np.random.Generator], Candidate | None]


def maze_candidate(config: PuzzleConfig, n: int, rng: np.random.Generator) -> Candidate | None:
    """A maze burr (:mod:`chaingeo.generator.maze`): ``hill_steps`` random walks, the one with the
    most straight runs kept; its level is measured by the solver and must equal the runs."""
    found = maze_search(n, config.min_level, config.hill_steps, rng)
    if found is None:
        return None
    path, plate, pin = found
    result = evaluate([plate, pin], config)
    if result is None or result.first_level != runs(with_exit(path, n)):
        raise RuntimeError(f"maze construction broken: runs {runs(with_exit(path, n))}, {result}")
    return Candidate([plate, pin], result)


def last_piece(plan: Sequence[Move], n: int) -> str | None:
    """The piece ``p0..p{n-1}`` that a full single-piece plan never moves (it is left alone at
    the end), or None when there is not exactly one."""
    moved = {p for m in plan for p in m.pieces}
    left = [f"p{i}" for i in range(n) if f"p{i}" not in moved]
    return left[0] if len(left) == 1 else None


def tower_candidate(
    config: PuzzleConfig, units: int, rng: np.random.Generator, unit_search: UnitSearch
) -> Candidate | None:
    """A tower of ``units`` burr units (layout ``burr{6*units}``), each unit designed and
    climbed on its own as a six-piece burr by ``unit_search`` (the units share no cells), then
    stacked. A unit is kept when its optimal plan never moves down and leaves one of its
    z-sticks (slots 4, 5) unmoved to the end, so that the tower can be taken apart unit by unit
    from the top in the block bound's number of moves, each unit's last piece touching the unit
    below as it leaves (:mod:`chaingeo.solvers.optimal.blockbound`)."""
    unit_config = replace(config, shape="burr6", min_level=1)
    shapes: list[Shape] = []
    for u in range(units):
        for _ in range(60):  # a unit whose optimal plan lets it leave the top of the stack
            unit = unit_search(unit_config, rng)
            if unit is None:
                continue
            named = {f"p{i}": s for i, s in enumerate(unit.shapes)}
            try:
                plan = translations(analyze_assembly(named, max_group=1, optimal=True).plan)
            except SearchLimitError:
                continue
            down = any(m.direction == "-z" for m in plan)
            if down or last_piece(plan, len(named)) not in ("p4", "p5"):
                continue
            shapes.extend(s.translate((0, 0, 6 * u)) for s in unit.shapes)
            break
        else:
            return None
    result = evaluate(shapes, replace(config, probe_states=config.max_states))
    return None if result is None else Candidate(shapes, result)
