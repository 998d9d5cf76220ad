"""Interlocking-puzzle generator: one pure function ``make(config, seed, index)``.

A candidate is a random design of a layout (:mod:`generator.layouts`: who owns each shared
cell of a burr, a plate burr or a chain of burr units), improved by hill climbing on single
voxels (give one shared cell to another slot), keeping a change when the puzzle still comes
apart and its (level, total moves) does not drop; or an interlocking partition of an n x n x n
cube (:mod:`generator.cubes`). The result is
accepted when it reaches ``min_level``; its optimal plan (o_i) is then computed exactly and the
level file is built and verified. Everything random comes from ``SeedSequence([seed, index])``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Literal

import numpy as np

from chaingeo.colors import assign_colors
from chaingeo.geometry import Shape, puzzle_signature
from chaingeo.kinematics import SearchLimitError
from chaingeo.level import (
    Difficulty,
    Level,
    Piece,
    Provenance,
    PuzzleSolution,
    default_step_budget,
    revalidate,
)
from chaingeo.rules import PuzzleRules
from generator.candidate import Candidate, evaluate
from generator.cubes import cube_search, interlocking_target
from generator.deep import TOWERS, maze_candidate, tower_candidate
from generator.layouts import get_layout
from generator.maze import parse_maze_shape
from generator.result import Rejection
from generator.standard_burr import STANDARD_DEFAULTS, STANDARD_SHAPES, standard_burr_search
from solvers.blockbound import analyze_by_blocks
from solvers.disassemble import Analysis, analyze
from solvers.partsearch import SearchLimits

GENERATOR = "chaingeo.generator.puzzle"
VERSION = "1"


@dataclass(frozen=True)
class PuzzleConfig:
    """What to make. ``shape``: a layout name (burr3, plate3, burr6, burr12, burr18, burr24,
    burr36), ``burr6x8`` / ``burr6x8u`` (Cutler's standard six-piece burr, 2x2x8 holey sticks;
    ``u``: unique assembly, :mod:`generator.standard_burr`), ``cubeN`` with ``pieces``, or
    ``mazeN`` (a maze burr on an N x N grid, the best of ``hill_steps`` walks); ``min_level``:
    moves until the first part comes free. Towers (burr12..burr36) with ``max_group=1`` are
    built unit by unit (:mod:`generator.deep`)."""

    shape: str = "burr6"
    min_level: int = 1
    pieces: int = 0  # cube partitions only
    hole_rate: float = 0.1  # chance a shared cell starts empty (0: solid burrs); cubes:
    # the share of inner cells left empty (at least one, see generator.cubes)
    hill_steps: int = 300  # improvement steps (cubes: steering one level deeper at a time)
    goal: Literal["disassemble", "assemble"] = "disassemble"
    max_group: int | None = None
    seconds: float | None = None  # optional time limit of each search (machine-dependent!)
    max_states: int = 500_000  # state cap per part in the final search
    max_total_states: int = 3_000_000  # state cap of the whole optimal-plan search
    probe_states: int = 20_000  # state cap of each evaluation while climbing (over: rejected)
    restarts: int = 2  # standard burrs (burr6x8): annealing runs of hill_steps changes each
    unique: bool = False  # standard burrs: keep only designs that assemble in exactly one way

    def __post_init__(self) -> None:
        # Standard burrs need many more holes and steps than the generic defaults: the CLI
        # passes --hole-rate / --hill-steps only when given, so a generic default here means
        # "not asked for" and becomes the family's own (generator.standard_burr.DEFAULTS).
        if self.shape in STANDARD_SHAPES:
            for name, value in STANDARD_DEFAULTS.items():
                if getattr(self, name) == _GENERIC_DEFAULTS[name]:
                    object.__setattr__(self, name, value)

    def to_json(self) -> dict[str, object]:
        return asdict(self)


_GENERIC_DEFAULTS: dict[str, object] = {"hole_rate": 0.1, "hill_steps": 300}


def _broken(shapes: Sequence[Shape]) -> int:
    return sum(1 for s in shapes if len(s) == 0 or not s.is_connected())


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
        for _ in range(400):
            broken = _broken(layout.pieces(design))
            if broken == 0:
                break
            i = int(rng.integers(len(design)))
            old = design[i]
            design[i] = _mutate(options[i], old, config.hole_rate, rng)
            if _broken(layout.pieces(design)) > broken:
                design[i] = old
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
    """The suite's thresholds (README, 'Puzzle suite'): *hard* when the first part needs 4 or
    more moves, or the optimal plan 14 or more, or there are 12 or more pieces; *easy* when the
    first part needs at most 2 moves, the plan at most 8 and there are at most 6 pieces; *mid*
    otherwise."""
    if first_level >= 4 or optimal_steps >= 14 or pieces >= 12:
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
    proves o_i with the block bound of :mod:`solvers.blockbound` instead of searching.
    """
    base = np.min(np.concatenate([s.voxels for s in shapes]), axis=0)
    placed = [s.translate(-base) for s in shapes]
    colors = assign_colors(len(placed))
    named = {c.name: s for c, s in zip(colors, placed, strict=True)}
    if blocks is None:
        result = analyze(named, max_group=max_group, limits=limits, optimal=True)
    else:
        if max_group != 1:
            raise ValueError("blocks prove o_i for single-piece moves (max_group=1) only")
        names = [c.name for c in colors]
        result = analyze_by_blocks(
            named,
            [[names[i] for i in b] for b in blocks],
            limits=limits,
            stacked=True,
            search=False,
        )
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


