"""One multiple-choice question with a proven answer, and the balancing of answer letters.

Why a separate record: a question is content (what is asked, its options, which is right, why)
decided here from the solvers, and presentation (the prompt's 1-based cells, the pictures, the
action texts that reach the state shown) added by the environments, which alone convert
coordinates and draw. A cell list in a text is written ``{cells}`` and carried 0-based in
``cells``; the presentation fills it in.
"""

from __future__ import annotations

import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any, Final

import numpy as np

from chaingeo.core.errors import ChainGeoError
from chaingeo.core.geometry import Cell

LETTERS: Final = ("A", "B", "C", "D")
#: The field a text uses for the cells it carries (filled in 1-based by the presentation).
CELLS_FIELD: Final = "{cells}"


class QuestionError(ChainGeoError, ValueError):
    """A question that cannot be built as asked (too few options, a bad category name)."""


@dataclass(frozen=True)
class Option:
    """One answer option; ``cells`` fills ``{cells}`` in ``text`` (0-based)."""

    text: str
    cells: tuple[Cell, ...] | None = None

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {"text": self.text}
        if self.cells is not None:
            out["cells"] = [list(c) for c in self.cells]
        return out


@dataclass(frozen=True)
class Question:
    """A four-option question about one state of one level.

    ``step``: how many actions of the level's stored solution lead from its start to the state
    shown (0: the start). ``answer``: index of the right option. ``proof``: the facts that make
    it right, machine-readable (JSON values only)."""

    category: str
    level: str
    family: str
    step: int
    prompt: str
    options: tuple[Option, ...]
    answer: int
    proof: Mapping[str, Any]
    signature: str = ""
    index: int = -1
    prompt_cells: tuple[Cell, ...] | None = None

    def __post_init__(self) -> None:
        if len(self.options) != len(LETTERS):
            raise QuestionError(f"{self.category}: {len(self.options)} options, need 4")
        if len({o.to_json().__repr__() for o in self.options}) != len(self.options):
            raise QuestionError(f"{self.category}: two options are the same")
        if not 0 <= self.answer < len(self.options):
            raise QuestionError(f"{self.category}: answer index {self.answer} out of range")

    @property
    def letter(self) -> str:
        return LETTERS[self.answer]

    @property
    def id(self) -> str:
        return f"q{self.index:06d}"

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "id": self.id,
            "category": self.category,
            "level": self.level,
            "family": self.family,
            "signature": self.signature,
            "step": self.step,
            "prompt": self.prompt,
            "options": [o.to_json() for o in self.options],
            "answer": self.letter,
            "proof": dict(self.proof),
        }
        if self.prompt_cells is not None:
            out["prompt_cells"] = [list(c) for c in self.prompt_cells]
        return out


def draft(
    category: str,
    level: Any,
    step: int,
    prompt: str,
    right: Option,
    wrong: Sequence[Option],
    proof: Mapping[str, Any],
    prompt_cells: tuple[Cell, ...] | None = None,
) -> Question:
    """A question with the right option first; :func:`balance` places it."""
    if len(wrong) != 3:
        raise QuestionError(f"{category}: {len(wrong)} wrong options, need 3")
    return Question(
        category=category,
        level=level.id,
        family=level.family,
        step=step,
        prompt=prompt,
        options=(right, *wrong),
        answer=0,
        proof=proof,
        signature=level.provenance.signature,
        prompt_cells=prompt_cells,
    )


def balance(questions: Sequence[Question], seed: int) -> list[Question]:
    """Number the questions and place each right answer: the k-th question of a category
    takes position ``perm[k % 4]`` of a random permutation drawn per block of four, so every
    letter is right within one question of a quarter of each category; the wrong options
    are shuffled too. All draws come from ``SeedSequence([seed, category, block])``."""
    out: list[Question] = []
    seen: dict[str, int] = {}
    perms: dict[tuple[str, int], np.ndarray] = {}
    for i, q in enumerate(questions):
        k = seen.get(q.category, 0)
        seen[q.category] = k + 1
        tag = zlib.crc32(q.category.encode("ascii"))
        key = (q.category, k // 4)
        if key not in perms:
            rng = np.random.default_rng(np.random.SeedSequence([seed, tag, k // 4]))
            perms[key] = rng.permutation(4)
        pos = int(perms[key][k % 4])
        rng = np.random.default_rng(np.random.SeedSequence([seed, tag, k, 7]))
        wrong = [q.options[j] for j in (1 + rng.permutation(3)).tolist()]
        wrong.insert(pos, q.options[q.answer])
        out.append(replace(q, options=tuple(wrong), answer=pos, index=i))
    return out
