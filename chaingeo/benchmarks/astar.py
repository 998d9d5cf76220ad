"""``chain bench astar``: o_i by A* with pattern databases against the branch-and-bound search.

Both searches run in this process on the same puzzle, one after the other (the machines are
shared, so compare the ratios of one run, not seconds across runs). Instances: the shipped
suite levels of at most 12 pieces (their own ``max_group``), BurrTools' AlPackino, PelikanBurr
and DraculasDentalDesaster (problem 0, from ``$CHAIN_BURRTOOLS_EXAMPLES`` or
``../shared/burrtools``, when present) and the 36-piece towers of the suite
played with multi-piece moves (``max_group`` None instead of the file's 1). On towers (levels
named ``burr12`` ... ``burr36``) the class bound of :mod:`chaingeo.solvers.optimal.classbound` over
the burr units is printed too (``class_bound``, its ``class_bound_classes`` and seconds), and
``plan_moves``, the shorter of the BurrTools-style plan and the units taken out one by one from the
ends of the stack (each by its own optimal plan,
:func:`chaingeo.solvers.optimal.blockbound.end_first_plan`, replayed with the reference kinematics):
o_i lies between them. Then the search under the class bound
(:mod:`chaingeo.solvers.optimal.classsearch`) closes the gap: ``class_search_o_i`` (its plan
replayed), ``class_search_nodes`` and ``class_search_seconds``, or ``class_search_bound`` when it
stops at its cap (``CHAIN_BENCH_CLASS_SEARCH_SECONDS``, default 900).

Per instance and search: ``o_i`` (or the cap it stopped at), ``seconds``, and the states:
``astar_expanded`` / ``astar_stored`` whole states, ``bfs_states`` the states the
branch-and-bound search stored over all its part searches (:attr:`Analysis.states`),
``plain_*`` the same search without peeling free pieces
(:mod:`chaingeo.solvers.motion.optimal_part`), and
``astar_bound``: A*'s proven lower bound when it stops at a cap. JIT compilation is excluded
(a warm-up runs first). Caps: ``CHAIN_BENCH_ASTAR_STATES`` stored A* states (default
2,000,000) and ``CHAIN_BENCH_ASTAR_SECONDS`` per search (default 60); ``CHAIN_BENCH_ASTAR_ONLY``:
run only the instances whose name contains it. ``--quick``: three suite levels only.
A* expands partially (:mod:`chaingeo.solvers.optimal.astar`), so ``astar_expanded`` counts partial
expansions.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import time
from collections.abc import Mapping
from pathlib import Path

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import SearchLimitError

Instance = tuple[str, dict[str, Shape], int | None]

#: BurrTools' example files benched (problem 0, its stored assembly), from
#: ``$CHAIN_BURRTOOLS_EXAMPLES`` or ``../shared/burrtools`` when present.
BT_FILES = ("AlPackino", "PelikanBurr", "DraculasDentalDesaster")


def _instances(quick: bool) -> list[Instance]:
    from chaingeo.core.level import load_levels
    from chaingeo.core.rules import PuzzleRules

    root = Path(__file__).resolve().parents[2]
    suite = root / "levels" / "puzzle"
    levels = load_levels(suite) if suite.is_dir() else []
    out: list[Instance] = []
    # translations only: A* does not search turns
    small = [
        lv
        for lv in levels
        if len(lv.shapes) <= 12 and not (isinstance(lv.rules, PuzzleRules) and lv.rules.turns)
    ]
    for lv in small[:3] if quick else small:
        mg = lv.rules.max_group if isinstance(lv.rules, PuzzleRules) else None
        out.append((lv.id, lv.shapes, mg))
    if quick:
        return out
    env = os.environ.get("CHAIN_BURRTOOLS_DIR")
    bt = Path(env) if env else root.parent / "shared" / "burrtools"
    examples = os.environ.get("CHAIN_BURRTOOLS_EXAMPLES")
    folders = [*([Path(examples)] if examples else []), bt]
    for name in BT_FILES:
        path = next((p for f in folders if (p := f / f"{name}.xmpuzzle").is_file()), None)
        if path is not None:
            from chaingeo.core.formats.burrtools import read_xmpuzzle

            (asm,) = read_xmpuzzle(path).assemblies(0)
            out.append((name, {f"p{k:02d}": s for k, s in asm.items()}, None))
    for tower in [lv for lv in levels if re.search(r"burr36", lv.id)]:
        out.append((f"{tower.id} (max_group None)", tower.shapes, None))
    return out


def _class_bound(name: str, shapes: Mapping[str, Shape]) -> dict[str, object]:
    """Class bound and plan length of a tower of burr units (six layers each)."""
    if not re.search(r"burr(12|18|24|36)\b", name):
        return {}
    from chaingeo.solvers.motion.disassemble import analyze_assembly, translations
    from chaingeo.solvers.optimal.blockbound import end_first_plan
    from chaingeo.solvers.optimal.classbound import band_blocks, class_lower_bound

    t0 = time.perf_counter()
    blocks = band_blocks(shapes, 6)
    found = class_lower_bound(shapes, blocks)
    seconds = round(time.perf_counter() - t0, 3)
    plan = analyze_assembly(shapes, max_group=None, optimal=False).moves
    own = [
        translations(analyze_assembly({n: shapes[n] for n in b}, max_group=None).plan)
        for b in blocks
    ]
    stack = end_first_plan(shapes, blocks, own)  # units one by one from the ends, replayed
    classes = " ".join(f"{'xyz'[a]}{k}x{c}" for (a, k), c in found.classes)
    return {
        "class_bound": found.bound if found.complete else f">= {found.bound}",
        "class_bound_classes": classes,
        "class_bound_seconds": seconds,
        "plan_moves": min(
            m for m in (plan, None if stack is None else len(stack)) if m is not None
        ),
        **_class_search(shapes, blocks),
    }


def _class_search(shapes: Mapping[str, Shape], blocks: list[list[str]]) -> dict[str, object]:
    """o_i by the search under the class bound, its plan replayed, or its proven bound."""
    from chaingeo.core.kinematics import replay_disassembly
    from chaingeo.solvers.optimal.classsearch import ClassSearchLimits, class_search_optimal

    seconds = float(os.environ.get("CHAIN_BENCH_CLASS_SEARCH_SECONDS", "900"))
    t0 = time.perf_counter()
    try:
        r = class_search_optimal(shapes, blocks, limits=ClassSearchLimits(seconds=seconds))
    except SearchLimitError as e:
        bound = re.search(r"lower bound (\d+)", str(e))
        return {
            "class_search_bound": int(bound.group(1)) if bound else None,
            "class_search_seconds": round(time.perf_counter() - t0, 3),
        }
    return {
        "class_search_o_i": r.optimal_steps,
        "class_search_replayed": replay_disassembly(shapes, r.plan).is_separated(),
        "class_search_nodes": r.nodes,
        "class_search_children": r.children,
        "class_search_seconds": round(time.perf_counter() - t0, 3),
    }


def _astar(
    shapes: Mapping[str, Shape], max_group: int | None, states: int, seconds: float
) -> dict[str, object]:
    from chaingeo.solvers.optimal.astar import AStarLimits, astar_optimal

    t0 = time.perf_counter()
    limits = AStarLimits(max_states=states, seconds=seconds)
    try:
        r = astar_optimal(shapes, max_group=max_group, limits=limits)
    except SearchLimitError as e:
        bound = re.search(r"lower bound (\d+)", str(e))
        return {
            "astar_o_i": None,
            "astar_stopped": str(e).split(";")[0],
            "astar_bound": int(bound.group(1)) if bound else None,
            "astar_seconds": round(time.perf_counter() - t0, 3),
        }
    return {
        "astar_o_i": r.optimal_steps,
        "astar_expanded": r.expanded,
        "astar_stored": r.states,
        "astar_start_bound": r.start_bound,
        "astar_pdb_states": r.pdb_states,
        "astar_seconds": round(time.perf_counter() - t0, 3),
    }


def _bfs(
    shapes: Mapping[str, Shape], max_group: int | None, seconds: float, peel: bool = True
) -> dict[str, object]:
    """The branch and bound (``bfs_*``), or without peeling free pieces (``plain_*``)."""
    from chaingeo.solvers.limits import SearchLimits
    from chaingeo.solvers.motion.disassemble import analyze_assembly

    key = "bfs" if peel else "plain"
    limits = SearchLimits(seconds=seconds)
    t0 = time.perf_counter()
    try:
        a = analyze_assembly(shapes, max_group=max_group, limits=limits, peel=peel)
    except SearchLimitError as e:
        return {
            f"{key}_o_i": None,
            f"{key}_stopped": str(e).split(";")[0],
            f"{key}_seconds": round(time.perf_counter() - t0, 3),
        }
    return {
        f"{key}_o_i": a.optimal_steps,
        f"{key}_states": a.states,
        f"{key}_seconds": round(time.perf_counter() - t0, 3),
    }


def run(args: argparse.Namespace) -> int:
    states = int(os.environ.get("CHAIN_BENCH_ASTAR_STATES", "2000000"))
    seconds = float(os.environ.get("CHAIN_BENCH_ASTAR_SECONDS", "60"))
    warm = {"a": Shape([(0, 0, 0), (1, 0, 0)]), "b": Shape([(0, 1, 0), (1, 1, 0)])}
    _astar(warm, None, states, seconds)  # JIT warm-up, not timed
    _bfs(warm, None, seconds)
    only = os.environ.get("CHAIN_BENCH_ASTAR_ONLY", "")
    for name, shapes, max_group in _instances(args.quick):
        if only not in name:
            continue
        row: dict[str, object] = {"instance": name, "pieces": len(shapes), "max_group": max_group}
        row.update(_astar(shapes, max_group, states, seconds))
        row.update(_bfs(shapes, max_group, seconds))
        row.update(_bfs(shapes, max_group, seconds, peel=False))
        if max_group is None:
            row.update(_class_bound(name, shapes))
        a_s, b_s = row.get("astar_seconds"), row.get("bfs_seconds")
        if row.get("astar_o_i") is not None and row.get("bfs_o_i") is not None:
            row["seconds_ratio_bfs_over_astar"] = round(
                float(str(b_s)) / max(float(str(a_s)), 1e-4), 2
            )
        print(json.dumps(row, sort_keys=True), flush=True)
    return 0
