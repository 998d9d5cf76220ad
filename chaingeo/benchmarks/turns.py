"""``chain bench turns``: the random episode ``chain eval`` plays on the level with turns, and its
legal turns, against the pure-Python reference timed in the same run.

``turns``: the legal turns at the first positions of that episode, ``ours`` (the numba kernel,
:func:`chaingeo.solvers.motion.turnsearch.turn_rows`, made into actions as the environment does)
against ``reference`` (:func:`chaingeo.core.kinematics.legal_turns`, seconds per position), checked
equal; ``speedup`` = reference / ours on the same positions. ``episode``: the random agent's
whole episode (seed 0, as ``chain eval --agent random`` plays it) on the shipped puzzle level
whose rules allow turns, where the parts drift wider than the stencil table reaches; ``ratio`` =
the first such episode in the process / the reference's listing of the start position (before
the fixed table the episode grew its own table, 80 s against 2.2 s). JIT compilation is excluded
(the start position's actions are listed first, untimed). ``--quick``: one reference position.
"""

from __future__ import annotations

import argparse
import json
import time
from typing import Any

from chaingeo.core.kinematics import Assembly, legal_turns
from chaingeo.core.level import Level, load_levels
from chaingeo.core.rules import PuzzleRules
from chaingeo.core.suite import suite_folder
from chaingeo.envs.machines.puzzle import PuzzleState
from chaingeo.envs.machines.puzzle_actions import turn_actions
from chaingeo.evaluation.agents.base import AgentSpec
from chaingeo.evaluation.play import EpisodeTask, run_episode
from chaingeo.solvers.motion.turns_kernel import TurnTable


def _episode(level: Level, repeat: int) -> tuple[float, float, dict[str, Any]]:
    """The first and the best of ``repeat`` timings of the seeded random episode, and its
    record (the first shows whatever a process builds as it goes, as ``chain eval`` pays it)."""
    times, record = [], {}
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        record = run_episode(EpisodeTask(level, 0, 0, AgentSpec("random"))).record
        times.append(time.perf_counter() - t0)
    return times[0], min(times), record


def _positions(level: Level, record: dict[str, Any]) -> list[Assembly]:
    """The positions the episode passed through, in order."""
    state = PuzzleState(level)
    out = [state.assembly]
    for step in record["steps"]:
        state.step_text(str(step["action"]))
        out.append(state.assembly)
    return out


def _span(asm: Assembly) -> int:
    """The widest part's extent in cells (the stencil table reaches 12 cells from an axis)."""
    out = 0
    for part in asm.parts:
        cells = [c for n in part for c in asm.cells_of(n)]
        out = max(out, *(max(c[t] for c in cells) - min(c[t] for c in cells) + 1 for t in range(3)))
    return out


def run(args: argparse.Namespace) -> int:
    suite = suite_folder("puzzle")
    levels = sorted(load_levels(suite) if suite.is_dir() else [], key=lambda lv: lv.id)
    turning = [lv for lv in levels if isinstance(lv.rules, PuzzleRules) and lv.rules.turns]
    if not turning:
        print(json.dumps({"error": f"no puzzle level with turns under {suite}"}))
        return 1
    level = turning[0]
    PuzzleState(level).legal_actions()[0].to_text()  # JIT warm-up at the start, not timed
    seconds, fastest, record = _episode(level, args.repeat)
    positions = _positions(level, record)
    mg = level.rules.max_group  # type: ignore[union-attr]
    table = TurnTable(level.shapes, level.rods)
    ours = ref = first = 0.0
    states = positions[: 1 if args.quick else 3]
    for asm in states:
        best = float("inf")
        for _ in range(max(1, args.repeat)):
            t0 = time.perf_counter()
            fast = turn_actions(asm, mg, table)
            best = min(best, time.perf_counter() - t0)
        ours += best
        t0 = time.perf_counter()
        slow = legal_turns(asm, mg)
        ref += time.perf_counter() - t0
        first = first or ref
        if sorted(a.turn for a in fast) != slow:
            raise AssertionError(f"{level.id}: fast and reference legal turns differ")
    rows: list[dict[str, Any]] = [
        {
            "turns": level.id,
            "states": len(states),
            "ours_ms_per_state": round(1000 * ours / len(states), 2),
            "reference_ms_per_state": round(1000 * ref / len(states), 1),
            "speedup": round(ref / ours, 1) if ours > 0 else None,
        },
        {
            "episode": level.id,
            "steps": len(record["steps"]),
            "widest_part_cells": max(_span(a) for a in positions),
            "seconds": round(seconds, 3),
            "best_seconds": round(fastest, 3),
            "reference_start_seconds": round(first, 3),
            "ratio": round(seconds / first, 3),
        },
    ]
    for row in rows:
        print(json.dumps(row, sort_keys=True), flush=True)
    return 0
