"""The numba disassembly search agrees with the reference kinematics (the specification)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import (
    Assembly,
    Move,
    SearchLimitError,
    legal_moves,
    reference_optimal_disassembly,
    replay_disassembly,
    state_key,
)
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion import disassemble
from chaingeo.solvers.motion.disassemble import (
    Separation,
    Separations,
    _Solver,
    analyze_assembly,
    fast_legal_moves,
)
from chaingeo.solvers.motion.partsearch import PartSearch, PieceTable
from tests.support.puzzle_strategies import small_scenes
from tests.support.scenes import SCENE, level_or_error, random_walk


def test_scene_moves_match_reference() -> None:
    a = Assembly.assembled(SCENE)
    assert fast_legal_moves(a) == legal_moves(a)
    assert fast_legal_moves(a, max_group=1) == legal_moves(a, max_group=1)


@settings(max_examples=60)
@given(small_scenes(), st.integers(0, 10**6), st.integers(0, 6), st.sampled_from([None, 1, 2]))
def test_legal_moves_match_reference(
    shapes: dict[str, Shape], seed: int, steps: int, max_group: int | None
) -> None:
    state = random_walk(shapes, seed, steps)
    assert fast_legal_moves(state, max_group) == legal_moves(state, max_group)


@settings(max_examples=40)
@given(small_scenes(), st.integers(0, 10**6), st.integers(0, 4))
def test_successor_states_match_reference(shapes: dict[str, Shape], seed: int, steps: int) -> None:
    """One expansion of the numba search yields exactly the reference's successor states."""
    state = random_walk(shapes, seed, steps)
    part = max(state.parts, key=lambda p: (len(p), sorted(p)))
    if len(part) < 2:
        return
    sub = Assembly({n: state.shapes[n] for n in part}, {n: state.offsets[n] for n in part},
                   (part,))  # fmt: skip
    table = PieceTable(sub.shapes)
    members = tuple(range(len(table.names)))
    offsets = np.array([sub.offsets[n] for n in table.names])
    search = PartSearch(table, members, offsets, max_group=None, limits=SearchLimits(),
                        deadline=Deadline(None))  # fmt: skip
    removals = search.expand_layer()
    fast_children = set()
    for node in range(1, search.n_states):
        rel = search.offsets_of(node)
        fast_children.add(tuple(tuple(int(v) for v in row) for row in rel))
    ref_children = set()
    ref_splits = set()
    start = state_key(sub)
    for m in legal_moves(sub):
        child = sub.apply(m)
        if len(child.parts) > 1:
            ref_splits.add(frozenset(frozenset(p) for p in child.parts))
            continue
        ((_, rel_offsets),) = state_key(child)
        if state_key(child) != start:
            ref_children.add(rel_offsets)
    assert fast_children == ref_children
    fast_splits = set()
    for r in removals:
        rm, _, lm, _ = search.split(r)
        fast_splits.add(
            frozenset(
                [frozenset(table.names[i] for i in rm), frozenset(table.names[i] for i in lm)]
            )
        )
    assert fast_splits == ref_splits


@settings(max_examples=40)
@given(small_scenes(max_pieces=4), st.sampled_from([None, 1]))
def test_optimal_steps_match_reference_bfs(shapes: dict[str, Shape], max_group: int | None) -> None:
    ref = reference_optimal_disassembly(shapes, max_group)
    got = analyze_assembly(shapes, max_group=max_group)
    if ref is None:
        assert not got.disassemblable and got.optimal_steps is None
        return
    assert got.disassemblable
    assert got.optimal_steps == len(ref)
    assert replay_disassembly(shapes, got.plan).is_separated()
    assert got.moves is not None and got.moves >= len(ref)
    assert got.tree is not None and replay_disassembly(shapes, got.tree.all_moves()).is_separated()
    if max_group is not None:
        assert all(len(m.pieces) <= max_group for m in got.plan)


