"""BurrTools' problem semantics in the assembler and disassembler, checked against the naive
oracle of :mod:`tests.support.bt_reference` (no shared code), on random problems and on the example
files (:mod:`chaingeo.generator.bt_examples`)."""

from __future__ import annotations

import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.cli.main import main
from chaingeo.core.formats.burrtools import BTPuzzle, parse_xmpuzzle, xmpuzzle_bytes
from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import SearchLimitError
from chaingeo.generator.bt_examples import EXAMPLES, staircase
from chaingeo.generator.maze import runs, with_exit
from chaingeo.solvers.assembly.btassemble import (
    Mirrors,
    bt_packing_spec,
    disassemble,
    iter_classes,
    named_assembly,
)
from chaingeo.solvers.assembly.btcount import StuckCheck, count_bt
from chaingeo.solvers.assembly.groups import PieceGroups, assignable
from chaingeo.solvers.cover.constrained import compile_packing
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.disassemble import Separation, Separations, _Solver, analyze_assembly
from tests.support import bt_reference as ref
from tests.support.bt_instances import random_puzzle, reference_parts
from tests.support.paths import DATA
from tests.support.scenes import level_or_error


def oracle(puzzle: BTPuzzle, index: int = 0, *, solutions: bool = False) -> dict[str, int]:
    """Assemblies with mirror images kept and dropped (and solutions, kept) by the oracle."""
    prob = puzzle.problems[index]
    res = puzzle.shapes[prob.result]
    parts = reference_parts(puzzle, index)
    fixed, var = frozenset(res.filled.cells), frozenset(res.variable.cells)
    color = dict(res.colors)

    def allowed(a: int, b: int) -> bool:
        return prob.placement_allowed(a, b, len(puzzle.colors))

    found = ref.assemblies(parts, fixed, var, color, allowed, prob.max_holes)
    out = {}
    for name, mirrors in (("keep", False), ("drop", True)):
        reps = ref.classes(found, parts, ref.symmetries(fixed, var, color, mirrors))
        out[name] = len(reps)
        if solutions and name == "keep":
            n = 0
            for a in reps:
                placed = sorted(a, key=lambda ip: (ip[0], sorted(ip[1])))
                pieces = {f"q{k}": frozenset(v for v, _ in p) for k, (_, p) in enumerate(placed)}
                groups = {f"q{k}": parts[i].group for k, (i, _) in enumerate(placed)}
                n += len(pieces) == 1 or ref.comes_apart(pieces, groups)
            out["solutions"] = n
    return out


def ours(puzzle: BTPuzzle, index: int = 0, *, solutions: bool = False) -> dict[str, int]:
    """Our counts under the oracle's semantics: congruent shapes merged, any separation whose
    parts come apart (the named options; BurrTools' own defaults are checked against burrTxt
    in tests/conformance/test_burrtxt_diff.py)."""
    packing = compile_packing(bt_packing_spec(puzzle, index, merge_congruent=True))
    out: dict[str, int] = {}
    for mirrors in ("keep", "drop"):
        m: Mirrors = "keep" if mirrors == "keep" else "drop"
        out[mirrors] = sum(1 for _ in iter_classes(packing, mirrors=m))
    if solutions:
        out["solutions"] = count_bt(packing, separations="any").solutions
    return out


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10**6))
def test_random_problems_match_the_oracle(seed: int) -> None:
    """Colours and colour rules, variable cells (pieces may lie wholly on them), ranges, a
    hole cap, mirror images kept or dropped: our counts are the oracle's."""
    puzzle = parse_xmpuzzle(xmpuzzle_bytes(random_puzzle(seed, small=True)))
    assert ours(puzzle, solutions=True) == oracle(puzzle, solutions=True)


@pytest.mark.slow
@settings(max_examples=200, deadline=None)
@given(st.integers(0, 10**6))
def test_random_problems_match_the_oracle_more(seed: int) -> None:
    puzzle = parse_xmpuzzle(xmpuzzle_bytes(random_puzzle(seed)))
    assert ours(puzzle) == oracle(puzzle)


