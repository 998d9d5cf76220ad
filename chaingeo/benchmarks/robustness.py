"""``chain bench robustness``: hostile agent text, tool calls and model servers never crash a
run, never hang it, never leak the key and never fill the disk.

States: a stacking, a puzzle-disassembly and a puzzle-assembly level of the shipped suite, each
at its start and halfway along its stored plan (6 states). Strings: a seeded generator
(:func:`hostile_texts`) mixing mutations of the state's legal actions (huge, negative and
Unicode numbers, cut and repeated pieces), grammar-shaped noise, random characters (NUL,
brackets, Unicode digits) and long texts (thousands of digits, deep brackets, repeated cells).
Each string is played on a fresh clone of the state; the contract (:func:`check_turn`) is: a
:class:`chaingeo.envs.machines.state.StepResult`, exactly one step counted, one turn logged and the
position unchanged when rejected. Printed: the typed outcomes, the other exceptions (must be
0), contract violations (must be 0) and the slowest call. ``--quick``: fewer strings and calls.

Tool calls (:func:`tool_call_fuzz`): seeded hostile native calls (numbers of 5,000 digits,
nesting 100,000 deep, NaN, lone surrogates, wrong types, unknown names) are translated and
played under the same contract. Server faults (:mod:`chaingeo.evaluation.drills`): a hostile
server plays each attack of issue #21 against a real ``evaluate`` run; the table counts the
episodes done and errored, run crashes, hangs, key leaks and the largest log (all but the last
must be 0). Round three (:mod:`chaingeo.benchmarks._surfaces`): the surfaces of issue #37, one
class each, printed as its table (cases, tracebacks, hangs, wrong acceptances, files outside
their folder or left partial; all but the cases must be 0).
"""

from __future__ import annotations

import argparse
import json
import random
import time
from collections import Counter
from collections.abc import Iterator
from typing import Any

from chaingeo.benchmarks._surfaces import surface_table, surfaces
from chaingeo.core.level import Level, load_level
from chaingeo.core.suite import suite_folder
from chaingeo.envs.machines import new_state
from chaingeo.envs.machines.state import BaseState, StepResult
from chaingeo.evaluation.agents.tools import tool_specs, translate
from chaingeo.evaluation.drills import fault_table, server_fault_rows

#: Strings per state: 6 states x 8,500 = 51,000 in the full run.
PER_STATE = 8_500
PER_STATE_QUICK = 500
SEED = 20261124

#: The shipped levels fuzzed (stacking, puzzle disassembly, puzzle assembly).
LEVEL_FILES = (
    ("stacking", "stacking-2x3x3-hard-s109-000000.json"),
    ("puzzle", "puzzle-easy-04-burr6.json"),
    ("puzzle", "puzzle-mid-11-cube4.json"),
)

_UNICODE_DIGITS = (  # Arabic-Indic, Persian, Devanagari, Thai, fullwidth, superscript, ...
    "\u0661\u0662\u0663",
    "\u0663",
    "\u06f4",
    "\u096b",
    "\u0e53",
    "\uff11\uff12",
    "\u00b2",
    "\u216b",
    "\U0001d7d9",
    "\u3007",
)
_ODD = ("\x00", "\u2212", "\u221e", "\u200b", "\ufeff", "\n", "\t", "\\", '"', "'", "`", "é")
_SYMS = "()[]{},;:&+-.*/#!?=<>|~^%$@_"
_WORDS = (
    "place",
    "put",
    "pickup",
    "pick",
    "up",
    "move",
    "slide",
    "finish",
    "done",
    "into",
    "offset",
    "inf",
    "infinity",
    "out",
    "at",
    "by",
    "and",
    "x",
    "y",
    "z",
    "action:",
)
_HUGE = (
    "99999999999999999999",
    "100000000000000000001",
    "9223372036854775808",
    "18446744073709551616",
    "1" + "0" * 400,
    "9" * 5000,
    "0" * 300 + "1",
    "1000000000",
    "100001",
    "100000",
    "0",
    "-0",
)


