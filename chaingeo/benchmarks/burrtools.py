"""``chain bench burrtools``: BurrTools problems, our whole analysis against the previous engine.

Instances: every example of :mod:`chaingeo.generator.bt_examples` (one per problem feature: colour
rules, piece groups with variable cells, ranges and several problems, mirror images, a level-51
maze, the solid burr catalogue), plus BurrTools' own example files when present
(``../shared/burrtools`` or ``CHAIN_BURRTOOLS_DIR``). For each problem, ``ours`` is what
``chain analyze --no-optimal`` does (:func:`chaingeo.solvers.analysis.problem_analysis_row`:
BurrTools' assemblies and solutions, then level and moves of the first solution; o_i is left
out, being no BurrTools figure and the same code in both engines) and ``previous`` the engine before
BurrTools' semantics, timed in the same run:

* on a problem with colour rules, ``previous`` counts without them and filters after: every
  packing of the uncoloured problem (:func:`chaingeo.solvers.cover.packings.iter_packings`), each
  coloured orientation of each piece checked voxel by voxel, classes of the survivors under the
  coloured result's symmetries, then the disassembler on those classes only (the same figures
  as ours, reached the slow way);
* elsewhere ``previous`` is the old ``chain analyze``
  (:func:`chaingeo.solvers.assembly.assemble.count_assemblies` on the uncoloured, ungrouped
  problem): its figures differ where groups, hole caps or pieces lying wholly on variable cells
  matter (the ring maze: 0 assemblies, the ring is never placed; the linked rings: no solution, the
  rings never come apart).

``speedup`` is previous / ours (wall clock; the best of ``--repeat`` runs, a run over 10 s not
repeated; ``agree`` says whether the previous engine's figures are ours). Every run builds
its problem from scratch (the engines' placement caches are cleared first); JIT compilation is
excluded: both engines run a small problem first. ``--quick``: four small instances, previous
engine capped at 5 s. Last (not with ``--quick``), when burrTxt can be built here, the
whole-process comparison with BurrTools itself (:mod:`chaingeo.benchmarks.burrtxt`, also
``chain bench burrtxt`` alone). ``CHAIN_BENCH_BT_SECONDS`` sets the time limit of each search
(default 120, as ``chain analyze``).
"""

from __future__ import annotations

import argparse
import json
import os
import time
from collections.abc import Callable, Mapping
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from chaingeo.core.formats.burrtools import BTPuzzle, read_xmpuzzle
from chaingeo.core.geometry import ROTATIONS, Shape
from chaingeo.core.kinematics import SearchLimitError

#: BurrTools' own figures for its example files (README of the shared folder).
BURRTOOLS_FIGURES: dict[tuple[str, int, str], tuple[int, int]] = {
    ("AlPackino", 0, "keep"): (1, 1),
    ("SolidSixPieceBurrs", 0, "keep"): (1063, 314),
    ("SolidSixPieceBurrs", 0, "drop"): (588, 179),
}
LONG_RUN_SECONDS = 10.0
QUICK = ("linked_rings", "ring_maze", "deep_maze", "soma_problems#2")

Instance = tuple[str, BTPuzzle, int, str]  # name, puzzle, problem, mirrors


def _instances(quick: bool) -> list[Instance]:
    from chaingeo.generator.bt_examples import EXAMPLES

    out: list[Instance] = []
    for name, build in EXAMPLES.items():
        puzzle = build()
        for index in range(len(puzzle.problems)):
            label = name if len(puzzle.problems) == 1 else f"{name}#{index}"
            out.append((label, puzzle, index, "keep"))
    out.append(("solid_burrs", EXAMPLES["solid_burrs"](), 0, "drop"))
    env = os.environ.get("CHAIN_BURRTOOLS_DIR")
    shared = Path(env) if env else Path(__file__).resolve().parents[3] / "shared" / "burrtools"
    if shared.is_dir():
        for path in sorted(shared.glob("*.xmpuzzle")):
            puzzle = read_xmpuzzle(path)
            for index in range(len(puzzle.problems)):
                for mirrors in ("keep", "drop") if path.stem == "SolidSixPieceBurrs" else ("keep",):
                    out.append((path.stem, puzzle, index, mirrors))
    if quick:
        out = [i for i in out if i[0] in QUICK and i[3] == "keep"]
    return out


# -- the previous engine ----------------------------------------------------------------------


