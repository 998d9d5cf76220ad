"""Levels made from CHAIN's published models: the importer's lattice pieces plus what needs
the solvers (a puzzle's level and optimal plan, a stacking model's packing).

One place for ``chain import`` and for the puzzle suite (:mod:`chaingeo.generator.puzzle_suite`), so
an imported level in the suite is byte for byte what ``chain import`` writes for the same model
and options.
"""

from __future__ import annotations

from typing import Literal

from chaingeo.core.formats.models import (
    ImportedModel,
    ModelImportError,
    model_puzzle_level,
    model_stacking_level,
)
from chaingeo.core.level import Difficulty, Level
from chaingeo.generator.puzzle import difficulty_of
from chaingeo.solvers.analysis import analyze_puzzle
from chaingeo.solvers.cover.packings import first_packing
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.disassemble import Analysis

#: The caps of ``chain import`` (its ``--max-states`` / ``--max-total-states`` / ``--seconds``).
IMPORT_LIMITS = SearchLimits(max_states=500_000, seconds=120.0, max_total_states=3_000_000)


def stacking_difficulty(model: ImportedModel) -> Difficulty:
    """As the stacking generator's modes: cuboids easy, flat pieces mid, free shapes hard."""
    shapes = [p.shape for p in model.parts]
    if all(s.is_cuboid() for s in shapes):
        return "easy"
    if all(min(s.extent) == 1 for s in shapes):
        return "mid"
    return "hard"


def imported_stacking_level(model: ImportedModel, level_id: str | None = None) -> Level:
    """The stacking level of a model laid out beside its container, packed by exact cover.
    Raises :class:`ModelImportError` when the pieces do not pack the box."""
    assert model.box is not None
    sol = first_packing(model.shapes, model.box, reflections=False)
    if sol is None:
        raise ModelImportError(
            model.model, "box", f"the pieces do not pack the {list(model.box)} box"
        )
    return model_stacking_level(
        model, dict(sol.placements), difficulty=stacking_difficulty(model), level_id=level_id
    )


def imported_puzzle_level(
    model: ImportedModel,
    *,
    goal: Literal["disassemble", "assemble"] = "disassemble",
    turns: bool = False,
    max_group: int | None = None,
    limits: SearchLimits = IMPORT_LIMITS,
    level_id: str | None = None,
) -> tuple[Level, Analysis]:
    """The verified puzzle level of an imported model: level and o_i from
    :func:`chaingeo.solvers.analysis.analyze_puzzle`, difficulty from the suite's rule. Raises
    :class:`ModelImportError` when the model does not come apart (by translations, or also by
    turns when ``turns``) and :class:`~chaingeo.core.kinematics.SearchLimitError` at the caps."""
    a = analyze_puzzle(
        model.shapes, max_group=max_group, limits=limits, turns=turns, rods=model.rods
    )
    if not a.disassemblable or a.optimal_steps is None:
        how = "translations and turns" if turns else "translations alone (try --turns)"
        raise ModelImportError(model.model, "parts", f"does not come apart by {how}")
    stats = {
        "level": a.level,
        "first_level": a.first_level,
        "moves": a.moves,
        "pieces": len(model.parts),
        "voxels": sum(len(p.shape) for p in model.parts),
        "states": a.states,
    }
    level = model_puzzle_level(
        model,
        a.plan,
        goal=goal,
        difficulty=difficulty_of(a.first_level or 0, a.optimal_steps, len(model.parts)),
        max_group=max_group,
        turns=turns,
        stats=stats,
        level_id=level_id,
    )
    return level, a
