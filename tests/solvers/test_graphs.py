"""The networkx graphs against the reference kinematics and the geometry they summarise."""

from __future__ import annotations

import itertools

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo import graphs as G
from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import (
    DIRECTIONS,
    Assembly,
    legal_steps,
    movable_groups,
    reference_first_level,
    state_key,
)
from chaingeo.core.level import StackingSolution
from chaingeo.generator.questions.states import puzzle_views
from tests.support.shipped import shipped

SMALL = [
    lv for lv in shipped("puzzle") if len(lv.pieces) <= 6 and not lv.rules.to_json().get("turns")
]
STACKS = shipped("stacking")
needs_suite = pytest.mark.skipif(
    not SMALL or not STACKS, reason="the shipped suite is not installed"
)


def _state(level_index: int, step: int) -> Assembly:
    views = list(puzzle_views(SMALL[level_index % len(SMALL)]))
    return views[step % len(views)].state


@needs_suite
@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10**6), st.integers(0, 40), st.sampled_from(sorted(DIRECTIONS)))
def test_blocking_graph_groups_are_the_reference_movable_groups(i: int, j: int, d: str) -> None:
    state = _state(i, j)
    g = G.blocking_graph(state, d)
    for n in g.nodes:
        assert sorted(g.successors(n)) == state.blockers(n, d)
    movable = set(movable_groups(state, d))
    for part in state.parts:
        names = sorted(part)
        for k in range(1, min(len(names), 4)):
            for grp in itertools.combinations(names, k):
                assert G.group_can_slide(g, grp) == (grp in movable)
                assert G.group_can_slide(g, grp) == (state.free_distance(grp, d) != 0)
    for grp in G.minimal_groups(g):
        assert grp in movable


@needs_suite
@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10**6), st.integers(0, 20))
def test_contact_and_support_graphs_match_the_geometry(i: int, k: int) -> None:
    level = STACKS[i % len(STACKS)]
    assert isinstance(level.solution, StackingSolution)
    order = level.solution.order[: 1 + k % len(level.solution.order)]
    placed = {n: level.solution.placements[n] for n in order}
    contact = G.contact_graph(placed)
    support = G.support_graph(placed)
    for a, b in itertools.combinations(sorted(placed), 2):
        faces = placed[a].contact(placed[b])
        assert contact.has_edge(a, b) == (faces > 0)
        if faces:
            assert contact.edges[a, b]["faces"] == faces
        above = {(x, y, z + 1) for x, y, z in placed[b].cells}
        assert support.has_edge(a, b) == bool(above & placed[a].cell_set)
    for n, s in placed.items():
        assert contact.has_edge(n, G.FLOOR) == any(z == 0 for _, _, z in s.cells)
    # a solution placed in its legal order: the first piece is on the floor, so it is grounded
    assert order[0] in G.grounded(support) or not any(z == 0 for *_, z in placed[order[0]].cells)
    assert G.grounded(support) <= set(placed)


def _bar(n: int, at: tuple[int, int, int]) -> Shape:
    return Shape([(at[0] + i, at[1], at[2]) for i in range(n)])


def test_state_graph_of_two_bars_and_its_layers() -> None:
    """Two bars side by side: every state, its depth, and that nothing is a dead end."""
    shapes = {"a": _bar(2, (0, 0, 0)), "b": _bar(2, (0, 1, 0))}
    start = Assembly.assembled(shapes)
    g = G.state_graph(start)
    key = state_key(start)
    layers = G.bfs_layers(g, key)
    assert layers[0] == [key]
    assert all(g.nodes[n]["depth"] == d for d, layer in enumerate(layers) for n in layer)
    assert G.dead_ends(g) == []
    dist = G.goal_distance(g, Assembly.is_separated)
    assert dist[key] == 1  # one move takes a bar away
    found = G.shortest_to(start, Assembly.is_separated)
    assert found is not None and found[0] == 1
    for u, v, move in g.edges(data="move"):
        assert g.nodes[v]["depth"] <= g.nodes[u]["depth"] + 1
        assert any(m.to_json() == move for m in legal_steps(g.nodes[u]["state"]))


def test_state_graph_refuses_past_its_cap() -> None:
    shapes = {"a": _bar(3, (0, 0, 0)), "b": _bar(3, (0, 1, 0)), "c": _bar(3, (0, 2, 0))}
    with pytest.raises(G.SearchLimitError):
        G.state_graph(Assembly.assembled(shapes), max_states=5)


@needs_suite
@pytest.mark.parametrize("level", [lv for lv in SMALL if len(lv.pieces) == 3], ids=lambda lv: lv.id)
def test_shortest_to_first_removal_is_the_reference_first_level(level: object) -> None:
    from chaingeo.core.level import Level

    assert isinstance(level, Level)
    start = Assembly.assembled(level.shapes, level.rods)
    found = G.shortest_to(start, lambda s: len(s.parts) > 1, max_states=20_000)
    assert found is not None
    assert found[0] == reference_first_level(level.shapes, level.rules.max_group)  # type: ignore[union-attr]
    assert found[0] == len(found[1])
