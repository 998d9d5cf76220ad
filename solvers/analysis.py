"""One way to analyse a puzzle: the level (BurrTools' notation), the moves and o_i.

Everything that analyses a puzzle level goes through here: ``chain analyze``, the generator
(:func:`chaingeo.generator.puzzle.puzzle_level`), the suite tests and the bench. A level that
carries the structure a proven bound needs (``stats["blocks"]``: towers of burr units) is analysed
with it, everywhere: the block bound of :mod:`chaingeo.solvers.optimal.blockbound` for moves of one
piece, the search under the class bound of :mod:`chaingeo.solvers.optimal.classsearch` for moves of
several; every other puzzle with the plain optimal search of
:func:`chaingeo.solvers.motion.disassemble.analyze_assembly`.

*Time*: ``limits.seconds`` bounds one whole analysis. :func:`analyze` (``chain analyze``,
:func:`chaingeo.analyze`) makes one :class:`chaingeo.solvers.deadline.Deadline` and hands it to
everything it runs (the enumeration of assemblies, every disassembly, the optimal search), so
the whole command stops with a :class:`SearchLimitError` naming ``seconds`` once it is spent (a
spent optimal search alone is reported as ``optimal_error``).
"""

from __future__ import annotations

import os
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Final

from chaingeo.core.errors import ChainGeoError
from chaingeo.core.formats.burrtools import BTPuzzle, read_xmpuzzle
from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import SearchLimitError
from chaingeo.core.rules import PuzzleRules
from chaingeo.solvers.assembly.btassemble import Mirrors, bt_packing_spec, piece_groups
from chaingeo.solvers.assembly.btcount import BTReport, count_bt
from chaingeo.solvers.assembly.groups import (
    RULE_TWO,
    PieceGroups,
    analyze_grouped,
    optimal_grouped,
)
from chaingeo.solvers.cover.constrained import Packing, compile_packing
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.figures import PuzzleFigures
from chaingeo.solvers.jobs import Farm
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.disassemble import (
    Analysis,
    OptimalLimitError,
    Rods,
    analyze_assembly,
)
from chaingeo.solvers.motion.kinematics_kernel import MAX_PIECES

if TYPE_CHECKING:  # a BurrTools file needs neither the level reader nor its imports
    from chaingeo.core.level import Level

__all__ = [
    "DEFAULT_LIMITS",
    "NotAPuzzleError",
    "PuzzleFigures",
    "RowOptions",
    "analyze",
    "analyze_level",
    "analyze_puzzle",
    "level_analysis_row",
    "problem_analysis_row",
]


class NotAPuzzleError(ChainGeoError, ValueError):
    """A stacking level given to the analysis, which takes puzzles only."""


#: The key of a level's ``stats`` naming the blocks of a tower (piece names, one list per unit
#: of a stack along z), written by the generator and read here.
BLOCKS_KEY = "blocks"


def level_blocks(level: Level) -> list[list[str]] | None:
    """The blocks a level carries for a proven bound, or None (the block bound for single-piece
    moves, the class search otherwise). Raises ValueError when they are malformed."""
    raw = level.stats.get(BLOCKS_KEY)
    if raw is None:
        return None
    names = {p.name for p in level.pieces}
    if not isinstance(raw, list) or not all(
        isinstance(b, list) and b and all(isinstance(n, str) and n in names for n in b) for b in raw
    ):
        raise ValueError(f"{level.id}: stats.{BLOCKS_KEY} must be lists of piece names")
    if sorted(n for b in raw for n in b) != sorted(names):
        raise ValueError(f"{level.id}: stats.{BLOCKS_KEY} must hold every piece exactly once")
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
    deadline: Deadline | None = None,
) -> Analysis:
    """Level, moves, o_i and an optimal plan of an assembled puzzle. With ``blocks`` o_i is proven
    with them: for single-piece moves by the block bound instead of searched (a
    :class:`SearchLimitError` says when no quick plan meets it), else by the class search.
    With ``turns`` groups may also turn (``rods``: the pieces' round rods). ``deadline``:
    shared with the caller's other searches (default: one of ``limits.seconds``)."""
    if blocks is not None and turns:
        raise ValueError("blocks prove o_i for translations only, not with turns")
    if blocks is not None and max_group != 1:
        from chaingeo.solvers.optimal.classsearch import (
            analyze_by_classes,  # levels with blocks only
        )

        return analyze_by_classes(
            shapes, blocks, max_group=max_group, limits=limits, deadline=deadline
        )
    if blocks is not None:
        from chaingeo.solvers.optimal.blockbound import analyze_by_blocks  # levels with blocks only

        return analyze_by_blocks(
            shapes, blocks, limits=limits, stacked=True, search=False, deadline=deadline
        )
    return analyze_assembly(
        shapes,
        max_group=max_group,
        limits=limits,
        optimal=True,
        turns=turns,
        rods=rods,
        deadline=deadline,
    )


