"""Hostile input: agent text from untrusted models and level files from anyone.

``step_text`` must return a StepResult for every string (one step counted, one turn logged,
the position unchanged when rejected) quickly; a malformed level file must give a
:class:`LevelError` naming file and field, quickly. See :mod:`chaingeo.core.limits`.
"""

from __future__ import annotations

import json
import random
import time
from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from chaingeo.benchmarks.robustness import check_turn, fuzz_states, hostile_texts
from chaingeo.cli.main import main
from chaingeo.core import limits
from chaingeo.core.kinematics import OPPOSITE
from chaingeo.core.level import LevelError, load_level
from chaingeo.core.suite import suite_folder
from chaingeo.envs.actions.types import MoveAction
from chaingeo.envs.machines import new_state
from chaingeo.envs.machines.puzzle import PuzzleState
from chaingeo.envs.machines.state import BaseState, StepResult

SECONDS = 1.0  # per agent turn
LOAD_SECONDS = 3.0  # per malformed level file

# ---------------------------------------------------------------------------------------------
# Agent text
# ---------------------------------------------------------------------------------------------


@cache
def _states() -> dict[str, BaseState]:
    """Stacking (halfway), puzzle disassembly (start), puzzle assembly (halfway)."""
    s = fuzz_states()
    return {"stacking": s[1], "disassemble": s[2], "assemble": s[5]}


KINDS = ("stacking", "disassemble", "assemble")
_PIECES = ("red", "green", "blue", "yellow", "orange", "purple", "white", "black", "cyan")
_TOKENS = (
    *("place", "pickup", "pick up", "move", "finish", "into", "offset", "inf", "out", "and"),
    *("+x", "-x", "x+", "+y", "-z", "z-", "(", ")", "[", "]", "{", "}", ",", "-", "+", "&"),
    *("1", "2", "3", "0", "-1", "99999999999999999999", "9" * 5000, "100001", "1" + "0" * 400),
    *("\u0661\u0662\u0663", "\uff11", "\u00b2", "\x00", "\u221e", "\u2212", "\ufeff", ""),
    *_PIECES,
)


def _timed_turn(state: BaseState, text: str) -> StepResult:
    """One turn on a clone of ``state`` within :data:`SECONDS`; a slow first try is timed
    again on a fresh clone, so a kernel compiled on first use (a fresh checkout has no numba
    cache) or a busy machine does not fail the test, while a slow path (slow every time) still
    does."""
    result, seconds = check_turn(state.clone(), text)
    if seconds >= SECONDS:
        result, seconds = check_turn(state.clone(), text)
    assert seconds < SECONDS, f"{seconds:.2f} s for {text[:80]!r}"
    return result


def _turn(state: BaseState, text: str) -> None:
    _timed_turn(state, text)


_fuzz = settings(max_examples=400, suppress_health_check=[HealthCheck.too_slow])


@pytest.mark.parametrize("kind", KINDS)
@_fuzz
@given(text=st.text(max_size=60))
def test_step_text_on_random_text(kind: str, text: str) -> None:
    _turn(_states()[kind], text)


@pytest.mark.parametrize("kind", KINDS)
@_fuzz
@given(parts=st.lists(st.sampled_from(_TOKENS), max_size=14), sep=st.sampled_from(" ,("))
def test_step_text_on_grammar_shaped_text(kind: str, parts: list[str], sep: str) -> None:
    _turn(_states()[kind], sep.join(parts))


@pytest.mark.parametrize("kind", KINDS)
@_fuzz
@given(seed=st.integers(0, 2**32 - 1))
def test_step_text_on_hostile_generator(kind: str, seed: int) -> None:
    state = _states()[kind]
    _turn(state, next(hostile_texts(state, random.Random(seed))))


ISSUE_TEXTS = (
    "move red +x inf into green offset (99999999999999999999,0,0)",
    "place blue (100000000000000000001,11,1000001) (-1,3,3)",
    "move red +x " + "9" * 5000,
    "move red +x inf into green offset (1000000000,0,0)",
    "move red +x inf into green offset (100000,-100000,100000)",
    "place red " + " ".join(f"(1,1,{i})" for i in range(1, 40_001)),
    "place red " + "(1,1,1) " * 500,
    "place red " + "(" * 100_000 + "1,1,1" + ")" * 100_000,
    "move red +\u0661 \u0662",
    "place red (\u0661,\u0662,\u0663)",
    "\x00" * 10_000,
    "x" * (limits.MAX_TEXT_CHARS + 1),
    "move red+green+blue+red -y 3",
    "place red (1,1,1) (1,1,1)",
    "move red +x 0",
    "finish finish",
    "",
)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("text", ISSUE_TEXTS, ids=range(len(ISSUE_TEXTS)))
def test_reported_texts_are_typed_and_fast(kind: str, text: str) -> None:
    result = _timed_turn(_states()[kind], text)
    assert not result.legal
    assert len(result.feedback) < 2_000  # long text is not echoed back whole


def test_far_offset_is_illegal_not_slow() -> None:
    state = _states()["assemble"]
    assert isinstance(state, PuzzleState)
    a, b = sorted(state.assembly.parts, key=sorted)[:2]
    text = f"move {'+'.join(sorted(a))} +x inf into {'+'.join(sorted(b))} offset (99999,0,0)"
    assert _timed_turn(state, text).error == "illegal"


# ---------------------------------------------------------------------------------------------
# Level files
# ---------------------------------------------------------------------------------------------