def _mutate(rng: random.Random, text: str, names: list[str]) -> str:
    kind = rng.randrange(9)
    tokens = text.split(" ")
    if kind == 0:  # a number replaced by a huge one
        digits = [i for i, c in enumerate(text) if c.isdigit()]
        if digits:
            i = rng.choice(digits)
            return text[:i] + rng.choice(_HUGE) + text[i + 1 :]
    if kind == 1:  # a number replaced by Unicode digits
        digits = [i for i, c in enumerate(text) if c.isdigit()]
        if digits:
            i = rng.choice(digits)
            return text[:i] + rng.choice(_UNICODE_DIGITS) + text[i + 1 :]
    if kind == 2:  # cut
        return text[: rng.randrange(len(text) + 1)]
    if kind == 3:  # a piece repeated many times
        i = rng.randrange(len(tokens))
        return " ".join(tokens[:i] + [tokens[i]] * rng.choice((2, 50, 700)) + tokens[i + 1 :])
    if kind == 4:  # odd characters inserted
        i = rng.randrange(len(text) + 1)
        return text[:i] + "".join(rng.choice(_ODD) for _ in range(rng.randint(1, 3))) + text[i:]
    if kind == 5:  # a name swapped
        return " ".join(rng.choice(names) if rng.random() < 0.3 else t for t in tokens)
    if kind == 6:  # insertion with a far offset
        far = rng.choice(_HUGE)
        group = rng.choice(names)
        return f"{text} into {group} offset ({far},{rng.choice(('0', '-' + far))},0)"
    if kind == 7:  # signs flipped
        return text.replace("(", "(-", rng.randint(1, 3))
    return text.upper()


def _noise(rng: random.Random, names: list[str]) -> str:
    parts: list[str] = []
    for _ in range(rng.randint(1, 12)):
        r = rng.random()
        if r < 0.35:
            parts.append(rng.choice(_WORDS))
        elif r < 0.55:
            parts.append(rng.choice(names))
        elif r < 0.75:
            parts.append(str(rng.randint(-5, 12)))
        elif r < 0.85:
            parts.append(rng.choice(_HUGE))
        elif r < 0.92:
            parts.append(rng.choice(_SYMS))
        else:
            parts.append(rng.choice(_UNICODE_DIGITS + _ODD))
    return rng.choice((" ", "", ",")).join(parts)


def _random_chars(rng: random.Random) -> str:
    n = rng.choice((0, 1, 3, 10, 40, 200))
    pool = "abcdefghijklmnopqrstuvwxyz0123456789 " + _SYMS + "".join(_UNICODE_DIGITS + _ODD)
    if rng.random() < 0.2:
        return (
            "".join(chr(rng.randrange(0x110000)) for _ in range(n))
            .encode("utf-8", "replace")
            .decode("utf-8", "replace")
        )
    return "".join(rng.choice(pool) for _ in range(n))


def _long(rng: random.Random, names: list[str]) -> str:
    name = rng.choice(names)
    kind = rng.randrange(6)
    if kind == 0:
        n = rng.choice((500, 4_000, 40_000))
        return f"place {name} " + " ".join(f"(1,1,{i})" for i in range(1, n + 1))
    if kind == 1:
        return f"place {name} (1,1,1) " * rng.choice((100, 1_000))
    if kind == 2:
        depth = rng.choice((100, 10_000, 100_000))
        return f"place {name} " + "(" * depth + "1,1,1" + ")" * depth
    if kind == 3:
        return f"move {name} +x " + "9" * rng.choice((20, 5_000, 50_000))
    if kind == 4:
        return "x" * rng.choice((4_097, 100_000))
    return f"move {name} +x inf into {rng.choice(names)} offset (1000000000,0,0)"