def level_turns(level: Level) -> bool:
    return isinstance(level.rules, PuzzleRules) and level.rules.turns


def analyze_level(level: Level, limits: SearchLimits | None = None) -> Analysis:
    """:func:`analyze_puzzle` of a puzzle level, with the blocks it carries."""
    if level.family != "puzzle":
        raise NotAPuzzleError(f"{level.id}: a {level.family} level; only puzzles are analysed")
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
    deadline: Deadline | None = None,
) -> dict[str, Any]:
    """``level``, ``moves`` and ``optimal_steps`` of one assembly (None where unknown); if the
    optimal search hits a cap, ``optimal_error`` says which (the level is still reported); an
    assembly of more pieces than the search kernels take is reported unsearched, with
    ``disassembly_error`` saying why. ``deadline``: the analysis' one (default: one of
    ``limits.seconds`` for both searches)."""
    if len(shapes) > MAX_PIECES:
        return {
            "level": None,
            "moves": None,
            "optimal_steps": None,
            "disassembly_error": f"{len(shapes)} pieces in one part; the disassembler "
            f"searches parts of at most {MAX_PIECES} pieces",
        }
    out: dict[str, Any] = {}
    if deadline is None:
        deadline = Deadline(limits.seconds)
    deadline.progress.stage = "taking the assembly apart"
    first = analyze_assembly(
        shapes,
        max_group=max_group,
        limits=limits,
        optimal=False,
        turns=turns,
        rods=rods,
        deadline=deadline,
    )
    out.update(level=first.level, moves=first.moves, optimal_steps=None)
    if optimal and first.disassemblable:
        out.update(
            optimal_figures(
                shapes,
                max_group=max_group,
                limits=limits,
                deadline=deadline,
                stage="searching for the optimal plan",
                blocks=blocks,
                turns=turns,
                rods=rods,
            )
        )
    return out


def optimal_figures(
    shapes: Mapping[str, Shape],
    *,
    max_group: int | None,
    limits: SearchLimits,
    deadline: Deadline,
    stage: str,
    blocks: Sequence[Sequence[str]] | None = None,
    turns: bool = False,
    rods: Rods | None = None,
    groups: PieceGroups | None = None,
) -> dict[str, Any]:
    """``optimal_steps`` and ``plan`` of an assembly known to come apart (with ``groups``:
    under BurrTools' group rule, :func:`chaingeo.solvers.assembly.groups.optimal_grouped`),
    searched within ``limits.optimal_seconds`` of ``deadline``; past a cap,
    :func:`optimal_error_of`'s entries instead."""
    deadline.progress.stage = stage
    within = deadline.within(limits.optimal_seconds, "optimal_seconds")
    try:
        if groups is not None:
            best = optimal_grouped(
                shapes, groups, max_group=max_group, limits=limits, deadline=within
            )
        else:
            best = analyze_puzzle(
                shapes,
                max_group=max_group,
                limits=limits,
                blocks=blocks,
                turns=turns,
                rods=rods,
                deadline=within,
            )
    except SearchLimitError as e:
        return optimal_error_of(e)
    if best.optimal_steps is None:
        return {"optimal_error": RULE_TWO}
    return {"optimal_steps": best.optimal_steps, "plan": best.plan}


