"""Our levels as BurrTools puzzles, so a designer opens them in BurrTools and every level can be
checked against ``burrTxt``.

A puzzle level becomes one problem whose result is the assembled shape and whose pieces are the
level's pieces, each its own shape used once (named as in the level; congruent pieces stay
separate shapes, so BurrTools counts them as distinguishable, as our game does: each has its own
name and colour), with the assembled state stored as the one solution. A stacking level becomes
the same with the box as the result and the level's packing as the stored solution. BurrTools
has no turns and no cap on the size of a moving group: those rules of a level are not carried
(``rules_not_carried`` lists them for the caller to say so).
"""

from __future__ import annotations

from chaingeo.core.formats.bt_model import BTPuzzle
from chaingeo.core.formats.bt_write import assembled_puzzle
from chaingeo.core.level import Level, StackingSolution
from chaingeo.core.rules import PuzzleRules


def level_puzzle(level: Level) -> BTPuzzle:
    """The level as a one-problem BurrTools puzzle (see the module docstring)."""
    comment = f"CHAIN-geo level {level.id} ({level.family}, {level.difficulty})"
    if isinstance(level.solution, StackingSolution):
        placed = dict(level.solution.placements)
        return assembled_puzzle(placed, name=level.id, comment=comment)
    return assembled_puzzle(level.shapes, name=level.id, comment=comment)


def rules_not_carried(level: Level) -> list[str]:
    """The level's rules a BurrTools file cannot express (empty when it carries them all)."""
    rules = level.rules
    if not isinstance(rules, PuzzleRules):
        return []
    out = []
    if rules.turns:
        out.append("turns (BurrTools only slides pieces)")
    if rules.max_group is not None:
        out.append(f"max_group {rules.max_group} (BurrTools moves groups of any size)")
    return out