def test_a_coloured_voxel_distinguishes_orientations() -> None:
    """A domino with one red end in a 1x1x2 slot: two assemblies without colour rules that
    bind it (the red end either way), one when the slot's end says where red goes."""
    from chaingeo.core.formats.burrtools import BTPart, BTProblem, colored_shape

    domino = colored_shape("d", Shape([(0, 0, 0), (1, 0, 0)]), None, {(0, 0, 0): 1})
    slot = Shape([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)])
    free = colored_shape("r", slot, None, {})
    bound = colored_shape("r", slot, None, {(0, 0, 0): 1, (1, 0, 0): 2, (0, 1, 0): 2, (1, 1, 0): 1})
    for result, pairs, expect in ((free, (), 2), (bound, ((1, 1),), 1)):
        puzzle = BTPuzzle(
            (domino, result),
            (BTProblem("p", (BTPart(0, 2, 2),), 1, color_pairs=pairs),),
            colors=((255, 0, 0), (0, 0, 255)),
        )
        assert ours(puzzle)["keep"] == oracle(puzzle)["keep"] == expect


def test_soma_problems_ranges_and_mirrors() -> None:
    """Several problems in one file; with ranges a mirror image merges with its assembly only
    when it is an assembly too (not when it needs the missing left screw)."""
    puzzle = EXAMPLES["soma_problems"]()
    assert ours(puzzle, 2) == oracle(puzzle, 2) == {"keep": 20, "drop": 18}
    assert ours(puzzle, 1) == {"keep": 122, "drop": 61}  # the oracle agrees (slow test below)


@pytest.mark.slow
@pytest.mark.parametrize(("index", "counts"), [(0, (480, 240)), (1, (122, 61))])
def test_soma_problems_match_the_oracle(index: int, counts: tuple[int, int]) -> None:
    puzzle = EXAMPLES["soma_problems"]()
    assert ours(puzzle, index) == oracle(puzzle, index) == {"keep": counts[0], "drop": counts[1]}


def test_linked_rings_need_not_come_apart_in_their_group() -> None:
    """The rings never come apart; in one group they need not, so both assemblies (with and
    without the lid on the variable top layer) are solutions. Without the group the first
    assembly is not one."""
    puzzle = EXAMPLES["linked_rings"]()
    assert ours(puzzle, solutions=True) == oracle(puzzle, solutions=True)
    packing = compile_packing(bt_packing_spec(puzzle, 0, merge_congruent=True))
    report = count_bt(packing)
    assert (report.assemblies, report.solutions) == (2, 2)
    assert report.first_analysis is not None and report.first_analysis.level == "1"
    # BurrTools tells the two congruent rings apart (burrTxt: 6 assemblies, 6 solutions).
    distinct = count_bt(compile_packing(bt_packing_spec(puzzle, 0)), mirrors="drop")
    assert (distinct.assemblies, distinct.solutions) == (6, 6)
    without_lid = next(
        named_assembly(packing, rows)
        for rows in iter_classes(packing)
        if len(named_assembly(packing, rows)) == 3
    )
    assert disassemble(packing, without_lid).disassemblable
    assert not analyze_assembly(without_lid, optimal=False).disassemblable


def test_group_counts_bound_stuck_parts() -> None:
    """Rule 2: stuck parts go into a group that all their shapes have, within its counts."""
    groups = PieceGroups(
        {"a": "A", "a2": "A", "b": "B"},
        {"a": ((1, 1), (2, 1)), "a2": ((1, 1), (2, 1)), "b": ((1, 2),)},
    )
    assert assignable([["a", "b"]], groups)
    assert assignable([["a", "b"], ["a2"]], groups)  # a2 goes to group 2
    assert not assignable([["a", "a2", "b"]], groups)  # shape A only once in group 1
    assert not assignable([["a"], ["a2"], ["b", "a"]], groups)
    assert groups.single_group(["b"]) == 1 and groups.single_group(["a"]) == 0


def test_ring_maze_level_is_the_mazes_runs() -> None:
    puzzle = EXAMPLES["ring_maze"]()
    packing = compile_packing(bt_packing_spec(puzzle, 0))
    assert packing.hole_type >= 0  # the ring lies wholly on variable cells
    report = count_bt(packing)
    assert (report.assemblies, report.solutions) == (2, 2)
    assert report.first_analysis is not None and report.first_analysis.level == "17"
    assert report.first_packing is not None
    pin_and_ring = {n: s for n, s in report.first_packing.items() if len(s) < 20}
    assert len(pin_and_ring) == 2
    assert not analyze_assembly(
        pin_and_ring, optimal=False
    ).disassemblable  # the ring never comes off


