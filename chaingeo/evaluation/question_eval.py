"""Scoring agents on questions with proven answers, single turn, with three baselines.

An answerer reads one question (its text, and its picture unless asked without) and replies with
text; the first option letter in the reply is its answer. The report gives accuracy per category
with a 95% Wilson interval for the agent, the same agent without pictures (so a category that text
alone solves shows), a uniform random choice, and the most frequent right answer of the category
(learned on the train split: it exposes answers a prior over option texts would guess).
"""

from __future__ import annotations

import base64
import math
import re
from collections import Counter, defaultdict
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final, Protocol

import numpy as np

from chaingeo.evaluation.agents.http import ServerSettings
from chaingeo.evaluation.question_files import Shown
from chaingeo.generator.questions import LETTERS

Z95: Final = 1.959963984540054
_LEAD = re.compile(r"^\W*([ABCD])(?:\W|$)")
_SAID = re.compile(r"answer\W{0,3}(?:is\W{0,3})?([ABCD])\b", re.IGNORECASE)
_ANY = re.compile(r"\b([ABCD])\b")


def wilson(k: int, n: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval of ``k`` successes in ``n`` trials (``(0, 1)`` for none)."""
    if n == 0:
        return 0.0, 1.0
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def parse_letter(text: str) -> str:
    """The letter a reply chose: a leading letter, else "answer is X", else the first capital
    A-D standing alone; empty when none."""
    for pattern in (_LEAD, _SAID, _ANY):
        found = pattern.search(text.strip())
        if found:
            return found.group(1).upper()
    return ""


class Answerer(Protocol):
    label: str

    def answer(self, q: Shown, image: bytes | None) -> str: ...


@dataclass
class RandomAnswerer:
    """A uniform random letter, drawn from ``SeedSequence([seed, question number])``."""

    seed: int = 0
    label: str = "random"

    def answer(self, q: Shown, image: bytes | None) -> str:
        rng = np.random.default_rng(np.random.SeedSequence([self.seed, int(q.id.lstrip("q"))]))
        return LETTERS[int(rng.integers(0, 4))]


class FrequentAnswerer:
    """The option whose text was most often right in the category's training questions."""

    label = "most frequent"

    def __init__(self, train: Sequence[Shown]) -> None:
        self.counts: dict[str, Counter[str]] = defaultdict(Counter)
        for q in train:
            self.counts[q.category][q.options[LETTERS.index(q.answer)]] += 1

    def answer(self, q: Shown, image: bytes | None) -> str:
        seen = self.counts[q.category]
        best = max(range(4), key=lambda i: (seen[q.options[i]], -i))
        return LETTERS[best]


class OracleAnswerer:
    """The proven answer: checks the harness (its accuracy must be 1)."""

    label = "oracle"

    def answer(self, q: Shown, image: bytes | None) -> str:
        return q.answer


class ModelAnswerer:
    """A model behind an OpenAI-compatible server (the ``openai`` agent's transport), asked
    one question per request: the text, then the picture unless ``pictures`` is false."""

    def __init__(
        self,
        options: Mapping[str, Any],
        secrets: Mapping[str, str] | None = None,
        pictures: bool = True,
        seed: int = 0,
    ) -> None:
        self.model = str(options.get("model") or "")
        self.pictures = pictures
        self.client = ServerSettings.from_options(options, secrets).client(seed)
        name = str(options.get("label") or self.model or "model")
        self.label = name if pictures else f"{name} (text only)"
        self.max_tokens = int(options.get("max_tokens", 512))

    def answer(self, q: Shown, image: bytes | None) -> str:
        content: list[dict[str, Any]] = [{"type": "text", "text": q.prompt()}]
        if self.pictures and image is not None:
            url = "data:image/png;base64," + base64.b64encode(image).decode("ascii")
            content.append({"type": "image_url", "image_url": {"url": url}})
        body = {
            "model": self.model,
            "messages": [{"role": "user", "content": content}],
            "max_tokens": self.max_tokens,
            "temperature": 0,
        }
        answer = self.client.complete(body)
        choice = answer.get("choices", [{}])[0].get("message", {}).get("content") or ""
        return str(choice)


@dataclass(frozen=True)
class Score:
    right: int
    n: int

    def cell(self) -> str:
        if self.n == 0:
            return "-"
        lo, hi = wilson(self.right, self.n)
        return f"{100 * self.right / self.n:.1f} [{100 * lo:.1f}, {100 * hi:.1f}]"


def score(
    answerer: Answerer, questions: Sequence[Shown], image: Callable[[Shown], bytes | None]
) -> dict[str, list[bool]]:
    """Per question id, whether the answerer chose the proven letter (grouped by category)."""
    out: dict[str, list[bool]] = defaultdict(list)
    for q in questions:
        out[q.category].append(parse_letter(answerer.answer(q, image(q))) == q.answer)
    return out


def table(columns: Mapping[str, Mapping[str, list[bool]]]) -> str:
    """Markdown: accuracy % with its 95% Wilson interval, per category and over all."""
    cats = sorted({c for col in columns.values() for c in col})
    head = "| category | n | " + " | ".join(columns) + " |"
    rule = "|---|---:|" + "---:|" * len(columns)
    rows = [head, rule]
    for cat in [*cats, "all"]:
        cells = []
        n = 0
        for col in columns.values():
            marks = [m for c in cats for m in col.get(c, [])] if cat == "all" else col.get(cat, [])
            n = max(n, len(marks))
            cells.append(Score(sum(marks), len(marks)).cell())
        rows.append(f"| {cat} | {n} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def evaluate_questions(
    questions: Sequence[Shown],
    train: Sequence[Shown],
    images: Path | None,
    answerers: Sequence[Answerer],
    seed: int = 0,
) -> str:
    """Each answerer's column, then random and most-frequent: the markdown table."""

    def picture(q: Shown) -> bytes | None:
        if images is None:
            return None
        path = images / q.image
        return path.read_bytes() if path.is_file() else None

    columns: dict[str, dict[str, list[bool]]] = {}
    for a in [*answerers, RandomAnswerer(seed), FrequentAnswerer(train)]:
        columns[a.label] = score(a, questions, picture)
    return table(columns)