@dataclass(frozen=True)
class RowOptions:
    """What one row of figures runs under (a level's or a BurrTools problem's): the caps,
    whether to search o_i and count assemblies, the mirror convention, the time (default: one
    of ``limits.seconds``) and the counting processes."""

    limits: SearchLimits
    optimal: bool = True
    assemble: bool = True
    mirrors: Mirrors = "drop"
    deadline: Deadline | None = None
    jobs: int | Farm | None = 1

    def clock(self) -> Deadline:
        """The row's deadline: the one given, or a new one of ``limits.seconds``."""
        return Deadline(self.limits.seconds) if self.deadline is None else self.deadline


def level_analysis_row(level: Level, how: RowOptions) -> dict[str, Any]:
    """The figures of one of our puzzle levels (a dict, with ``plan``): BurrTools' assemblies and
    solutions of the level written as a BurrTools file (:func:`level_puzzle`: each piece its
    own shape, so the counts are burrTxt's on that file, whatever the level's ``max_group``), then
    level, moves and o_i of the level's own assembly under its rules. All of it within
    ``deadline`` (default: one of ``limits.seconds``); counts cut short by a cap are kept as
    lower bounds (see :func:`count_figures`)."""
    if level.family != "puzzle":
        raise NotAPuzzleError(f"{level.id}: a {level.family} level; analyze takes puzzle levels")
    limits, optimal, mirrors, jobs = how.limits, how.optimal, how.mirrors, how.jobs
    deadline = how.clock()
    max_group = level_max_group(level)
    out: dict[str, Any] = {"assemblies": None, "solutions": None}
    if how.assemble:
        packing = level_packing(level)
        rep = count_figures(packing, out, mirrors, limits, deadline, "", jobs)
        deadline = deadline if rep.complete else grace_deadline(limits)
    out.update(
        disassembly_figures(
            level.shapes,
            max_group=max_group,
            limits=limits,
            optimal=optimal,
            blocks=level_blocks(level),
            turns=level_turns(level),
            rods=level.rods,
            deadline=deadline,
        )
    )
    return out


def level_packing(level: Level) -> Packing:
    """A level as BurrTools' assembler sees it: the level written as a BurrTools file
    (:func:`chaingeo.core.formats.bt_level.level_puzzle`, each piece its own shape)."""
    from chaingeo.core.formats.bt_level import level_puzzle

    return compile_packing(bt_packing_spec(level_puzzle(level), 0))


def optimal_error_of(e: SearchLimitError) -> dict[str, Any]:
    """The figures' entries for an optimal search stopped by a cap: ``optimal_error`` (the
    reason), ``optimal_limit_cap`` (the field of ``SearchLimits`` reached, for a front end
    to name its own option: ``chain analyze`` names the flag and drops this key) and, when the
    search proved them, ``optimal_bounds`` ``(lo, hi)`` with ``lo <= o_i <= hi``."""
    out: dict[str, Any] = {"optimal_error": e.reason, "optimal_limit_cap": e.cap}
    if isinstance(e, OptimalLimitError):
        out["optimal_bounds"] = (e.lo, e.hi)
    return out


#: Seconds the figures of a known assembly get when counting spent the analysis' time.
GRACE_SECONDS = 10.0


def grace_deadline(limits: SearchLimits) -> Deadline:
    """The time the level, moves and o_i of a known assembly get after counting was cut short
    (the analysis' own time is spent): at most :data:`GRACE_SECONDS`."""
    seconds = GRACE_SECONDS if limits.seconds is None else min(GRACE_SECONDS, limits.seconds)
    return Deadline(seconds)


#: The name the figures give each way of counting mirror images (``convention``): burrTxt's
#: (BurrTools' command-line solver, the default: an assembly and its mirror image are one) or
#: BurrTools' stored figures (its GUI's "keep mirror solutions").
CONVENTIONS: Final[dict[str, str]] = {"drop": "burrtxt", "keep": "mirrors-kept"}