def test_deep_maze_level_above_50() -> None:
    puzzle = EXAMPLES["deep_maze"]()
    report = count_bt(compile_packing(bt_packing_spec(puzzle, 0)))
    assert (report.assemblies, report.solutions) == (1, 1)
    assert report.first_analysis is not None
    assert report.first_analysis.level == str(runs(with_exit(staircase(26), 26))) == "51"


@pytest.mark.slow
def test_ring_maze_counts_match_the_oracle() -> None:
    puzzle = EXAMPLES["ring_maze"]()
    assert ours(puzzle) == oracle(puzzle)


@pytest.mark.slow
@pytest.mark.parametrize("mirrors", ["keep", "drop"])
def test_colour_rules_match_filtering_every_uncoloured_packing(mirrors: Mirrors) -> None:
    """The colour example (7880 packings up to rotation without colours) the slow way: every
    packing of the uncoloured problem by the plain engine, every coloured orientation of each
    piece checked voxel by voxel, classes under the coloured box's symmetries (the previous
    engine of ``chain bench burrtools``; the naive oracle would take hours here)."""
    from chaingeo.benchmarks.burrtools import previous_colours

    puzzle = EXAMPLES["colour_pentominoes"]()
    slow = previous_colours(puzzle, 0, SearchLimits(), mirrors)
    fast = count_bt(compile_packing(bt_packing_spec(puzzle, 0)), mirrors=mirrors)
    assert (fast.assemblies, fast.solutions) == (slow["assemblies"], slow["solutions"])
    assert fast.assemblies == {"keep": 82, "drop": 41}[mirrors]


@pytest.mark.slow
def test_solid_burrs_built_by_us_reproduce_burrtools() -> None:
    packing = compile_packing(bt_packing_spec(EXAMPLES["solid_burrs"](), 0))
    keep, drop = count_bt(packing), count_bt(packing, mirrors="drop")
    assert (keep.assemblies, keep.solutions, drop.assemblies, drop.solutions) == (
        1063,
        314,
        588,
        179,
    )


def test_stuck_check_is_exactly_no_first_move() -> None:
    """The assembler skips the search of an assembly where nothing moves: on solid six-piece
    burrs that is 745 of 1063 assemblies, and exactly those whose search has one state."""
    packing = compile_packing(bt_packing_spec(EXAMPLES["solid_burrs"](), 0))
    stuck = StuckCheck(packing)
    verdicts = []
    for rows in iter_classes(packing):
        found = analyze_assembly(named_assembly(packing, rows), optimal=False, fallback=False)
        verdicts.append((stuck(rows), not found.disassemblable and found.states == 1))
    assert all(s == one for s, one in verdicts)
    assert sum(s for s, _ in verdicts) == 745


@pytest.mark.parametrize("separations", ["first", "any"])
@pytest.mark.parametrize("total", [None, 20])
def test_level_kernel_matches_python_search_on_solid_burrs(
    total: int | None, separations: Separations
) -> None:
    """Every solid six-piece burr assembly that can move gets the same tree and state count
    (or, under a total state cap, the same error) from the level kernel as from the Python
    search, BurrTools' way and the way of any separation (whose stuck components both
    remember); the cap fires once a finished sub-part search has counted its states."""
    packing = compile_packing(bt_packing_spec(EXAMPLES["solid_burrs"](), 0))
    stuck = StuckCheck(packing)
    limits = SearchLimits(max_total_states=total)
    errors = solved = 0
    for rows in iter_classes(packing):
        if stuck(rows):
            continue
        shapes = named_assembly(packing, rows)
        fast = level_or_error(_Solver(shapes, None, limits, separations=separations), True)
        slow = level_or_error(_Solver(shapes, None, limits, separations=separations), False)
        assert fast == slow
        errors += fast[1] == -1
        solved += isinstance(fast[0], Separation)
    assert (errors > 0) == (total is not None)
    if total is None:  # BurrTools' figure with mirror images kept: 314; any way finds more
        assert solved == 314 if separations == "first" else solved >= 314