def _base(family: str) -> dict[str, Any]:
    name = "puzzle-easy-04-burr6.json" if family == "puzzle" else ""
    folder = suite_folder(family)
    path = folder / name if name else sorted(folder.glob("*.json"))[0]
    data: dict[str, Any] = json.loads(path.read_text())
    return data


def _edit(family: str, change: Callable[[dict[str, Any]], None]) -> str:
    data = _base(family)
    change(data)
    return json.dumps(data)


def _set(key: str, value: Any) -> Callable[[dict[str, Any]], None]:
    return lambda d: d.__setitem__(key, value)


def _voxel(value: list[int], piece: int = 0) -> Callable[[dict[str, Any]], None]:
    return lambda d: d["pieces"][piece]["voxels"].append(value)


def _many_pieces(d: dict[str, Any]) -> None:
    d["pieces"] = [dict(d["pieces"][0]) for _ in range(limits.MAX_PIECES + 1)]


def _big_piece(d: dict[str, Any]) -> None:
    d["pieces"][0]["voxels"] = [[0, 0, i % 1000] for i in range(limits.MAX_PIECE_VOXELS + 1)]


def _duplicates(d: dict[str, Any]) -> None:  # quadratic before: 4,000 distinct, then a repeat
    d["pieces"][0]["voxels"] = [[i // 100, i % 100, 0] for i in range(4000)] + [[0, 0, 0]]


def _nested(depth: int) -> Any:
    out: Any = []
    for _ in range(depth):
        out = [out]
    return out


MALFORMED: dict[str, tuple[Callable[[], str], str]] = {
    "nested-100k": (lambda: "[" * 100_000 + "]" * 100_000, "(file)"),
    "nested-in-stats": (lambda: _edit("puzzle", _set("stats", _nested(80))), "(file)"),
    "voxel-beyond-int64": (lambda: _edit("puzzle", _voxel([2**63, 0, 0])), "pieces[0].voxels"),
    "number-5000-digits": (lambda: _edit("puzzle", _set("max_steps", 10**4000)), "(file)"),
    "puzzle-piece-far": (lambda: _edit("puzzle", _voxel([10**12, 0, 0])), "pieces[0].voxels"),
    "tray-piece-2**62": (lambda: _edit("stacking", _voxel([2**62, 0, 0])), "pieces[0].voxels"),
    "coordinate-1025": (lambda: _edit("puzzle", _voxel([1025, 0, 0])), "pieces[0].voxels"),
    "max-steps-10**18": (lambda: _edit("puzzle", _set("max_steps", 10**18)), "max_steps"),
    "max-steps-401-digits": (lambda: _edit("puzzle", _set("max_steps", 10**400)), "(file)"),
    "too-many-pieces": (lambda: _edit("puzzle", _many_pieces), "pieces"),
    "piece-too-big": (lambda: _edit("puzzle", _big_piece), "pieces[0].voxels"),
    "duplicate-voxels": (lambda: _edit("puzzle", _duplicates), "pieces[0].voxels"),
    "box-huge": (lambda: _edit("stacking", _set("box", [10**9, 1, 1])), "box[0]"),
    "file-5-mib": (lambda: " " * (5 * 1024 * 1024) + "{}", "(file)"),
    "not-utf8": (lambda: "\udcff", "(file)"),
}


@pytest.mark.parametrize("case", sorted(MALFORMED))
def test_malformed_level_file_is_a_level_error(case: str, tmp_path: Path) -> None:
    make, field = MALFORMED[case]
    path = tmp_path / f"{case}.json"
    path.write_bytes(make().encode("utf-8", "surrogateescape"))
    t0 = time.perf_counter()
    with pytest.raises(LevelError) as err:
        load_level(path)
    assert time.perf_counter() - t0 < LOAD_SECONDS
    assert err.value.source == str(path)
    assert err.value.field.startswith(field), err.value


def test_json_depth_ignores_brackets_in_strings() -> None:
    assert limits.json_depth('{"a": ["[[[[", {"b": "\\"]]"}]}') == 3
    assert limits.json_depth('"\\' * 1000) == 0


def test_shipped_levels_are_within_the_limits() -> None:
    for family in ("stacking", "puzzle"):
        for path in sorted(suite_folder(family).glob("*.json")):
            load_level(path)


# ---------------------------------------------------------------------------------------------
# chain validate: optimal_steps re-derived
# ---------------------------------------------------------------------------------------------


def test_validate_flags_a_stored_optimum_that_is_not(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = _base("puzzle")
    state = new_state(load_level(suite_folder("puzzle") / "puzzle-easy-04-burr6.json"))
    assert isinstance(state, PuzzleState) and data["optimal_steps"] == 7
    # a detour: one slide and back, then the stored optimal plan (still a valid plan)
    slide = next(
        a
        for a in state.legal_actions()
        if isinstance(a, MoveAction) and a.move.distance is not None
    )
    move = slide.move
    there = {"pieces": list(move.pieces), "direction": move.direction, "distance": 1}
    back = {**there, "direction": OPPOSITE[move.direction]}
    data["solution"]["moves"] = [there, back, *data["solution"]["moves"]]
    data["optimal_steps"] = 9
    data["max_steps"] = max(data["max_steps"], 9)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    load_level(path)  # a valid file: only the search can tell the optimum is 7
    assert main(["validate", str(path)]) == 2
    row = json.loads(capsys.readouterr().out.splitlines()[0])
    assert "optimum is 7" in row["error"]
    good = suite_folder("puzzle") / "puzzle-easy-04-burr6.json"
    assert main(["validate", str(good)]) == 0