def count_figures(
    packing: Packing,
    out: dict[str, Any],
    mirrors: Mirrors,
    limits: SearchLimits,
    deadline: Deadline,
    label: str,
    jobs: int | Farm | None = 1,
) -> BTReport:
    """Count BurrTools' assemblies and solutions into ``out``; a cap reached ends the count,
    and ``out`` then says so: ``counts_complete`` false, the counts lower bounds, ``limit``
    the cap's reason and ``limit_cap`` the field of ``SearchLimits`` it names. Every assembly
    is judged by BurrTools' rules (groups of any size move): a level's ``max_group`` is not in
    its BurrTools file, and judging the first assembly by it, the rest by the file, mixed two
    rules (and, where a capped part never comes apart, searched without end)."""
    deadline.progress.stage = f"{label}counting assemblies"
    rep = count_bt(
        packing,
        mirrors=mirrors,
        limits=limits,
        deadline=deadline,
        partial=True,
        jobs=jobs,
    )
    out.update(assemblies=rep.assemblies, solutions=rep.solutions, convention=CONVENTIONS[mirrors])
    if rep.limit is not None:
        out.update(counts_complete=False, limit=rep.limit.reason, limit_cap=rep.limit.cap)
    return rep


def _stored_assembly(puzzle: BTPuzzle, index: int) -> tuple[dict[str, Shape], PieceGroups] | None:
    """The first stored assembly of a problem (pieces ``p<slot>``) and its pieces' groups."""
    stored = puzzle.assemblies(index)
    if not stored:
        return None
    prob = puzzle.problem(index)
    part_of = [k for k, p in enumerate(prob.parts) for _ in range(p.max)]
    # Named so that sorted names are slot order: BurrTools searches the pieces in that order.
    shapes = {f"p{slot:04d}": s for slot, s in stored[0].items()}
    shape_of = {n: f"part{part_of[int(n[1:])]}" for n in shapes}
    groups_of = {n: prob.parts[part_of[int(n[1:])]].groups for n in shapes}
    return shapes, PieceGroups(shape_of, groups_of)


def problem_analysis_row(puzzle: BTPuzzle, index: int, how: RowOptions) -> dict[str, Any]:
    """The figures of one problem of a BurrTools puzzle (a dict, with ``plan``): BurrTools'
    assemblies and solutions (``mirrors``: see :mod:`chaingeo.solvers.assembly.btassemble`), then
    level, moves and o_i of the first solution (with ``assemble`` off: of the first stored
    assembly); with piece groups o_i under BurrTools' group rule. Everything runs
    within ``deadline`` (default: one of ``limits.seconds``)."""
    limits, optimal, mirrors, jobs = how.limits, how.optimal, how.mirrors, how.jobs
    deadline = how.clock()
    prob = puzzle.problem(index)
    out: dict[str, Any] = {"problem": index, "name": prob.name}
    out.update(assemblies=None, solutions=None)
    found: tuple[dict[str, Shape], PieceGroups] | None = None
    first: Analysis | None = None
    if how.assemble:
        packing = compile_packing(bt_packing_spec(puzzle, index))
        rep = count_figures(packing, out, mirrors, limits, deadline, f"problem {index}: ", jobs)
        if rep.first_packing is not None:
            found, first = (rep.first_packing, piece_groups(packing)), rep.first_analysis
        if not rep.complete:
            deadline = grace_deadline(limits)
            found = found or _stored_assembly(puzzle, index)
    else:
        found = _stored_assembly(puzzle, index)
    if found is None:
        out.update(level=None, moves=None, optimal_steps=None)
        return out
    shapes, groups = found
    if groups.any():
        result = first or analyze_grouped(shapes, groups, limits=limits, deadline=deadline)
        out.update(level=result.level, moves=result.moves, optimal_steps=None)
        if optimal and result.disassemblable:
            stage = f"problem {index}: searching for the optimal plan"
            out.update(
                optimal_figures(
                    shapes,
                    max_group=None,
                    limits=limits,
                    deadline=deadline,
                    stage=stage,
                    groups=groups,
                )
            )
    elif first is None:
        out.update(
            disassembly_figures(
                shapes, max_group=None, limits=limits, optimal=optimal, deadline=deadline
            )
        )
    else:  # the level is known: the assembler's disassembler found it
        out.update(level=first.level, moves=first.moves, optimal_steps=None)
        if optimal:
            stage = f"problem {index}: searching for the optimal plan"
            out.update(
                optimal_figures(
                    shapes, max_group=None, limits=limits, deadline=deadline, stage=stage
                )
            )
    return out


