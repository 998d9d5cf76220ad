"""Complete counts in a puzzle level's stats: BurrTools' assemblies and solutions of the level
written as a BurrTools file, as ``chain analyze`` counts them (burrTxt's convention: an assembly
and its mirror image are one), with how they were obtained.

``chain generate puzzle-counts [--levels levels/puzzle] [--jobs N | --scheduler ADDRESS]`` counts
the levels of a folder that do not yet hold complete counts (``--recount``: all of them) and
writes them back; :func:`chaingeo.generator.puzzle_suite.build_puzzle_suite` runs the same step
on the levels it makes, reusing a stored count only for the same puzzle (the same bytes apart
from the counts). Counting has no clock: the disassembler's state caps are ``chain analyze``'s
caps, raised to :data:`COUNT_STATES` states a part (the program stored with the counts), so every
machine writes the same files; a count that meets a cap is an error (it would not be complete).
Every assembly is judged by BurrTools' rules, whatever the level's ``max_group`` (its BurrTools
file has none).

A level whose congruent pieces are separate BurrTools shapes with at least
:data:`BY_ARRANGEMENT_FROM` relabellings (hard-03's 11 sticks: 11!) is counted by arrangement
(:mod:`chaingeo.solvers.assembly.btcongruent`): each arrangement judged once (and on
:data:`CHECKS` relabellings, which must agree), its labelled classes counted exactly; its
``program`` says so, and whether each verdict is also proven for every labelling.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Iterable, Mapping
from importlib.metadata import version
from pathlib import Path
from typing import Any, Final

from chaingeo.core.level import Level, level_bytes, load_level, revalidate, save_level
from chaingeo.generator.batch import GenerationError
from chaingeo.solvers.analysis import CONVENTIONS, count_figures, level_packing
from chaingeo.solvers.assembly.btcongruent import (
    ArrangementReport,
    Plan,
    arrangement_plan,
    count_by_arrangement,
    relabelling_count,
)
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.jobs import Farm
from chaingeo.solvers.limits import SearchLimits

#: The stats keys the count step writes.
COUNT_KEYS: Final = ("assemblies", "solutions", "counts")
#: States a part's disassembly may take while counting (``chain analyze --max-states``).
COUNT_STATES: Final = 20_000_000
#: The caps of counting: no clock.
COUNT_LIMITS: Final = SearchLimits(max_states=COUNT_STATES, seconds=None)
#: How the counts were obtained (stored with them).
PROGRAM: Final = f"chain analyze --no-optimal --max-states {COUNT_STATES}"
#: Levels whose congruent pieces have this many relabellings or more are counted by arrangement.
BY_ARRANGEMENT_FROM: Final = 1_000_000
#: Relabellings of each arrangement judged besides its first when counting by arrangement.
CHECKS: Final = 1000
#: How counts by arrangement were obtained (stored with them).
PROGRAM_BY_ARRANGEMENT: Final = (
    f"chain generate puzzle-counts --max-states {COUNT_STATES}: each arrangement of congruent "
    f"pieces judged once and on {CHECKS} seeded relabellings (all agreeing), times its "
    "labelled classes (Burnside over its stabiliser)"
)
#: The same, each arrangement's verdict also proven for every labelling (by geometry alone).
PROGRAM_PROVEN: Final = (
    f"chain generate puzzle-counts --max-states {COUNT_STATES}: each arrangement of congruent "
    "pieces judged once, its verdict proven for every labelling (every separation BurrTools' "
    f"first could be, recursively) and checked on {CHECKS} seeded relabellings, times its "
    "labelled classes (Burnside over its stabiliser)"
)


def has_counts(level: Level) -> bool:
    """Whether the level's stats hold complete counts."""
    info = level.stats.get("counts")
    return (
        isinstance(info, Mapping)
        and info.get("complete") is True
        and all(isinstance(level.stats.get(k), int) for k in ("assemblies", "solutions"))
    )


def without_counts(level: Level) -> Level:
    """The level with no counts in its stats (what the puzzle is, apart from them)."""
    stats = {k: v for k, v in level.stats.items() if k not in COUNT_KEYS}
    return dataclasses.replace(level, stats=stats)


def count_level(level: Level, farm: Farm) -> Level:
    """The level with complete counts in its stats (see the module's docstring)."""
    packing = level_packing(level)
    plan = arrangement_plan(packing)
    program = PROGRAM
    if plan is not None and relabelling_count(plan) >= BY_ARRANGEMENT_FROM:
        got = _by_arrangement(plan, level)
        rep = got.report
        program = PROGRAM_PROVEN if got.all_proven else PROGRAM_BY_ARRANGEMENT
    else:
        out: dict[str, Any] = {}
        rep = count_figures(packing, out, "drop", COUNT_LIMITS, Deadline(None), "", farm)
        if not rep.complete:
            raise GenerationError(f"{level.id}: counting stopped ({out.get('limit')})")
    counts = {
        "assemblies": rep.assemblies,
        "solutions": rep.solutions,
        "counts": {
            "complete": True,
            "convention": CONVENTIONS["drop"],
            "program": program,
            "version": version("chaingeo"),
        },
    }
    return revalidate(dataclasses.replace(level, stats={**without_counts(level).stats, **counts}))


def _by_arrangement(plan: Plan, level: Level) -> ArrangementReport:
    """The counts by arrangement, in this process (a handful of verdicts)."""
    got = count_by_arrangement(
        plan, mirrors="drop", max_group=None, limits=COUNT_LIMITS,
        deadline=Deadline(None), checks=CHECKS,
    )  # fmt: skip
    if not got.report.complete:
        raise GenerationError(f"{level.id}: counting stopped ({got.report.limit})")
    return got


def reuse_counts(level: Level, stored: Iterable[Level]) -> Level | None:
    """``level`` with the complete counts of a stored level of the same puzzle, if any."""
    mine = level_bytes(without_counts(level))
    for old in stored:
        if has_counts(old) and level_bytes(without_counts(old)) == mine:
            counts = {k: old.stats[k] for k in COUNT_KEYS}
            return revalidate(dataclasses.replace(level, stats={**level.stats, **counts}))
    return None


def count_folder(
    folder: Path,
    farm: Farm,
    *,
    recount: bool = False,
    only: Iterable[str] = (),
    log: Callable[[str], None] | None = None,
) -> list[Level]:
    """Count the ``puzzle-*.json`` levels of ``folder`` lacking complete counts (all with
    ``recount``; only the ids in ``only`` when given) and write them back."""
    wanted = set(only)
    done: list[Level] = []
    for path in sorted(folder.glob("puzzle-*.json")):
        level = load_level(path)
        if (wanted and level.id not in wanted) or (has_counts(level) and not recount):
            continue
        start = time.perf_counter()
        level = count_level(level, farm)
        save_level(level, path)
        done.append(level)
        if log is not None:
            s = level.stats
            log(f"{level.id}: {s['assemblies']} assemblies, {s['solutions']} solutions "
                f"({time.perf_counter() - start:.1f} s)")  # fmt: skip
    return done