def previous_plain(puzzle: BTPuzzle, index: int, limits: Any, mirrors: str) -> dict[str, Any]:
    """The old ``chain analyze`` on a ``.xmpuzzle`` problem: colours, groups and hole caps
    unknown to it."""
    from chaingeo.solvers.analysis import disassembly_figures
    from chaingeo.solvers.assembly.assemble import count_assemblies
    from chaingeo.solvers.cover.problem import PieceSpec

    prob = puzzle.problem(index)
    result = puzzle.shapes[prob.result]
    pieces = [
        PieceSpec(puzzle.shapes[p.shape].filled, f"s{p.shape}p{k}", p.min, p.max)
        for k, p in enumerate(prob.parts)
        if len(puzzle.shapes[p.shape].filled)
    ]
    rep = count_assemblies(
        pieces,
        result.cells,
        optional=result.variable if len(result.variable) else None,
        mirror_distinct=mirrors == "keep",
        limits=limits,
    )
    out: dict[str, Any] = {"assemblies": rep.assemblies, "solutions": rep.solutions}
    if rep.first_packing is not None:
        figures = disassembly_figures(
            rep.first_packing, max_group=None, limits=limits, optimal=False
        )
        out.update(level=figures["level"], moves=figures["moves"])
    return out


Voxels = frozenset[tuple[tuple[int, int, int], int]]


def _colour_variants(
    placed: Shape, piece: Shape, cmap: Mapping[tuple[int, int, int], int]
) -> list[Voxels]:
    """Every way the coloured piece can be the placed voxels (one per coloured orientation
    with the same voxels)."""
    target = placed.normalized().cells
    shift = placed.min_corner
    out: set[Voxels] = set()
    for m in ROTATIONS:
        v = piece.voxels @ np.asarray(m).T
        lo = v.min(axis=0)
        moved = [tuple(int(a) for a in row) for row in (v - lo)]
        if sorted(moved) != list(target):
            continue
        colours = [cmap.get(c, 0) for c in piece.cells]
        out.add(
            frozenset(
                ((c[0] + int(shift[0]), c[1] + int(shift[1]), c[2] + int(shift[2])), k)
                for c, k in zip(moved, colours, strict=True)
            )
        )
    return sorted(out, key=sorted)


def previous_colours(puzzle: BTPuzzle, index: int, limits: Any, mirrors: str) -> dict[str, Any]:
    """Colour rules the slow way: every uncoloured packing, filtered voxel by voxel."""
    import itertools

    from chaingeo.solvers.analysis import disassembly_figures
    from chaingeo.solvers.cover.packings import iter_packings
    from chaingeo.solvers.cover.placements import target_symmetries
    from chaingeo.solvers.cover.problem import PieceSpec
    from chaingeo.solvers.motion.disassemble import analyze_assembly

    prob = puzzle.problem(index)
    res = puzzle.shapes[prob.result]
    n_colors = len(puzzle.colors)
    specs = [
        PieceSpec(puzzle.shapes[p.shape].filled, f"k{k}", p.min, p.max)
        for k, p in enumerate(prob.parts)
    ]
    coloured = {f"k{k}": puzzle.shapes[p.shape] for k, p in enumerate(prob.parts)}
    rcol = res.color_map
    var = res.variable.cell_set
    group = [
        (m, t)
        for m, t in target_symmetries(res.cells, reflections=mirrors == "drop")
        if all(
            rcol.get(c, 0) == rcol.get(_image(m, t, c), 0)
            and (c in var) == (_image(m, t, c) in var)
            for c in res.cells.cells
        )
    ]
    seen: set[frozenset[Voxels]] = set()
    reps: list[frozenset[Voxels]] = []
    optional = res.variable if len(res.variable) else None
    for sol in iter_packings(specs, res.cells, optional=optional, reflections=False):
        choices = []
        for slot, placed in sol.placements:
            shape = coloured[slot.split("#")[0]]
            ok = [
                v
                for v in _colour_variants(placed, shape.filled, shape.color_map)
                if all(prob.placement_allowed(k, rcol.get(c, 0), n_colors) for c, k in v)
            ]
            choices.append(ok)
        for combo in itertools.product(*choices):
            assembly = frozenset(combo)
            if assembly in seen:
                continue
            reps.append(assembly)
            for m, t in group:
                seen.add(frozenset(frozenset((_image(m, t, c), k) for c, k in p) for p in assembly))
    out: dict[str, Any] = {"assemblies": len(reps), "solutions": 0}
    first = None
    for assembly in reps:
        shapes = {
            f"p{i}": Shape(sorted(c for c, _ in p))
            for i, p in enumerate(sorted(assembly, key=sorted))
        }
        if analyze_assembly(shapes, limits=limits, optimal=False).disassemblable:
            out["solutions"] += 1
            first = first or shapes
    if first is not None:
        figures = disassembly_figures(first, max_group=None, limits=limits, optimal=False)
        out.update(level=figures["level"], moves=figures["moves"])
    return out


