"""Multiple-choice questions with answers proven by the solvers, from any level suite.

One module per family of categories (:mod:`.puzzle`, :mod:`.counting`, :mod:`.stacking`), each
registering its drafters in :data:`CATEGORIES`; :func:`generate_questions` runs them over the
levels in a fixed order and places the right answers in balance (:func:`.model.balance`). The
same levels and seed give the same questions, byte for byte.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np

from chaingeo.core.level import Level
from chaingeo.generator.questions import counting, puzzle, stacking, views
from chaingeo.generator.questions.common import CATEGORIES
from chaingeo.generator.questions.model import LETTERS, Option, Question, QuestionError, balance

__all__ = [
    "CATEGORIES",
    "LETTERS",
    "Option",
    "Question",
    "QuestionError",
    "generate_questions",
    "level_questions",
]
_FAMILIES = (puzzle, counting, stacking, views)  # imported for their registrations


def level_questions(
    level: Level, seed: int, categories: Sequence[str] | None = None
) -> list[Question]:
    """The drafts of one level (right answer first), category by category; each category draws
    from ``SeedSequence([seed, category number, level signature])``."""
    names = list(CATEGORIES.names()) if categories is None else list(categories)
    out: list[Question] = []
    for name in names:
        drafter = CATEGORIES.get(name)
        tag = int(level.provenance.signature[:12] or "0", 16)
        number = list(CATEGORIES.names()).index(name)
        rng = np.random.default_rng(np.random.SeedSequence([seed, number, tag]))
        out.extend(drafter(level, rng))
    return out


def generate_questions(
    levels: Iterable[Level], seed: int = 0, categories: Sequence[str] | None = None
) -> list[Question]:
    """Every category's questions on every level (levels sorted by id), answers balanced."""
    drafts: list[Question] = []
    for level in sorted(levels, key=lambda lv: lv.id):
        drafts.extend(level_questions(level, seed, categories))
    return balance(drafts, seed)
