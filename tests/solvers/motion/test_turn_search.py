"""The numba turn kernels and the turn-aware search against the pure-Python reference."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import (
    Assembly,
    SearchLimitError,
    legal_steps,
    legal_turns,
    reference_first_level,
    reference_optimal_disassembly,
    replay_disassembly,
    state_key,
)
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.disassemble import analyze_assembly, fast_legal_moves
from chaingeo.solvers.motion.turns_kernel import TurnTable
from chaingeo.solvers.motion.turnsearch import TurnPartSearch, fast_legal_turns
from tests.support.puzzle_strategies import small_scenes
from tests.support.scenes import luban3, turning_walk


@settings(max_examples=40)
@given(small_scenes(max_pieces=3), st.integers(0, 2**16), st.integers(0, 4))
def test_fast_turns_match_reference(shapes: dict[str, Shape], seed: int, steps: int) -> None:
    state = turning_walk(shapes, seed, steps)
    assert fast_legal_turns(state) == legal_turns(state)
    assert fast_legal_turns(state, max_group=1) == legal_turns(state, max_group=1)
    # translations of turned pieces too
    from chaingeo.core.kinematics import legal_moves

    assert fast_legal_moves(_oriented(state)) == legal_moves(state)


def _oriented(state: Assembly) -> Assembly:
    """The same cells with the turned shapes baked in (what the translation kernel reads)."""
    from chaingeo.core.kinematics import oriented

    shapes = {n: oriented(s, state.rotation_of(n)) for n, s in state.shapes.items()}
    return Assembly(shapes, state.offsets, state.parts)


@settings(max_examples=30)
@given(small_scenes(max_pieces=3), st.integers(0, 2**16), st.integers(0, 4))
def test_successor_states_match_reference(shapes: dict[str, Shape], seed: int, steps: int) -> None:
    """One layer of the turn search from a (turned) state reaches exactly the states the
    reference's moves and turns reach, seen relative to the first piece's pose."""
    state = turning_walk(shapes, seed, steps)
    part = max(state.parts, key=len)
    if len(part) < 2:
        return
    names = sorted(part)
    sub = Assembly(
        {n: state.shapes[n] for n in names},
        {n: state.offsets[n] for n in names},
        (frozenset(names),),
        {n: state.rotation_of(n) for n in names},
    )
    table = TurnTable(sub.shapes, {})
    poses = np.array([[*sub.offsets[n], sub.rotation_of(n)] for n in names], dtype=np.int64)
    search = TurnPartSearch(
        table, range(len(names)), poses, max_group=None, limits=SearchLimits(),
        deadline=Deadline(None),
    )  # fmt: skip
    search.expand_layer()
    got = set()
    for node in range(1, search.n_states):
        p = search.poses_of(node)
        child = Assembly(
            sub.shapes,
            {n: (int(p[i, 0]), int(p[i, 1]), int(p[i, 2])) for i, n in enumerate(names)},
            sub.parts,
            {n: int(p[i, 3]) for i, n in enumerate(names)},
        )
        got.add(state_key(child))
    want = {state_key(sub.apply(m)) for m in legal_steps(sub, turns=True) if not sub.removes(m)} - {
        state_key(sub)
    }
    assert got == want
    # and every path the search reports replays with the reference
    for node in range(1, search.n_states):
        after = sub
        for m in search.path_to(node):
            after = after.apply(m)
        p = search.poses_of(node)
        assert all(
            after.offsets[n] == tuple(int(v) for v in p[i, :3])
            and after.rotation_of(n) == int(p[i, 3])
            for i, n in enumerate(names)
        )


@settings(max_examples=25)
@given(small_scenes(max_pieces=3))
def test_optimal_with_turns_matches_reference_bfs(shapes: dict[str, Shape]) -> None:
    ref = reference_optimal_disassembly(shapes, turns=True, max_states=20_000)
    a = analyze_assembly(shapes, turns=True, limits=SearchLimits(seconds=None))
    if ref is None:
        assert not a.disassemblable
        return
    assert a.optimal_steps == len(ref)
    assert a.first_level == reference_first_level(shapes, turns=True, max_states=20_000)
    assert replay_disassembly(shapes, a.plan).is_separated()
    plain = analyze_assembly(shapes, limits=SearchLimits(seconds=None))
    if plain.optimal_steps is not None:  # turns only add ways
        assert a.optimal_steps is not None and a.optimal_steps <= plain.optimal_steps


def test_luban_lock_needs_its_rod_to_spin() -> None:
    shapes, rods = luban3(6)
    assert not analyze_assembly(shapes).disassemblable  # translations alone: locked
    assert not analyze_assembly(shapes, turns=True).disassemblable  # a square rod cannot spin
    a = analyze_assembly(shapes, turns=True, rods=rods)
    assert a.disassemblable and a.level == "2" and a.optimal_steps == 3
    assert replay_disassembly(shapes, a.plan, rods).is_separated()
    ref = reference_optimal_disassembly(shapes, turns=True, rods=rods)
    assert ref is not None and len(ref) == a.optimal_steps


@pytest.mark.slow
@settings(max_examples=30)
@given(small_scenes(max_pieces=4))
def test_optimal_with_turns_matches_reference_bfs_four_pieces(shapes: dict[str, Shape]) -> None:
    """Loose four-piece scenes: the reference searches whole states and may pass its cap
    (turns multiply the states); those examples are skipped."""
    try:
        ref = reference_optimal_disassembly(shapes, turns=True, max_states=20_000)
    except SearchLimitError:
        assume(False)
        return
    a = analyze_assembly(shapes, turns=True, limits=SearchLimits(seconds=None))
    assert a.optimal_steps == (None if ref is None else len(ref))
    if ref is not None:
        assert replay_disassembly(shapes, a.plan).is_separated()


@pytest.mark.slow
def test_full_size_luban_lock_matches_reference() -> None:
    shapes, rods = luban3(10)
    a = analyze_assembly(shapes, turns=True, rods=rods)
    ref = reference_optimal_disassembly(shapes, turns=True, rods=rods)
    assert ref is not None and a.optimal_steps == len(ref) == 3 and a.level == "2"
