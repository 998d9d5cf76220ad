"""Interlocking-puzzle generator: one pure function ``make(config, seed, index)``.

A candidate is a random design of a layout (:mod:`chaingeo.generator.layouts`: who owns each shared
cell of a burr, a plate burr or a chain of burr units), improved by hill climbing on single
voxels (give one shared cell to another slot), keeping a change when the puzzle still comes
apart and its (level, total moves) does not drop; or an interlocking partition of an n x n x n
cube (:mod:`chaingeo.generator.cubes`). The result is
accepted when it reaches ``min_level``; its optimal plan (o_i) is then computed exactly and the
level file is built and verified. Everything random comes from ``SeedSequence([seed, index])``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from chaingeo.core.colors import assign_colors
from chaingeo.core.geometry import Shape, connected, puzzle_signature
from chaingeo.core.kinematics import SearchLimitError
from chaingeo.core.level import (
    Difficulty,
    Level,
    Piece,
    Provenance,
    PuzzleSolution,
    default_step_budget,
    revalidate,
)
from chaingeo.core.registry import Registry
from chaingeo.core.rules import PuzzleRules
from chaingeo.generator.candidate import Candidate, evaluate
from chaingeo.generator.config import STANDARD_SHAPES, PuzzleConfig
from chaingeo.generator.cubes import cube_search, interlocking_target
from chaingeo.generator.deep import TOWERS, maze_candidate, tower_candidate
from chaingeo.generator.layouts import Layout, get_layout
from chaingeo.generator.maze import parse_maze_shape
from chaingeo.generator.result import GenerationRejection
from chaingeo.generator.standard_burr import standard_burr_search
from chaingeo.solvers.analysis import BLOCKS_KEY, analyze_puzzle
from chaingeo.solvers.limits import SearchLimits

GENERATOR = "chaingeo.generator.puzzle"
VERSION = "1"


def _repair(
    layout: Layout,
    design: list[int],
    options: Sequence[Sequence[int]],
    hole_rate: float,
    rng: np.random.Generator,
) -> None:
    """Give shared cells other owners, at most 400 times, until no piece is empty or falls
    apart; a change that leaves more such pieces is undone. A change touches two pieces only,
    so only theirs are checked again."""
    bad = [not connected(cells) for cells in layout.piece_cells(design)]
    for _ in range(400):
        if not any(bad):
            return
        i = int(rng.integers(len(design)))
        old = design[i]
        design[i] = _mutate(options[i], old, hole_rate, rng)
        cells = layout.piece_cells(design)
        after = list(bad)
        for owner in {old, design[i]} - {-1}:
            after[owner] = not connected(cells[owner])
        if sum(after) > sum(bad):
            design[i] = old
        else:
            bad = after


def _mutate(owners: Sequence[int], current: int, hole_rate: float, rng: np.random.Generator) -> int:
    """Another owner for one shared cell (or empty, when holes are allowed)."""
    choices = [o for o in (*owners, -1) if o != current and (o >= 0 or hole_rate > 0)]
    return int(choices[int(rng.integers(len(choices)))]) if choices else current


def _layout_search(config: PuzzleConfig, rng: np.random.Generator) -> Candidate | None:
    layout = get_layout(config.shape)
    shared = layout.shared
    options = [layout.owners(c) for c in shared]
    design = [
        -1 if rng.random() < config.hole_rate else int(opts[rng.integers(len(opts))])
        for opts in options
    ]
    best: Candidate | None = None
    for _ in range(40):  # repair towards connected pieces, then look for one that comes apart
        _repair(layout, design, options, config.hole_rate, rng)
        shapes = layout.pieces(design)
        result = evaluate(shapes, config)
        if result is not None:
            best = Candidate(shapes, result)
            break
        for _ in range(3):  # shake and retry
            i = int(rng.integers(len(design)))
            design[i] = _mutate(options[i], design[i], config.hole_rate, rng)
    if best is None:
        return None
    for _ in range(config.hill_steps):
        i = int(rng.integers(len(design)))
        old = design[i]
        design[i] = _mutate(options[i], old, config.hole_rate, rng)
        shapes = layout.pieces(design)
        result = evaluate(shapes, config)
        if result is not None and Candidate(shapes, result).score >= best.score:
            best = Candidate(shapes, result)
        else:
            design[i] = old
    return best


def difficulty_of(first_level: int, optimal_steps: int, pieces: int) -> Difficulty:
    """The suite's tiers (docs/guides/generating.md, 'The puzzle suite'), in the paper's sense:
    *easy* is few pieces and weak interlocking (at most 6 pieces, the first part free within 2
    moves, a plan of at most 8); *hard* is strong interlocking (5 or more moves before any part
    comes free), a long plan (20 or more moves), or many pieces that interlock (12 or more pieces
    and a first part needing 3 or more moves); *mid* is everything else, such as many loosely held
    pieces."""
    if first_level >= 5 or optimal_steps >= 20 or (pieces >= 12 and first_level >= 3):
        return "hard"
    if first_level <= 2 and optimal_steps <= 8 and pieces <= 6:
        return "easy"
    return "mid"


def puzzle_level(
    level_id: str,
    shapes: Sequence[Shape],
    *,
    goal: Literal["disassemble", "assemble"],
    max_group: int | None,
    limits: SearchLimits,
    seed: int | None = None,
    index: int | None = None,
    difficulty: Difficulty | None = None,
    extra_stats: dict[str, object] | None = None,
    blocks: Sequence[Sequence[int]] | None = None,
) -> Level:
    """Build and verify a puzzle level: palette names, the exact optimal plan (o_i) and stats.

    For 'assemble' the stored plan is the optimal disassembly reversed with each move inverted
    (the assembly optimum equals the disassembly optimum: the two state graphs are mirror
    images). Raises :class:`SearchLimitError` when o_i cannot be computed within ``limits``.
    ``blocks`` (indices into ``shapes``, a stack of units along z; single-piece moves only)
    proves o_i with the block bound of :mod:`chaingeo.solvers.optimal.blockbound` instead of
    searching; the level carries them (``stats["blocks"]``) so that
    :func:`chaingeo.solvers.analysis.analyze_level` analyses it the same way.
    """
    base = np.min(np.concatenate([s.voxels for s in shapes]), axis=0)
    placed = [s.translate(-base) for s in shapes]
    colors = assign_colors(len(placed))
    named = {c.name: s for c, s in zip(colors, placed, strict=True)}
    names = [c.name for c in colors]
    named_blocks = None if blocks is None else [[names[i] for i in b] for b in blocks]
    result = analyze_puzzle(named, max_group=max_group, limits=limits, blocks=named_blocks)
    if not result.disassemblable or result.optimal_steps is None:
        raise ValueError(f"{level_id}: the puzzle does not come apart")
    plan = list(result.plan)
    moves = plan if goal == "disassemble" else [m.inverse() for m in reversed(plan)]
    first = result.first_level or 0
    stats: dict[str, object] = {
        "level": result.level,
        "first_level": first,
        "moves": result.moves,
        "pieces": len(placed),
        "voxels": int(sum(len(s) for s in placed)),
        "states": result.states,
    }
    stats.update(extra_stats or {})
    if named_blocks is not None:
        stats[BLOCKS_KEY] = named_blocks
    level = Level(
        id=level_id,
        family="puzzle",
        difficulty=difficulty or difficulty_of(first, result.optimal_steps, len(placed)),
        goal=goal,
        box=None,
        pieces=tuple(Piece(c.name, c.hex, s) for c, s in zip(colors, placed, strict=True)),
        solution=PuzzleSolution(tuple(moves)),
        optimal_steps=result.optimal_steps,
        # Past 30 moves the benchmark's 60-step cap would leave no room: twice the optimum.
        max_steps=max(default_step_budget(result.optimal_steps), 2 * result.optimal_steps),
        rules=PuzzleRules(max_group=max_group),
        provenance=Provenance(GENERATOR, VERSION, seed, index, puzzle_signature(placed)),
        stats=stats,
    )
    return revalidate(level)


@dataclass(frozen=True)
class Built:
    """What a shape family's search found: the best candidate (None: nothing came apart), the
    blocks of a tower, and the family's own statistics for the level file."""

    best: Candidate | None
    blocks: list[list[int]] | None = None
    stats: dict[str, object] = field(default_factory=dict)