#: The caps :func:`analyze` uses by default: ``chain analyze``'s (120 s for the whole analysis,
#: 10 s of it for o_i, 2,000,000 states per part).
DEFAULT_LIMITS: Final = SearchLimits(optimal_seconds=10.0)


def analyze(
    source: Level | BTPuzzle | str | os.PathLike[str],
    *,
    limits: SearchLimits | None = None,
    problem: int | None = None,
    optimal: bool = True,
    assemble: bool = True,
    mirrors: Mirrors = "drop",
    deadline: Deadline | None = None,
    jobs: int | None = None,
    scheduler: str | None = None,
) -> PuzzleFigures:
    """Assemblies, solutions, level, moves and o_i of a puzzle, as ``chain analyze`` prints
    them (:meth:`PuzzleFigures.to_json`).

    ``source``: a :class:`~chaingeo.core.level.Level`, a level file or shipped level id, a
    ``.xmpuzzle`` file or a read :class:`BTPuzzle`. ``problem``: the problem of a BurrTools
    puzzle (default: its only one, or every one in ``problems``; ignored for levels).
    ``optimal`` / ``assemble``: search o_i / count assemblies. ``mirrors``: see
    :mod:`chaingeo.solvers.assembly.btassemble`. Everything runs within ``deadline`` (default:
    one of ``limits.seconds``; ``limits`` default :data:`DEFAULT_LIMITS`). ``jobs``: worker
    processes for the counts (None: the machine's cores), or ``scheduler``: the address of a
    Dask cluster that does them; the figures do not depend on either."""
    from chaingeo.kernels.jit import mode
    from chaingeo.solvers.jobs import as_farm

    farm = as_farm(jobs, scheduler)
    limits = DEFAULT_LIMITS if limits is None else limits
    deadline = Deadline(limits.seconds) if deadline is None else deadline
    start = time.perf_counter()
    file = os.fspath(source) if isinstance(source, str | os.PathLike) else None
    if file is not None and file.endswith(".xmpuzzle"):
        source = read_xmpuzzle(file)
    several = False
    how = RowOptions(limits, optimal, assemble, mirrors, deadline, farm)
    if isinstance(source, BTPuzzle):
        several = problem is None and len(source.problems) != 1
        rows = _puzzle_rows(source, problem, how)
    else:
        from chaingeo.core.suite import load_level

        level = load_level(source) if isinstance(source, str | os.PathLike) else source
        rows = [level_analysis_row(level, how)]
    meta: dict[str, Any] = {"file": file, "kernels": mode()}
    meta["seconds"] = round(time.perf_counter() - start, 3)
    if several:
        return PuzzleFigures.from_dict({"problems": rows, **meta})
    return PuzzleFigures.from_dict({**rows[0], **meta})


def _puzzle_rows(puzzle: BTPuzzle, problem: int | None, how: RowOptions) -> list[dict[str, Any]]:
    """The rows of problem ``problem``, or with None of the puzzle's only problem, or of every
    one."""
    if problem is not None or len(puzzle.problems) == 1:
        return [problem_analysis_row(puzzle, problem or 0, how)]
    return [problem_analysis_row(puzzle, i, how) for i in range(len(puzzle.problems))]
