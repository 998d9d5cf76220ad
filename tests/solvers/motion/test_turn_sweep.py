"""The fast turn sweep (:mod:`chaingeo.solvers.motion.turns_sweep_kernel`, the turn kernel beyond
its table, the
env's turn checks) against the Python reference :mod:`chaingeo.core.turns`, and its cost as pieces
wander."""

from __future__ import annotations

import resource
import time
import tracemalloc
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import Assembly, legal_turns, oriented
from chaingeo.core.level import load_level
from chaingeo.core.turns import AXES, TurnMove, square_hit, swept_squares
from chaingeo.envs.machines import puzzle_actions
from chaingeo.evaluation.agents.base import AgentSpec
from chaingeo.evaluation.play import EpisodeTask, run_episode
from chaingeo.solvers.motion import turns_sweep_kernel as sweep
from chaingeo.solvers.motion.turns_kernel import TurnTable
from chaingeo.solvers.motion.turnsearch import fast_legal_turns, turn_problem, turn_rows
from tests.support.jit import seconds_for
from tests.support.puzzle_strategies import small_scenes
from tests.support.scenes import turning_walk

LUBAN = "levels/puzzle/puzzle-easy-01-luban-3-piece.json"


@st.composite
def square_pairs(draw: st.DrawFn, reach: int = 60) -> tuple[tuple[int, int], tuple[int, int]]:
    """A moving and a fixed square (doubled, one parity class), the fixed one often near the
    start or the end of the sweep, where the test is hardest."""
    par = draw(st.integers(0, 1))
    sx = 2 * draw(st.integers(-reach, reach)) + par
    sy = 2 * draw(st.integers(-reach, reach)) + par
    base = draw(st.sampled_from([(sx, sy), (-sy, sx), (0, 0)]))
    dx, dy = (2 * draw(st.integers(-3, 3)) for _ in range(2))
    return (sx, sy), (base[0] + dx, base[1] + dy)


@settings(max_examples=400, deadline=None)
@given(square_pairs())
def test_int64_square_hit_matches_the_reference(
    pair: tuple[tuple[int, int], tuple[int, int]],
) -> None:
    (s, f) = pair
    assert sweep.square_hit(s[0], s[1], f[0], f[1]) == square_hit(s, f)
    # -90 is the mirror image
    assert sweep.turn_hit(s[0], s[1], f[0], f[1], 1) == square_hit((s[0], -s[1]), (f[0], -f[1]))


def _stencil(s: tuple[int, int], quarter: int) -> list[tuple[int, int]]:
    table = sweep.stencils()
    k, i, j = (0 if quarter == 1 else 1), s[0] + table.bound, s[1] + table.bound
    rows = table.cells[table.start[k, i, j] : table.end[k, i, j]].tolist()
    return sorted((int(u), int(v)) for u, v in rows)


def test_stencil_table_matches_swept_squares_near_the_axis() -> None:
    for x in range(-6, 7):
        for y in range(-6, 7):
            if (x - y) % 2 == 0:
                for q in (1, -1):
                    assert _stencil((x, y), q) == list(swept_squares((x, y), q))


@settings(max_examples=25, deadline=None)
@given(
    st.integers(-sweep.BOUND, sweep.BOUND), st.integers(0, sweep.BOUND), st.sampled_from([1, -1])
)
def test_stencil_table_matches_swept_squares(x: int, y: int, quarter: int) -> None:
    y -= (x - y) % 2
    assert _stencil((x, y), quarter) == list(swept_squares((x, y), quarter))


@settings(max_examples=10, deadline=None)
@given(st.integers(sweep.BOUND + 1, 60), st.integers(-60, 60), st.sampled_from([1, -1]))
def test_pair_test_beyond_the_table_sweeps_what_the_reference_sweeps(
    x: int, y: int, quarter: int
) -> None:
    """A far cell's squares, found by the pair test over a box holding its whole sweep, are the
    reference's stencil."""
    y -= (x - y) % 2
    reach = int(np.hypot(abs(x) + 1, abs(y) + 1)) + 3
    lo = -reach - (reach + x) % 2  # x's parity
    sense = 0 if quarter == 1 else 1
    got = [
        (fx, fy)
        for fx in range(lo, reach + 1, 2)
        for fy in range(lo, reach + 1, 2)
        if sweep.turn_hit(x, y, fx, fy, sense)
    ]
    assert got == list(swept_squares((x, y), quarter))


def _spread(shapes: dict[str, Shape], seed: int, spread: int) -> Assembly:
    """The pieces in random orientations, strung out along x (the first and the last
    ``spread`` cells apart, cells never shared), all in one part."""
    rng = np.random.default_rng(seed)
    taken: set[tuple[int, int, int]] = set()
    offsets: dict[str, tuple[int, int, int]] = {}
    rotations: dict[str, int] = {}
    for i, (name, shape) in enumerate(sorted(shapes.items())):
        x = i * spread // (len(shapes) - 1)
        while True:
            r = int(rng.integers(24))
            o = (x + int(rng.integers(2)), int(rng.integers(4)), int(rng.integers(4)))
            cells = {(x + o[0], y + o[1], z + o[2]) for x, y, z in oriented(shape, r)}
            if not cells & taken:
                break
        taken |= cells
        offsets[name], rotations[name] = o, r
    return Assembly(shapes, offsets, (frozenset(shapes),), rotations)


@settings(max_examples=25, deadline=None)
@given(small_scenes(max_pieces=3), st.integers(0, 2**16), st.integers(0, 4))
def test_fast_turns_with_every_cell_beyond_the_table_match_reference(
    shapes: dict[str, Shape], seed: int, steps: int
) -> None:
    """A table of reach 0 sends every cell off the axis to the pair test."""
    state = turning_walk(shapes, seed, steps)
    assert fast_legal_turns(state, st=sweep.Stencils(0)) == legal_turns(state)