@settings(max_examples=60)
@given(
    small_scenes(),
    st.sampled_from([None, 1, 2]),
    st.sampled_from([1, 3, 20000]),
    st.sampled_from([None, 0, 3, 10]),
    st.sampled_from(["first", "any"]),
)
def test_level_kernel_matches_python_search(
    shapes: dict[str, Shape],
    max_group: int | None,
    budget: int,
    total: int | None,
    separations: Separations,
) -> None:
    """The one-call level kernels (BurrTools' first separation,
    :mod:`chaingeo.solvers.motion.btsearch`, and any separation,
    :mod:`chaingeo.solvers.motion.levelsearch`) find the same tree, with the same state count (or
    the same cap error), as the Python searches they stand for, also when they outgrow their buffers
    or their node budget."""
    if len(shapes) < 2:
        return
    limits = SearchLimits(max_total_states=total)
    mp = pytest.MonkeyPatch()
    mp.setattr(disassemble, "KERNEL_NODES", budget)
    mp.setattr(disassemble, "_TREE_ROWS", 1)
    try:
        fast = level_or_error(_Solver(shapes, max_group, limits, separations=separations), True)
    finally:
        mp.undo()
    # The plain Python search: its shortcut for stuck groups apart (test_apart.py)
    # keeps every tree but not every state count.
    mp.setattr(_Solver, "stuck_apart", lambda *_: False)
    try:
        slow = level_or_error(_Solver(shapes, max_group, limits, separations=separations), False)
    finally:
        mp.undo()
    assert fast == slow


def test_level_notation_follows_burrtools() -> None:
    m = Move(("red",), "+x", None)
    one = Separation((m,))
    three = Separation((m, m, m))
    tree = Separation((m,) * 4, removed=one, left=Separation((m,) * 9, left=three, removed=one))
    assert tree.level_text() == "4.9.3"
    assert tree.total_moves() == 4 + 1 + 9 + 3 + 1
    assert Separation((m,), left=one, removed=one).level_text() == "1"


def test_limits_raise_clear_errors() -> None:
    shapes = {
        "red": Shape([(0, 0, 0), (1, 0, 0), (2, 0, 0), (3, 0, 0)]),
        "blue": Shape([(0, 1, 0)]),
    }
    with pytest.raises(SearchLimitError, match="time limit"):
        analyze_assembly(shapes, limits=SearchLimits(seconds=0.0))
    with pytest.raises(SearchLimitError, match="state cap"):  # BurrTools' way needs 3 states
        analyze_assembly(
            SCENE | {"yellow": Shape([(5, 5, 5)])},
            limits=SearchLimits(max_states=4),
            separations="any",
        )


@settings(max_examples=40)
@given(small_scenes(), st.integers(0, 10**6), st.integers(0, 4))
def test_movement_matrix_matches_reference(shapes: dict[str, Shape], seed: int, steps: int) -> None:
    """Cutler's pairwise matrix from the numba kernel equals the reference blocking_matrix."""
    from chaingeo.core.kinematics import DIRECTIONS, blocking_matrix
    from chaingeo.solvers.motion import kinematics_kernel

    state = random_walk(shapes, seed, steps)
    table = PieceTable(state.shapes)
    members = tuple(range(len(table.names)))
    vox, starts, lo, hi = table.part_arrays(members)
    off = np.array([state.offsets[n] for n in table.names], dtype=np.int64)
    n = len(members)
    gaps = np.empty((3, n, n), dtype=np.int64)
    kinematics_kernel.pair_gaps(vox, starts, lo, hi, off, gaps)
    for d, name in enumerate(DIRECTIONS):
        ref = blocking_matrix(state, name)
        axis, sign = d // 2, 1 if d % 2 == 0 else -1
        for (a, b), free in ref.items():
            if state.part_of(a) != state.part_of(b):
                continue
            i, j = table.index(a), table.index(b)
            got = int(gaps[axis, i, j] if sign > 0 else gaps[axis, j, i])
            assert (None if got >= kinematics_kernel.INF else got) == free