@dataclass(frozen=True)
class ShapeFamily:
    """The ``shape`` names a family builds (the first registered family that matches is used),
    how it searches, and how a search that found nothing is reported."""

    matches: Callable[[PuzzleConfig], bool]
    build: Callable[[PuzzleConfig, np.random.Generator], Built]
    failure: Callable[[PuzzleConfig], str]


def _standard(config: PuzzleConfig, rng: np.random.Generator) -> Built:
    outcome = standard_burr_search(config, rng)
    return Built(None) if outcome is None else Built(outcome.candidate, None, outcome.stats())


def _cube(config: PuzzleConfig, rng: np.random.Generator) -> Built:
    try:
        n = int(config.shape[4:])
    except ValueError:
        raise ValueError(f"cube shapes are cube3..cube5, got {config.shape!r}") from None
    return Built(cube_search(config, n, rng))


def _tower(config: PuzzleConfig, rng: np.random.Generator) -> Built:
    units = TOWERS[config.shape]
    blocks = [list(range(6 * u, 6 * u + 6)) for u in range(units)]
    return Built(tower_candidate(config, units, rng, _layout_search), blocks)


def _apart(config: PuzzleConfig) -> str:
    return "no design that comes apart"


def _standard_failure(config: PuzzleConfig) -> str:
    if config.unique or config.shape.endswith("u"):
        return "no design that comes apart and assembles uniquely"
    return _apart(config)