@settings(max_examples=5, deadline=None)
@given(small_scenes(max_pieces=3), st.integers(0, 2**16))
def test_fast_turns_of_pieces_far_apart_match_reference(
    shapes: dict[str, Shape], seed: int
) -> None:
    """Pieces strung out over 14 cells along x: cells beyond the table's reach (12 cells from
    the axis) and within it, in one state."""
    state = _spread(shapes, seed, 14)
    assert fast_legal_turns(state) == legal_turns(state)


@settings(max_examples=60, deadline=None)
@given(small_scenes(max_pieces=3), st.integers(0, 2**16), st.integers(0, 4), st.data())
def test_turn_problem_matches_reference(
    shapes: dict[str, Shape], seed: int, steps: int, data: st.DataObject
) -> None:
    """Legal, swept through another piece (the same first cell named) or off the group's box."""
    kind = seed % 3  # assembled (most turns sweep through a piece), walked, spread
    state = _spread(shapes, seed, 6) if kind == 2 else turning_walk(shapes, seed, kind * steps)
    part = sorted(next(p for p in state.parts if len(p) > 1))
    group = data.draw(st.lists(st.sampled_from(part), min_size=1, max_size=len(part) - 1))
    cells = [c for n in group for c in state.cells_of(n)]
    c = [2 * data.draw(st.sampled_from(cells))[t] + data.draw(st.integers(-2, 2)) for t in range(3)]
    axis = data.draw(st.integers(0, 2))
    c[axis] = 0
    if (c[(axis + 1) % 3] - c[(axis + 2) % 3]) % 2:
        c[(axis + 1) % 3] += 1
    move = TurnMove(
        tuple(set(group)), AXES[axis], data.draw(st.sampled_from([1, -1])), (c[0], c[1], c[2])
    )
    assert turn_problem(state, move) == state.turn_problem(move)


def test_pieces_far_apart_cost_no_more_memory() -> None:
    """Three pieces of one part, one of them 400 cells away: the turns come from the same
    table, in a few MB (the stencils of the old kernel grew with the distance to a table of
    O(distance^3) cells)."""
    shapes = {
        "a": Shape([(0, 0, 0), (1, 0, 0), (1, 1, 0)]),
        "b": Shape([(0, 0, 0), (0, 1, 0)]),
        "c": Shape([(0, 0, 0), (0, 0, 1)]),
    }
    state = Assembly(
        shapes, {"a": (0, 0, 0), "b": (3, 0, 0), "c": (400, 1, 0)}, (frozenset(shapes),)
    )
    table = TurnTable(shapes, {})
    before = sweep.stencils()
    warm = turn_rows(state, None, table)  # compiled and warm
    tracemalloc.start()
    try:
        t0 = time.perf_counter()
        rows = turn_rows(state, None, table)
        took = time.perf_counter() - t0
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert sweep.stencils() is before and before.bound == sweep.BOUND
    all_pairs = turn_rows(state, None, table, st=sweep.Stencils(0))
    assert [r.tolist() for _, r in rows] == [r.tolist() for _, r in all_pairs]
    assert [r.tolist() for _, r in rows] == [r.tolist() for _, r in warm]
    assert sum(len(r) for _, r in rows) > 0
    assert peak < 8 << 20, f"{peak / 2**20:.1f} MB"
    assert took < seconds_for(5.0)


def test_random_episode_on_the_turn_level_is_bounded(monkeypatch: pytest.MonkeyPatch) -> None:
    """The episode ``chain eval --agent random`` plays on the one level with turns (80 s and
    2.1 GB before the fixed table): its pieces wander well beyond the table's reach, and it
    takes seconds and a bounded amount of memory."""
    spans: list[int] = []

    def spy(state: Assembly, *args: Any, **kwargs: Any) -> Any:
        for part in state.parts:
            cells = np.array([c for n in part for c in state.cells_of(n)])
            spans.append(int((cells.max(axis=0) - cells.min(axis=0)).max()) + 1)
        return turn_rows(state, *args, **kwargs)

    monkeypatch.setattr(puzzle_actions, "turn_rows", spy)
    task = EpisodeTask(load_level(LUBAN), 0, 0, AgentSpec("random"))
    table = sweep.stencils()
    peak_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # KB on Linux
    t0 = time.perf_counter()
    record = run_episode(task).record
    took = time.perf_counter() - t0
    grown = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - peak_before
    assert record["status"] == "done", record.get("error")
    assert took < seconds_for(20.0)
    assert grown < 400 << 10, f"peak memory grew by {grown >> 10} MB"
    assert sweep.stencils() is table and table.bound == sweep.BOUND
    # a part wider than 13 cells puts cells more than 24 doubled units from some centre
    assert max(spans) > 13, spans


def test_turn_problem_passes_a_piece_that_is_all_spinning_rod() -> None:
    """A one-cell rod on the axis line spins in place: nothing of it is left to hit (the U
    around it turns freely)."""
    u_shape = [(0, 0, 0), (0, 1, 0), (1, 1, 0), (2, 1, 0), (2, 0, 0)]
    shapes = {"a": Shape(u_shape), "r": Shape([(0, 0, 0)])}
    state = Assembly(
        shapes, {"a": (0, 0, 0), "r": (1, 0, 0)}, (frozenset(shapes),), {}, {"r": {(0, 0, 0): 2}}
    )
    for quarter in (1, -1):
        move = TurnMove(("a",), "z", quarter, (2, 0, 0))
        assert turn_problem(state, move) == state.turn_problem(move)
    assert turn_problem(state, TurnMove(("a",), "z", 1, (2, 0, 0))) is None