def analyze_level(level: Level, limits: SearchLimits | None = None) -> Analysis:
    """Analyse a puzzle level again as :func:`puzzle_level` did: towers made with single-piece
    moves (``stats['shape']`` in :data:`TOWERS`, ``max_group=1``) with the block bound, one
    block per unit of six pieces in file order; every other level with the plain search."""
    mg = level.rules.max_group if isinstance(level.rules, PuzzleRules) else None
    shapes = level.shapes
    if mg == 1 and level.stats.get("shape") in TOWERS:
        names = [p.name for p in level.pieces]
        blocks = [names[i : i + 6] for i in range(0, len(names), 6)]
        return analyze_by_blocks(shapes, blocks, limits=limits, stacked=True, search=False)
    return analyze(shapes, max_group=mg, limits=limits, optimal=True)


def make(config: PuzzleConfig, seed: int, index: int) -> Level | Rejection:
    """Item ``index`` of ``seed``: a verified level, or why the candidate was rejected."""
    rng = np.random.default_rng(np.random.SeedSequence([seed, index]))
    blocks: list[list[int]] | None = None
    extra: dict[str, object] = {"shape": config.shape}
    if config.shape in STANDARD_SHAPES:
        outcome = standard_burr_search(config, rng)
        best = None if outcome is None else outcome.candidate
        extra.update({} if outcome is None else outcome.stats())
    elif config.shape.startswith("cube"):
        try:
            n = int(config.shape[4:])
        except ValueError:
            raise ValueError(f"cube shapes are cube3..cube5, got {config.shape!r}") from None
        best = cube_search(config, n, rng)
    elif config.shape.startswith("maze"):
        best = maze_candidate(config, parse_maze_shape(config.shape), rng)
    elif config.max_group == 1 and config.shape in TOWERS:
        units = TOWERS[config.shape]
        best = tower_candidate(config, units, rng, _layout_search)
        blocks = [list(range(6 * u, 6 * u + 6)) for u in range(units)]
    else:
        best = _layout_search(config, rng)
    if best is None:
        if config.shape.startswith("cube"):
            target = interlocking_target(config.min_level)
            return Rejection(f"no cube design comes apart at level {target} or more", seed, index)
        if config.shape in STANDARD_SHAPES and (config.unique or config.shape.endswith("u")):
            return Rejection("no design that comes apart and assembles uniquely", seed, index)
        return Rejection("no design that comes apart", seed, index)
    if best.score[0] < config.min_level:
        return Rejection(f"level {best.score[0]} below {config.min_level}", seed, index)
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
        return Rejection(f"optimal plan not found within limits: {e}", seed, index)
