"""Questions with proven answers: every answer re-proved by an independent route, answer
letters in balance, the same bytes twice, a registry that refuses a second category."""

from __future__ import annotations

import json
from collections import Counter
from functools import cache

import numpy as np
import pytest

from chaingeo.core.registry import DuplicateNameError
from chaingeo.generator.questions import CATEGORIES, LETTERS, Question, generate_questions
from chaingeo.generator.questions.model import Option, QuestionError, balance, draft
from tests.support.question_proofs import truth
from tests.support.shipped import shipped

LEVELS = {lv.id: lv for lv in shipped()}
#: A sample the default run re-proves in seconds: small puzzles and small boxes.
SAMPLE = [
    "puzzle-easy-07-burr3",
    "puzzle-easy-09-cube3",
    "stacking-2x2x3-easy-s103-000000",
    "stacking-2x2x4-mid-s106-000001",
    "stacking-2x3x3-mid-s108-000000",
]
needs_suite = pytest.mark.skipif(not LEVELS, reason="the shipped suite is not installed")


@cache
def _generated(ids: tuple[str, ...], seed: int) -> tuple[Question, ...]:
    return tuple(generate_questions([LEVELS[i] for i in ids], seed))


def _questions(ids: list[str], seed: int = 0) -> list[Question]:
    """The questions of these levels (generated once per process for the same arguments)."""
    return list(_generated(tuple(ids), seed))


def _check(q: Question) -> None:
    right = truth(q, LEVELS[q.level])
    assert right == [i == q.answer for i in range(4)], (q.id, q.category, q.to_json(), right)


@needs_suite
def test_sample_answers_reproved() -> None:
    qs = _questions(SAMPLE)
    assert len({q.category for q in qs}) >= 8
    for q in qs:
        _check(q)


@needs_suite
@pytest.mark.slow
@pytest.mark.parametrize("level_id", sorted(LEVELS))
def test_every_answer_reproved(level_id: str) -> None:
    level = LEVELS[level_id]
    if level.family == "puzzle" and len(level.pieces) > 16:
        pytest.skip("36-piece burrs: the reference kinematics' groups are too many to list")
    for q in _questions([level_id]):
        big = level.box is not None and int(np.prod(level.box)) > 36
        if big and q.category in ("completes", "dead-end"):
            continue  # the naive counter lists every packing: small boxes only
        _check(q)


@needs_suite
def test_same_bytes_twice_and_seed_matters() -> None:
    levels = [LEVELS[i] for i in SAMPLE[1:4]]
    a = [json.dumps(q.to_json(), sort_keys=True) for q in generate_questions(levels, 3)]
    b = [json.dumps(q.to_json(), sort_keys=True) for q in generate_questions(levels, 3)]
    c = [json.dumps(q.to_json(), sort_keys=True) for q in generate_questions(levels, 4)]
    assert a == b
    assert a != c


@needs_suite
def test_answer_letters_balanced_per_category() -> None:
    qs = _questions(SAMPLE)
    for cat in {q.category for q in qs}:
        letters = Counter(q.letter for q in qs if q.category == cat)
        n = sum(letters.values())
        for letter in LETTERS:  # blocks of four take each letter once
            assert abs(letters[letter] - n / 4) <= 1 + n % 4, (cat, letters)


def test_balance_places_right_option_and_keeps_it() -> None:
    level = LEVELS[SAMPLE[0]] if LEVELS else None
    if level is None:
        pytest.skip("the shipped suite is not installed")
    drafts = [
        draft("count", level, 0, f"q{i}", Option("right"), [Option(f"w{j}") for j in range(3)], {})
        for i in range(40)
    ]
    placed = balance(drafts, seed=1)
    assert all(q.options[q.answer].text == "right" for q in placed)
    assert Counter(q.letter for q in placed) == dict.fromkeys(LETTERS, 10)
    assert [q.index for q in placed] == list(range(40))


def test_bad_questions_refused() -> None:
    level = LEVELS[SAMPLE[0]] if LEVELS else None
    if level is None:
        pytest.skip("the shipped suite is not installed")
    with pytest.raises(QuestionError):
        draft("count", level, 0, "q", Option("a"), [Option("b"), Option("c")], {})
    with pytest.raises(QuestionError):
        draft("count", level, 0, "q", Option("a"), [Option("a"), Option("b"), Option("c")], {})


def test_registry_refuses_a_second_category_of_the_same_name() -> None:
    with pytest.raises(DuplicateNameError):
        CATEGORIES.register("count", CATEGORIES.get("count"))
