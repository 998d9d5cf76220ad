"""A level's optimal plan in the shapes a model would send it."""

from __future__ import annotations

from chaingeo.core.level import Level, StackingSolution


def place_calls(level: Level) -> list[tuple[str, dict[str, object]]]:
    """The optimal plan of a stacking level as ``place`` tool calls (cells 1-based)."""
    sol = level.solution
    assert isinstance(sol, StackingSolution)
    cells = {n: [[c + 1 for c in cell] for cell in p.cells] for n, p in sol.placements.items()}
    return [("place", {"piece": n, "cells": cells[n]}) for n in sol.order]
