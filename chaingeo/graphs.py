"""The graphs of a puzzle or packing as networkx graphs (blocking per direction, contact,
support, the state graph of a small puzzle): :mod:`chaingeo.solvers.graphs`, re-exported
under a short name for readers who want the graphs alone."""

from __future__ import annotations

from chaingeo.core.kinematics import SearchLimitError
from chaingeo.solvers.graphs import (
    FLOOR,
    MAX_STATES,
    bfs_layers,
    blocking_graph,
    blocking_graphs,
    can_slide,
    closure,
    contact_graph,
    dead_ends,
    goal_distance,
    grounded,
    group_can_slide,
    minimal_groups,
    piece_free,
    shortest_to,
    state_graph,
    support_graph,
)

__all__ = [
    "FLOOR",
    "MAX_STATES",
    "SearchLimitError",
    "bfs_layers",
    "blocking_graph",
    "blocking_graphs",
    "can_slide",
    "closure",
    "contact_graph",
    "dead_ends",
    "goal_distance",
    "grounded",
    "group_can_slide",
    "minimal_groups",
    "piece_free",
    "shortest_to",
    "state_graph",
    "support_graph",
]