def _image(m: np.ndarray, t: np.ndarray, c: tuple[int, int, int]) -> tuple[int, int, int]:
    v = np.asarray(m) @ np.asarray(c) + np.asarray(t)
    return int(v[0]), int(v[1]), int(v[2])


# -- timing -----------------------------------------------------------------------------------


def _from_scratch() -> None:
    """Forget the placements and problems the engines cache, so every run builds its own."""
    from chaingeo.solvers.cover.placements import _placements, target_index
    from chaingeo.solvers.cover.problem import _cover_problem

    for cached in (_placements, target_index, _cover_problem):
        cached.cache_clear()


def _timed(fn: Callable[[], dict[str, Any]], repeat: int) -> tuple[float, dict[str, Any]]:
    best, out = float("inf"), {}
    for _ in range(max(repeat, 1)):
        _from_scratch()
        t0 = time.perf_counter()
        try:
            out = fn()
        except SearchLimitError as e:
            out = {"error": str(e)}
        seconds = time.perf_counter() - t0
        best = min(best, seconds)
        if seconds > LONG_RUN_SECONDS or "error" in out:
            break
    return best, out


def _warm_up() -> None:
    """Compile every kernel both engines use (bit-board, dancing links, movement)."""
    from chaingeo.generator.bt_examples import linked_rings
    from chaingeo.solvers.analysis import RowOptions, problem_analysis_row
    from chaingeo.solvers.assembly.btassemble import bt_packing_spec
    from chaingeo.solvers.cover.constrained import compile_packing
    from chaingeo.solvers.cover.search import CoverSearch
    from chaingeo.solvers.limits import SearchLimits

    puzzle = linked_rings()
    problem_analysis_row(puzzle, 0, RowOptions(SearchLimits()))
    previous_plain(puzzle, 0, SearchLimits(max_states=1000), "keep")
    CoverSearch(compile_packing(bt_packing_spec(puzzle, 0)).problem, engine="dlx").count()


def run(args: argparse.Namespace) -> int:
    from chaingeo.solvers.analysis import RowOptions, problem_analysis_row
    from chaingeo.solvers.assembly.btassemble import Mirrors
    from chaingeo.solvers.limits import SearchLimits

    seconds = float(os.environ.get("CHAIN_BENCH_BT_SECONDS", "5" if args.quick else "120"))
    limits = SearchLimits(seconds=seconds)
    _warm_up()
    rows = []
    keys = ("assemblies", "solutions", "level", "moves", "error")
    for name, puzzle, index, mirrors in _instances(args.quick):
        mode: Mirrors = "drop" if mirrors == "drop" else "keep"
        ours_s, ours = _timed(
            partial(problem_analysis_row, puzzle, index, RowOptions(limits, False, True, mode)),
            args.repeat,
        )
        colours = bool(puzzle.colors and puzzle.problems[index].color_pairs)
        previous = previous_colours if colours else previous_plain
        prev_s, prev = _timed(partial(previous, puzzle, index, limits, mirrors), args.repeat)
        row: dict[str, Any] = {
            "instance": name,
            "problem": index,
            "mirrors": mirrors,
            "ours": {k: ours[k] for k in keys if k in ours},
            "seconds": round(ours_s, 4),
            "previous": {k: prev[k] for k in keys if k in prev},
            "previous_seconds": round(prev_s, 4),
            "previous_engine": "filter after an uncoloured count"
            if colours
            else "old chain analyze",
            "agree": all(prev.get(k) == ours.get(k) for k in ("assemblies", "solutions", "level")),
            "speedup": round(prev_s / ours_s, 2) if ours_s > 0 else None,
        }
        known = BURRTOOLS_FIGURES.get((name, index, mirrors))
        if known is not None:
            row["burrtools"] = {"assemblies": known[0], "solutions": known[1]}
        rows.append(row)
        print(json.dumps(row, sort_keys=True), flush=True)
    total = sum(float(r["seconds"]) for r in rows)
    print(
        json.dumps(
            {"instances": len(rows), "seconds": round(total, 3), "rows": rows}, sort_keys=True
        )
    )
    if args.quick:  # a smoke run; `chain bench burrtxt --quick` is the oracle's own
        return 0
    from chaingeo.benchmarks import burrtxt

    return burrtxt.run(args)
