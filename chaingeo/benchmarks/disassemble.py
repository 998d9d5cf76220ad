"""``chain bench disassemble``: the numba disassembly search against the reference kinematics.

Instances: every level of the shipped puzzle suite (``levels/puzzle``), plus puzzles generated
on the spot from seed 10: six-piece burrs (the hill climber's best level) and maze burrs of
level >= 10 (:data:`DEEP_CONFIG`; the level reached and the seconds generation took are
printed). For each instance, ``ours`` is the full analysis
(BurrTools-style level and the exact optimal plan) and ``states_per_s`` the states it visited
per second; ``reference`` is a breadth-first search with the pure-Python reference kinematics
(:mod:`chaingeo.core.kinematics`) on the same puzzle, stopped after expanding
``CHAIN_BENCH_REF_STATES`` states (default 2000) or 5 seconds, giving its states per second.
``speedup`` is the ratio of the two rates.
JIT compilation is excluded (a warm-up analysis runs first). ``--quick``: three suite levels and
one small generated puzzle. Set ``CHAIN_BENCH_GENERATED=N`` for N generated puzzles (default 2).
"""

from __future__ import annotations

import argparse
import json
import os
import time
from collections.abc import Mapping

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import Assembly, legal_moves, state_key
from chaingeo.core.level import Level
from chaingeo.core.suite import suite_folder


def reference_rate(
    shapes: Mapping[str, Shape], max_states: int, max_seconds: float = 5.0
) -> tuple[int, float]:
    """States found by the reference breadth-first search (it stops after expanding
    ``max_states``) and the seconds it took: the same unit as the states our search stores."""
    start = Assembly.assembled(shapes)
    seen = {state_key(start)}
    frontier = [start]
    t0 = time.perf_counter()
    expanded = 0
    while frontier and expanded < max_states and time.perf_counter() - t0 < max_seconds:
        nxt = []
        for state in frontier:
            expanded += 1
            for m in legal_moves(state):
                child = state.apply(m)
                k = state_key(child)
                if k not in seen:
                    seen.add(k)
                    nxt.append(child)
            if expanded >= max_states or time.perf_counter() - t0 >= max_seconds:
                break
        frontier = nxt
    return len(seen), time.perf_counter() - t0


def _ours(
    shapes: Mapping[str, Shape], max_group: int | None, level: Level | None = None
) -> tuple[float, int, dict[str, object]]:
    """Our full analysis; a suite level is analysed as it was made (towers with single-piece
    moves by the block bound, :func:`chaingeo.solvers.analysis.analyze_level`)."""
    from chaingeo.solvers.analysis import analyze_level, analyze_puzzle

    t0 = time.perf_counter()
    if level is not None:
        result = analyze_level(level)
    else:
        result = analyze_puzzle(shapes, max_group=max_group)
    seconds = time.perf_counter() - t0
    info: dict[str, object] = {
        "level": result.level,
        "moves": result.moves,
        "optimal_steps": result.optimal_steps,
    }
    return seconds, result.states, info


Instance = tuple[str, dict[str, Shape], int | None, dict[str, object], Level | None]

#: Generated deep puzzles: maze burrs (:mod:`chaingeo.generator.maze`) of level >= 10 from seed 10.
DEEP_CONFIG = {"shape": "maze8", "min_level": 10, "hill_steps": 300}


def _instances(quick: bool) -> list[Instance]:
    from chaingeo.core.level import load_levels
    from chaingeo.core.rules import PuzzleRules
    from chaingeo.generator.config import PuzzleConfig
    from chaingeo.generator.puzzle import make

    out: list[Instance] = []
    suite = suite_folder("puzzle")
    levels = load_levels(suite) if suite.is_dir() else []
    for lv in levels[:3] if quick else levels:
        mg = lv.rules.max_group if isinstance(lv.rules, PuzzleRules) else None
        out.append((lv.id, lv.shapes, mg, {}, lv))
    n_gen = 1 if quick else int(os.environ.get("CHAIN_BENCH_GENERATED", "2"))
    burr6 = PuzzleConfig(shape="burr6", min_level=1, hill_steps=60 if quick else 600)
    deep = PuzzleConfig(**DEEP_CONFIG)  # type: ignore[arg-type]
    for config in (burr6, deep):
        for i in range(n_gen):
            t0 = time.perf_counter()
            item = make(config, 10, i)
            extra: dict[str, object] = {"generate_seconds": round(time.perf_counter() - t0, 3)}
            if hasattr(item, "pieces"):
                name = f"generated-{config.shape}-s10-i{i}"
                out.append((name, item.shapes, None, extra, None))  # type: ignore[union-attr]
    return out


def run(args: argparse.Namespace) -> int:
    ref_states = int(os.environ.get("CHAIN_BENCH_REF_STATES", "2000"))
    warm = {"a": Shape([(0, 0, 0), (1, 0, 0)]), "b": Shape([(0, 1, 0), (1, 1, 0)])}
    _ours(warm, None)  # JIT warm-up, not timed
    rows = []
    for name, shapes, max_group, extra, level in _instances(args.quick):
        best = float("inf")
        states = 0
        info: dict[str, object] = {}
        for _ in range(max(1, args.repeat)):
            seconds, states, info = _ours(shapes, max_group, level)
            best = min(best, seconds)
        ours_rate = states / best if best > 0 else float("inf")
        n_ref, ref_seconds = reference_rate(shapes, ref_states)
        ref_rate = n_ref / ref_seconds if ref_seconds > 0 else float("inf")
        row = {
            "instance": name,
            "pieces": len(shapes),
            **info,
            **extra,
            "seconds": round(best, 4),
            "states": states,
            "states_per_s": round(ours_rate),
            "reference_states_per_s": round(ref_rate, 1),
            "speedup": round(ours_rate / ref_rate, 1) if ref_rate > 0 else None,
        }
        rows.append(row)
        print(json.dumps(row, sort_keys=True), flush=True)
    if rows:
        total = sum(float(str(r["seconds"])) for r in rows)
        print(
            json.dumps({"instances": len(rows), "seconds_per_puzzle": round(total / len(rows), 4)})
        )
    return 0
