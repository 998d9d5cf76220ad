"""``chain bench actions``: a puzzle state's legal actions, fast and lazy, against the reference.

Instances: the 'assemble' levels of the shipped puzzle suite with the most pieces (up to 12,
where the reference takes seconds per state), at the
states along their optimal plan (pieces apart, then joined one insertion at a time) and along a
seeded random walk (loose parts, where groups and insertions are most numerous). ``ours`` is
``PuzzleState.legal_actions()`` on a fresh state (numba movement analysis and insertion kernel,
actions left lazy) plus building ``CHAIN_BENCH_PICKS`` of them (default 64: what an agent looks
at); ``reference`` builds the same list one action at a time with the pure-Python kinematics
(:func:`chaingeo.envs.machines.puzzle_actions.reference_actions`). ``speedup`` = reference / ours on
the same states in the same run; the two lists are checked equal on the first state of each level.
JIT compilation is excluded (a warm-up call runs first). ``--quick``: one level, three states.
"""

from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np

from chaingeo.core.kinematics import Assembly
from chaingeo.core.level import Level, load_levels
from chaingeo.core.suite import suite_folder
from chaingeo.envs.actions.types import action_of_move
from chaingeo.envs.machines.puzzle import PuzzleState
from chaingeo.envs.machines.puzzle_actions import reference_actions

#: The pure-Python reference takes seconds per state at 12 pieces; larger levels are left out.
REFERENCE_PIECES = 12


def _states(level: Level, walk: int, seed: int) -> list[PuzzleState]:
    """States on the recorded plan, then ``walk`` states of a seeded random walk."""
    state = PuzzleState(level)
    out = [state.clone()]
    for move in level.solution.moves:  # type: ignore[union-attr]
        state.apply(state.resolve(action_of_move(move)))
        out.append(state.clone())
    rng = np.random.default_rng(np.random.SeedSequence([seed, len(level.pieces)]))
    state = PuzzleState(level)
    for _ in range(walk):
        legal = state.legal_actions()
        if len(legal) < 2:
            break
        state.apply(legal[int(rng.integers(len(legal) - 1))])
        out.append(state.clone())
    return out


def _ours(asm: Assembly, level: Level, picks: int) -> tuple[float, int]:
    t0 = time.perf_counter()
    state = PuzzleState(level)
    state._asm = asm  # the position under test, on a fresh state (nothing cached)
    legal = state.legal_actions()
    n = len(legal)
    for i in np.linspace(0, n - 1, num=min(picks, n), dtype=np.int64).tolist():
        legal[i].to_text()
    return time.perf_counter() - t0, n


def run(args: argparse.Namespace) -> int:
    suite = suite_folder("puzzle")
    levels = [
        lv
        for lv in (load_levels(suite) if suite.is_dir() else [])
        if lv.goal == "assemble" and len(lv.pieces) <= REFERENCE_PIECES
    ]
    levels.sort(key=lambda lv: (-len(lv.pieces), lv.id))
    levels = levels[: 1 if args.quick else 3]
    picks = int(os.environ.get("CHAIN_BENCH_PICKS", "64"))
    walk = 2 if args.quick else 12
    if not levels:
        print(json.dumps({"error": f"no assemble levels under {suite}"}))
        return 1
    warm = _states(levels[0], 1, 0)[0]
    _ours(warm.assembly, levels[0], picks)  # JIT warm-up, not timed
    ours_total = ref_total = 0.0
    for level in levels:
        states = _states(level, walk, 0)[: 3 if args.quick else None]
        mg = level.rules.max_group  # type: ignore[union-attr]
        turns = level.rules.turns  # type: ignore[union-attr]
        first = states[0]
        if list(first.legal_actions()) != reference_actions(first.assembly, first.mode, mg, turns):
            raise AssertionError(f"{level.id}: fast and reference action lists differ")
        ours = ref = 0.0
        counts = []
        for s in states:
            best = float("inf")
            for _ in range(max(1, args.repeat)):
                seconds, n = _ours(s.assembly, level, picks)
                best = min(best, seconds)
            ours += best
            counts.append(n)
            t0 = time.perf_counter()
            reference_actions(s.assembly, s.mode, mg, turns)
            ref += time.perf_counter() - t0
        ours_total += ours
        ref_total += ref
        row = {
            "level": level.id,
            "pieces": len(level.pieces),
            "states": len(states),
            "actions_mean": round(sum(counts) / len(counts)),
            "actions_max": max(counts),
            "ours_ms_per_state": round(1000 * ours / len(states), 2),
            "reference_ms_per_state": round(1000 * ref / len(states), 1),
            "speedup": round(ref / ours, 1) if ours > 0 else None,
        }
        print(json.dumps(row, sort_keys=True), flush=True)
    print(json.dumps({"speedup_overall": round(ref_total / ours_total, 1)}))
    return 0
