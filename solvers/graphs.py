"""The graphs of a puzzle or a packing as networkx graphs: blocking per direction, contact,
support, and the state graph of a small puzzle (its breadth-first layers and dead ends).

Why graphs: a question about a puzzle ("which piece stops red along +x?", "which group can move
first?", "what does the box rest on?") is a question about one of these relations, and a reader
can draw, query or export them with networkx's own tools. Each is built from the exact
relations of :mod:`chaingeo.core.kinematics` and :mod:`chaingeo.core.rules`; the state graph
expands states with the numba movement analysis (:mod:`chaingeo.solvers.motion`), whose moves
the tests compare with the reference kinematics.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any, Final

import networkx as nx

from chaingeo.core.geometry import NEIGHBOURS, Cell, Shape
from chaingeo.core.kinematics import (
    DIRECTIONS,
    Assembly,
    Move,
    SearchLimitError,
    legal_steps,
    state_key,
)
from chaingeo.core.turns import TurnMove
from chaingeo.solvers.motion.partsearch import fast_legal_moves
from chaingeo.solvers.motion.turnsearch import fast_legal_turns

#: The node of the support and contact graphs that stands for the floor of the box.
FLOOR: Final = "floor"
#: The default cap on states of :func:`state_graph` (a small puzzle's whole graph).
MAX_STATES: Final = 20_000

Step = Move | TurnMove


# ---------------------------------------------------------------------------------------------
# Blocking: who stops whom, per direction
# ---------------------------------------------------------------------------------------------


def blocking_graph(state: Assembly, direction: str) -> nx.DiGraph:
    """Edge ``a -> b`` when a one-unit step of ``a`` alone along ``direction`` would hit ``b``
    (pieces of one part only). A piece with no out-edge can slide alone; a group can slide
    exactly when it holds every piece reachable from its members."""
    if direction not in DIRECTIONS:
        raise ValueError(f"direction must be one of {sorted(DIRECTIONS)}, got {direction!r}")
    g = nx.DiGraph(direction=direction)
    for part in sorted(state.parts, key=sorted):
        for name in sorted(part):
            g.add_node(name, part=tuple(sorted(part)))
    for name in sorted(g.nodes):
        for other in state.blockers(name, direction):
            g.add_edge(name, other)
    return g


def blocking_graphs(state: Assembly) -> dict[str, nx.DiGraph]:
    """:func:`blocking_graph` for all six directions."""
    return {d: blocking_graph(state, d) for d in DIRECTIONS}


def can_slide(g: nx.DiGraph, name: str) -> bool:
    """Can ``name`` alone take a unit step along the graph's direction (it blocks on nothing,
    and it is not a whole part by itself)?"""
    return len(g.nodes[name]["part"]) > 1 and g.out_degree(name) == 0


def closure(g: nx.DiGraph, names: Iterable[str]) -> frozenset[str]:
    """The least group holding ``names`` that can step: they and all they reach."""
    out: set[str] = set()
    for n in names:
        out.add(n)
        out.update(nx.descendants(g, n))
    return frozenset(out)


def group_can_slide(g: nx.DiGraph, names: Sequence[str]) -> bool:
    """Can the group step one unit along the graph's direction? It must be closed under
    "is blocked by" and a proper subset of one part."""
    group = frozenset(names)
    part = frozenset(g.nodes[names[0]]["part"])
    return group <= part and group != part and closure(g, group) == group


def minimal_groups(g: nx.DiGraph) -> list[tuple[str, ...]]:
    """The smallest movable groups: single-piece closures that contain no other closure
    (sorted by size, then names)."""
    found: set[frozenset[str]] = set()
    for n in g.nodes:
        c = closure(g, [n])
        if c != frozenset(g.nodes[n]["part"]):
            found.add(c)
    least = [c for c in found if not any(o < c for o in found)]
    return sorted((tuple(sorted(c)) for c in least), key=lambda t: (len(t), t))


# ---------------------------------------------------------------------------------------------
# Packings: contact and support
# ---------------------------------------------------------------------------------------------


def _cells(pieces: Mapping[str, Shape | Iterable[Cell]]) -> dict[str, frozenset[Cell]]:
    return {
        n: s.cell_set if isinstance(s, Shape) else frozenset(tuple(c) for c in s)  # type: ignore[misc]
        for n, s in pieces.items()
    }


def contact_graph(pieces: Mapping[str, Shape | Iterable[Cell]], floor: bool = True) -> nx.Graph:
    """Edge between two pieces that share a face, ``faces`` = how many; with ``floor``, an edge
    to :data:`FLOOR` from every piece with a cell at ``z == 0`` (``faces`` on the floor)."""
    cells = _cells(pieces)
    owner = {c: n for n, cs in cells.items() for c in cs}
    g = nx.Graph()
    g.add_nodes_from(sorted(cells))
    if floor:
        g.add_node(FLOOR)
    faces: dict[tuple[str, str], int] = {}
    for n in sorted(cells):
        for x, y, z in cells[n]:
            for dx, dy, dz in NEIGHBOURS:
                o = owner.get((x + dx, y + dy, z + dz))
                if o is not None and o != n and n < o:
                    faces[(n, o)] = faces.get((n, o), 0) + 1
            if floor and z == 0:
                faces[(n, FLOOR)] = faces.get((n, FLOOR), 0) + 1
    for (a, b), k in sorted(faces.items()):
        g.add_edge(a, b, faces=k)
    return g


def support_graph(pieces: Mapping[str, Shape | Iterable[Cell]]) -> nx.DiGraph:
    """Edge ``a -> b`` when ``a`` rests on ``b``: a cell of ``a`` lies directly on a cell of
    ``b`` (``cells`` = how many), or ``b`` is :data:`FLOOR` and ``a`` has a cell at ``z == 0``.
    A piece is held up from below exactly when it reaches the floor in this graph."""
    cells = _cells(pieces)
    owner = {c: n for n, cs in cells.items() for c in cs}
    g = nx.DiGraph()
    g.add_nodes_from(sorted(cells))
    g.add_node(FLOOR)
    count: dict[tuple[str, str], int] = {}
    for n in sorted(cells):
        for x, y, z in cells[n]:
            below = FLOOR if z == 0 else owner.get((x, y, z - 1))
            if below is not None and below != n:
                count[(n, below)] = count.get((n, below), 0) + 1
    for (a, b), k in sorted(count.items()):
        g.add_edge(a, b, cells=k)
    return g


def grounded(g: nx.DiGraph) -> frozenset[str]:
    """The pieces of a support graph held up from below: those with a path to the floor."""
    return frozenset(nx.ancestors(g, FLOOR))


# ---------------------------------------------------------------------------------------------
# The state graph of a small puzzle
# ---------------------------------------------------------------------------------------------


def legal_steps_fast(state: Assembly, max_group: int | None, turns: bool) -> list[Step]:
    """Every legal move (and turn, with ``turns``) of ``state`` from the numba analysis; a
    state where turns left pieces in other orientations goes to the reference kinematics
    (the movement kernel's piece table holds the assembled orientations only)."""
    if state.rotations:
        return legal_steps(state, max_group, turns)
    steps: list[Step] = list(fast_legal_moves(state, max_group))
    if turns:
        steps.extend(fast_legal_turns(state, max_group))
    return steps


def state_graph(
    start: Assembly,
    max_group: int | None = None,
    turns: bool = False,
    max_states: int = MAX_STATES,
    steps: Callable[[Assembly, int | None, bool], list[Step]] = legal_steps_fast,
) -> nx.DiGraph:
    """Every state reachable from ``start``, breadth first: nodes are :func:`state_key`\\ s with
    ``state`` (the :class:`Assembly`), ``depth`` (fewest moves from ``start``) and ``done``
    (every piece apart); edge ``u -> v`` holds one ``move`` (as JSON) that takes ``u`` to
    ``v`` (the first in sorted order). Raises :class:`SearchLimitError` past ``max_states``."""
    g = nx.DiGraph()
    key0 = state_key(start)
    g.add_node(key0, state=start, depth=0, done=start.is_separated())
    queue = deque([key0])
    while queue:
        u = queue.popleft()
        here: Assembly = g.nodes[u]["state"]
        for move in sorted(steps(here, max_group, turns), key=_step_key):
            child = here.apply(move)
            v = state_key(child)
            if v not in g:
                if g.number_of_nodes() >= max_states:
                    raise SearchLimitError(f"the state graph passed {max_states} states")
                g.add_node(v, state=child, depth=g.nodes[u]["depth"] + 1, done=child.is_separated())
                queue.append(v)
            if not g.has_edge(u, v):
                g.add_edge(u, v, move=move.to_json())
    return g


def _step_key(m: Step) -> tuple[Any, ...]:
    if isinstance(m, TurnMove):
        return (m.pieces, "rotate", m.axis, m.quarter, m.centre2)
    return (m.pieces, m.direction, m.distance is None, m.distance or 0)


def shortest_to(
    start: Assembly,
    goal: Callable[[Assembly], bool],
    max_group: int | None = None,
    turns: bool = False,
    max_states: int = MAX_STATES,
    steps: Callable[[Assembly, int | None, bool], list[Step]] = legal_steps_fast,
) -> tuple[int, list[Step], int] | None:
    """Fewest moves from ``start`` to a state where ``goal`` holds, breadth first by whole
    layers (exact however far the rest of the graph goes): ``(moves, a plan, states seen)``,
    or None when no state reachable satisfies ``goal``. Raises :class:`SearchLimitError`
    past ``max_states`` states."""
    if goal(start):
        return 0, [], 1
    parent: dict[Any, tuple[Any, Step | None]] = {state_key(start): (None, None)}
    layer = [start]
    depth = 0
    while layer:
        depth += 1
        nxt: list[Assembly] = []
        for here in layer:
            hk = state_key(here)
            for move in sorted(steps(here, max_group, turns), key=_step_key):
                child = here.apply(move)
                ck = state_key(child)
                if ck in parent:
                    continue
                parent[ck] = (hk, move)
                if goal(child):
                    return depth, _plan(parent, ck), len(parent)
                if len(parent) >= max_states:
                    raise SearchLimitError(f"the breadth-first search passed {max_states} states")
                nxt.append(child)
        layer = nxt
    return None


def _plan(parent: Mapping[Any, tuple[Any, Step | None]], key: Any) -> list[Step]:
    out: list[Step] = []
    while True:
        prev, move = parent[key]
        if move is None:
            return out[::-1]
        out.append(move)
        key = prev


def bfs_layers(g: nx.DiGraph, source: Any) -> list[list[Any]]:
    """The states by their fewest moves from ``source`` (networkx's layers, each sorted)."""
    return [sorted(layer) for layer in nx.bfs_layers(g, [source])]


def goal_distance(g: nx.DiGraph, goal: Callable[[Assembly], bool]) -> dict[Any, int]:
    """Fewest moves from each state to a state where ``goal`` holds (states that cannot reach
    one are absent): breadth first backwards from every goal state."""
    targets = [n for n, s in g.nodes(data="state") if goal(s)]
    dist = dict.fromkeys(targets, 0)
    queue = deque(targets)
    while queue:
        v = queue.popleft()
        for u in g.predecessors(v):
            if u not in dist:
                dist[u] = dist[v] + 1
                queue.append(u)
    return dist


def dead_ends(g: nx.DiGraph) -> list[Any]:
    """States from which every piece can no longer be taken apart (sorted)."""
    alive = goal_distance(g, Assembly.is_separated)
    return sorted(n for n in g.nodes if n not in alive)


def piece_free(name: str) -> Callable[[Assembly], bool]:
    """The goal "``name`` is out": its part is the piece alone."""

    def free(state: Assembly) -> bool:
        return len(state.part_of(name)) == 1

    return free