def hostile_texts(state: BaseState, rng: random.Random) -> Iterator[str]:
    """An endless seeded stream of hostile agent texts for ``state``."""
    names = sorted(p.name for p in state.level.pieces)
    legal = state.legal_actions()
    samples = [legal[i].to_text() for i in range(0, len(legal), max(1, len(legal) // 40))]
    while True:
        r = rng.random()
        if r < 0.45:
            yield _mutate(rng, rng.choice(samples), names)
        elif r < 0.75:
            yield _noise(rng, names)
        elif r < 0.95:
            yield _random_chars(rng)
        else:
            yield _long(rng, names)


def check_turn(state: BaseState, text: str) -> tuple[StepResult, float]:
    """Play ``text`` on ``state`` (changed) and check the step contract; AssertionError if
    it is broken. Returns the result and the seconds the call took."""
    before_key, steps, turns = state.key(), state.steps_used, len(state.history)
    t0 = time.perf_counter()
    result = state.step_text(text)
    seconds = time.perf_counter() - t0
    assert isinstance(result, StepResult), type(result)
    assert state.steps_used == steps + 1, "a turn must count exactly one step"
    assert len(state.history) == turns + 1, "a turn must be logged"
    if not result.legal:
        assert result.error in ("unparseable", "illegal", "ambiguous"), result.error
        assert state.key() == before_key, "a rejected turn must not change the position"
    return result, seconds


def fuzz_states() -> list[BaseState]:
    """Each fuzzed level at its start and halfway along its stored plan."""
    out: list[BaseState] = []
    for family, name in LEVEL_FILES:
        level: Level = load_level(suite_folder(family) / name)
        state = new_state(level)
        out.append(state.clone())
        plan = _plan_texts(level)
        for text in plan[: len(plan) // 2]:
            result = state.step_text(text)
            if not result.legal:
                raise AssertionError(f"{level.id}: stored plan step {text!r}: {result.feedback}")
        out.append(state.clone())
    return out


def _plan_texts(level: Level) -> list[str]:
    from chaingeo.core.level import PuzzleSolution, StackingSolution
    from chaingeo.envs.actions.types import PlaceAction

    sol = level.solution
    if isinstance(sol, StackingSolution):
        return [PlaceAction(n, sol.placements[n].cells).to_text() for n in sol.order]
    assert isinstance(sol, PuzzleSolution)
    return [m.describe() for m in sol.moves]


# ---------------------------------------------------------------------------------------------
# Tool calls: a model's native calls, arguments as hostile as its text
# ---------------------------------------------------------------------------------------------

#: Hostile tool calls per state: 6 states x 2,000 = 12,000 in the full run.
TOOL_CALLS = 2_000
TOOL_CALLS_QUICK = 150


def _hostile_value(rng: random.Random, names: list[str], depth: int = 0) -> Any:
    r = rng.random()
    if r < 0.2 or depth > 2:
        return rng.choice((*names, "\ud800", "x" * 5_000, "", "inf", "+x", "z", "red\n" * 50))
    if r < 0.45:
        return rng.choice((0, -1, 1, 2, 90, -90, 10**30, 1e308, 2.5, True, None))
    if r < 0.8:
        return [_hostile_value(rng, names, depth + 1) for _ in range(rng.choice((0, 1, 3, 3, 70)))]
    return {rng.choice(_KEYS): _hostile_value(rng, names, depth + 1) for _ in range(3)}


_KEYS = ("piece", "cells", "pieces", "direction", "distance", "axis", "angle", "into", "offset")
_RAW_ARGUMENTS = (
    '{"piece": "red", "cells": [[' + "9" * 5_000 + ", 1, 1]]}",
    '{"piece": "red", "cells": [[' + "9" * 50 + ", 1, 1]]}",
    "[" * 100_000,
    '{"pieces": ["red"], "direction": "+x", "distance": NaN}',
    '{"pieces": ["red"], "direction": "+x", "distance": Infinity}',
    '{"piece": "\\ud800"}',
    "{not json",
    '"a string"',
    " ",
    '{"piece": "' + "r" * 10_000 + '"}',
)


def hostile_calls(state: BaseState, rng: random.Random) -> Iterator[tuple[Any, Any]]:
    """An endless seeded stream of hostile ``(name, arguments)`` tool calls for ``state``."""
    names = sorted(p.name for p in state.level.pieces)
    offered = [t["function"]["name"] for t in tool_specs(state.level)]
    while True:
        r = rng.random()
        name: Any = rng.choice(offered) if r < 0.85 else rng.choice(("\ud800", 7, None, "x" * 999))
        if rng.random() < 0.25:
            yield name, rng.choice(_RAW_ARGUMENTS)
            continue
        args = {rng.choice(_KEYS): _hostile_value(rng, names) for _ in range(rng.randint(0, 4))}
        yield name, (json.dumps(args) if rng.random() < 0.7 else args)


def tool_call_fuzz(per_state: int) -> dict[str, Any]:
    """Hostile tool calls translated (:func:`translate`) and played (:func:`check_turn`) on the
    six states: counts of malformed and translated calls, the step outcomes, other exceptions
    (must be 0), contract violations (must be 0) and the slowest call."""
    rng = random.Random(SEED + 1)
    translated: Counter[str] = Counter()
    outcomes: Counter[str] = Counter()
    others: Counter[str] = Counter()
    violations = 0
    slowest = 0.0
    for base in fuzz_states():
        offered = tool_specs(base.level)
        calls = hostile_calls(base, rng)
        for _ in range(per_state):
            name, arguments = next(calls)
            t0 = time.perf_counter()
            try:
                out = translate(name, arguments, offered)
                translated["malformed" if out.problem else "translated"] += 1
                result, _ = check_turn(base.clone(), out.action)
            except AssertionError:
                violations += 1
                continue
            except Exception as e:  # must stay 0
                others[type(e).__name__] += 1
                continue
            slowest = max(slowest, time.perf_counter() - t0)
            outcomes[result.error or "legal"] += 1
    return {
        "tool_calls": sum(translated.values()) + sum(others.values()),
        "calls": dict(sorted(translated.items())),
        "typed_results": dict(sorted(outcomes.items())),
        "other_exceptions": sum(others.values()),
        "other_exception_types": dict(sorted(others.items())),
        "contract_violations": violations,
        "slowest_call_ms": round(1000 * slowest, 2),
    }


def _step_text_fuzz(per_state: int) -> dict[str, Any]:
    """The original class: hostile agent text through ``step_text`` on the six states."""
    rng = random.Random(SEED)
    outcomes: Counter[str] = Counter()
    others: Counter[str] = Counter()
    violations = 0
    slowest = (0.0, "")
    t_start = time.perf_counter()
    for base in fuzz_states():
        texts = hostile_texts(base, rng)
        for _ in range(per_state):
            text = next(texts)
            state = base.clone()
            try:
                result, seconds = check_turn(state, text)
            except AssertionError:
                violations += 1
                continue
            except Exception as e:  # the figure this benchmark exists for: must stay 0
                others[type(e).__name__] += 1
                continue
            outcomes[result.error or "legal"] += 1
            if seconds > slowest[0]:
                slowest = (seconds, text)
    total = sum(outcomes.values()) + sum(others.values()) + violations
    shown = slowest[1] if len(slowest[1]) <= 80 else slowest[1][:77] + "..."
    return {
        "strings": total,
        "typed_results": dict(sorted(outcomes.items())),
        "other_exceptions": sum(others.values()),
        "other_exception_types": dict(sorted(others.items())),
        "contract_violations": violations,
        "slowest_call_ms": round(1000 * slowest[0], 2),
        "slowest_text": shown,
        "slowest_text_chars": len(slowest[1]),
        "seconds": round(time.perf_counter() - t_start, 1),
    }


def run(args: argparse.Namespace) -> int:
    """Every class; prints the step-text figures (JSON), then the tool-call and server-fault
    tables; exit 1 if any class broke its contract."""
    text = _step_text_fuzz(PER_STATE_QUICK if args.quick else PER_STATE)
    print(json.dumps(text, sort_keys=True))
    calls = tool_call_fuzz(TOOL_CALLS_QUICK if args.quick else TOOL_CALLS)
    print(json.dumps(calls, sort_keys=True))
    rows = server_fault_rows()
    print(fault_table(rows))
    found = surfaces()  # round three (issue #37): files, stores, run folders, doors, writers
    print(surface_table(found))
    broken = text["other_exceptions"] or text["contract_violations"]
    broken = broken or calls["other_exceptions"] or calls["contract_violations"]
    broken = broken or any(r.bad() for r in found)
    return 1 if broken or any(r["crash"] or r["hang"] or r["leak"] for r in rows) else 0