def test_state_caps_are_reported_not_swallowed() -> None:
    packing = compile_packing(bt_packing_spec(EXAMPLES["deep_maze"](), 0))
    with pytest.raises(SearchLimitError):
        count_bt(packing, limits=SearchLimits(max_states=20))


def test_chain_analyze_lists_every_problem(
    tmp_path: object, capsys: pytest.CaptureFixture[str]
) -> None:
    from pathlib import Path

    from chaingeo.core.formats.burrtools import write_xmpuzzle

    soma = EXAMPLES["soma_problems"]()
    small = BTPuzzle(soma.shapes, soma.problems[1:], colors=soma.colors)
    path = write_xmpuzzle(small, Path(str(tmp_path)) / "two.xmpuzzle")
    assert main(["analyze", str(path), "--no-optimal", "--mirrors", "keep"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [(p["problem"], p["assemblies"], p["solutions"]) for p in out["problems"]] == [
        (0, 122, 122),
        (1, 20, 20),
    ]
    assert {p["convention"] for p in out["problems"]} == {"mirrors-kept"}
    assert main(["analyze", str(path), "--no-optimal"]) == 0  # burrTxt's figures by default
    out = json.loads(capsys.readouterr().out)
    assert [(p["assemblies"], p["convention"]) for p in out["problems"]] == [
        (61, "burrtxt"),
        (18, "burrtxt"),
    ]
    assert main(["analyze", str(path), "--problem", "1"]) == 0
    one = json.loads(capsys.readouterr().out)
    assert (one["problem"], one["name"], one["assemblies"], one["solutions"]) == (
        1,
        "without B",
        18,
        18,
    )
    assert one["optimal_steps"] == one["moves"] == 3
    assert main(["analyze", str(path), "--problem", "5"]) == 2
    assert "problem 5 does not exist" in capsys.readouterr().err


def test_chain_analyze_gives_o_i_with_groups(capsys: pytest.CaptureFixture[str]) -> None:
    """The pin and ring are one group: the ring's way off the maze is the whole plan (17
    moves, BurrTools' level), and no shorter one exists
    (tests/solvers/assembly/test_group_optimal.py checks plans and bounds)."""
    path = DATA / "burrtools" / "ring_maze.xmpuzzle"
    assert main(["analyze", str(path)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert (out["assemblies"], out["solutions"], out["level"], out["moves"]) == (2, 2, "17", 17)
    assert out["optimal_steps"] == 17 and "optimal_error" not in out


def test_bench_burrtools_quick(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bench", "burrtools", "--quick", "--repeat", "1"]) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    rows = {r["instance"]: r for r in summary["rows"]}
    assert set(rows) == {"linked_rings", "ring_maze", "deep_maze", "soma_problems#2"}
    assert rows["deep_maze"]["ours"]["level"] == "51"
    assert rows["ring_maze"]["ours"]["solutions"] == 2
    assert rows["ring_maze"]["previous"]["assemblies"] == 0  # the ring lies on variable cells
    assert all(r["speedup"] is not None for r in rows.values())


def test_one_piece_is_no_solution_burrtools_way() -> None:
    """BurrTools does not disassemble an assembly of one piece (``disassembler_a.cpp``,
    ``disassemble``): of the 3 assemblies here (the domino alone on the fixed cells; the domino
    and the cube, the cube at either end) burrTxt counts 2 solutions."""
    from chaingeo.core.formats.burrtools import BTPart, BTProblem, colored_shape

    domino = colored_shape("a", Shape([(0, 0, 0), (1, 0, 0)]))
    cube = colored_shape("b", Shape([(0, 0, 0)]))
    result = colored_shape("r", Shape([(0, 0, 0), (1, 0, 0), (2, 0, 0)]), Shape([(2, 0, 0)]))
    puzzle = BTPuzzle(
        (domino, cube, result), (BTProblem("p", (BTPart(0, 1, 1), BTPart(1, 0, 1)), 2),)
    )
    packing = compile_packing(bt_packing_spec(puzzle, 0))
    first = count_bt(packing, mirrors="drop")
    assert (first.assemblies, first.solutions) == (3, 2)
    assert count_bt(packing, mirrors="drop", separations="any").solutions == 3