#: Puzzle shape families by name, tried in this order; ``layout`` takes every other name.
SHAPES: Registry[ShapeFamily] = Registry("puzzle shape family")
SHAPES.register(
    "standard", ShapeFamily(lambda c: c.shape in STANDARD_SHAPES, _standard, _standard_failure)
)
SHAPES.register(
    "cube",
    ShapeFamily(
        lambda c: c.shape.startswith("cube"),
        _cube,
        lambda c: f"no cube design comes apart at level {interlocking_target(c.min_level)} or more",
    ),
)
SHAPES.register(
    "maze",
    ShapeFamily(
        lambda c: c.shape.startswith("maze"),
        lambda c, rng: Built(maze_candidate(c, parse_maze_shape(c.shape), rng)),
        _apart,
    ),
)
SHAPES.register(
    "tower", ShapeFamily(lambda c: c.max_group == 1 and c.shape in TOWERS, _tower, _apart)
)
SHAPES.register(
    "layout", ShapeFamily(lambda c: True, lambda c, rng: Built(_layout_search(c, rng)), _apart)
)


def shape_family(config: PuzzleConfig) -> ShapeFamily:
    """The first registered family that builds ``config.shape``."""
    return next(family for _, family in SHAPES.items() if family.matches(config))


def make(config: PuzzleConfig, seed: int, index: int) -> Level | GenerationRejection:
    """Item ``index`` of ``seed``: a verified level, or why the candidate was rejected."""
    rng = np.random.default_rng(np.random.SeedSequence([seed, index]))
    family = shape_family(config)
    built = family.build(config, rng)
    best, blocks = built.best, built.blocks
    extra: dict[str, object] = {"shape": config.shape, **built.stats}
    if best is None:
        return GenerationRejection(family.failure(config), seed, index)
    if best.score[0] < config.min_level:
        return GenerationRejection(f"level {best.score[0]} below {config.min_level}", seed, index)
    limits = SearchLimits(
        max_states=config.max_states,
        seconds=config.seconds,
        max_total_states=config.max_total_states,
    )
    level_id = f"puzzle-{config.shape}-s{seed}-i{index}"
    try:
        return puzzle_level(
            level_id,
            best.shapes,
            goal=config.goal,
            max_group=config.max_group,
            limits=limits,
            seed=seed,
            index=index,
            extra_stats=extra,
            blocks=blocks,
        )
    except SearchLimitError as e:
        return GenerationRejection(f"optimal plan not found within limits: {e}", seed, index)
