"""The verdict for every piece order (chaingeo.solvers.motion.btproof) against BurrTools'
first-separation verdict under every relabelling of congruent pieces and seeded other piece
orders, on seeded random boxes cut into winding pieces, doubled by a half-turn (congruent
pairs); and a mixture of candidate outcomes comes out order-dependent."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from chaingeo.core.geometry import Shape
from chaingeo.solvers.deadline import Deadline
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.btproof import OrderFree, verdict_for_all_orders
from chaingeo.solvers.motion.disassemble import analyze_assembly
from tests.support.burrtxt import _cut

SEED = 11
#: The default run's assemblies (about a second, two of them no solution); the slow run: more.
CASES = range(24)
MORE = range(24, 150)
#: Piece orders besides the relabellings, each a seeded random order of every piece.
ORDERS = 12


def _assembly(index: int) -> tuple[dict[str, Shape], list[tuple[int, int]]]:
    """A box cut into 3 or 4 winding pieces, doubled by a half-turn about z on odd indices;
    and the congruent pairs (piece indices)."""
    rng = np.random.default_rng(np.random.SeedSequence([SEED, index]))
    a, b, c = ((3, 3, 3), (3, 3, 4), (2, 3, 3))[index % 3]
    box = [(x, y, z) for x in range(a) for y in range(b) for z in range(c)]
    pieces = None
    while pieces is None:
        pieces = _cut(box, 3 + index // 3 % 2, rng)
    k = len(pieces)
    pairs = []
    if index % 2:
        pieces += [[(2 * a - 1 - x, b - 1 - y, z) for x, y, z in p] for p in pieces]
        pairs = [(j, j + k) for j in range(k)]
    return {f"p{j}": Shape(p) for j, p in enumerate(pieces)}, pairs


def _orders(n: int, pairs: list[tuple[int, int]], rng: np.random.Generator) -> list[list[int]]:
    """Every relabelling of the congruent pairs (which of a pair comes first), then seeded
    random orders of all pieces."""
    out = []
    for swaps in itertools.product((False, True), repeat=len(pairs)):
        order = list(range(n))
        for (i, j), swap in zip(pairs, swaps, strict=True):
            if swap:
                order[i], order[j] = j, i
        out.append(order)
    out += [rng.permutation(n).tolist() for _ in range(ORDERS)]
    return out


def _verdicts(index: int) -> tuple[bool | None, set[bool]]:
    shapes, pairs = _assembly(index)
    names = list(shapes)
    rng = np.random.default_rng(np.random.SeedSequence([SEED, index, 1]))
    seen = set()
    for order in _orders(len(names), pairs, rng):
        got = analyze_assembly(
            shapes, optimal=False, separations="first", order=[names[i] for i in order],
            fallback=False,
        )  # fmt: skip
        seen.add(got.disassemblable)
    return verdict_for_all_orders(shapes), seen


def _check(indices: range) -> dict[bool | None, int]:
    tally: dict[bool | None, int] = {}
    for index in indices:
        proof, seen = _verdicts(index)
        if proof is not None:
            assert seen == {proof}, index
        tally[proof] = tally.get(proof, 0) + 1
    return tally


def test_the_proof_is_every_orders_verdict() -> None:
    """Decisive on every case (no cap is met), solutions and non-solutions among them."""
    tally = _check(CASES)
    assert None not in tally and tally.get(True, 0) >= 2 and tally.get(False, 0) >= 2, tally


@pytest.mark.slow
def test_the_proof_is_every_orders_verdict_on_more() -> None:
    tally = _check(MORE)
    assert None not in tally and tally.get(False, 0) >= 5, tally


def _row() -> tuple[OrderFree, tuple[bytes, ...]]:
    """Three cubes in a row: any of them can leave first, leaving two cubes side by side or
    two cubes one apart; the key of the latter part."""
    shapes = {f"c{x}": Shape([(x, 0, 0)]) for x in range(3)}
    solver = OrderFree(shapes, SearchLimits(), Deadline(None))
    apart = solver.key((0, 2), np.array([[0, 0, 0], [0, 0, 0]], dtype=np.int64))
    return solver, apart


def _whole(solver: OrderFree) -> bool | None:
    return solver.part((0, 1, 2), np.zeros((3, 3), dtype=np.int64))


def test_candidates_that_disagree_make_the_verdict_order_dependent() -> None:
    """The first separation matters when one candidate's part comes apart and another's does
    not: here made so by declaring the cubes one apart stuck."""
    solver, apart = _row()
    assert _whole(solver) is True
    solver, apart = _row()
    solver.memo[apart] = False
    assert _whole(solver) is None
    solver, apart = _row()
    solver.memo[apart] = None
    assert _whole(solver) is None


def test_stuck_and_single() -> None:
    """Two linked rings are stuck for every order; one piece is no disassembly."""
    square = [(0, 0), (1, 0), (2, 0), (2, 1), (2, 2), (1, 2), (0, 2), (0, 1)]
    flat = Shape([(x, y, 0) for x, y in square])
    upright = Shape([(x + 1, 1, z - 1) for x, z in square])
    assert verdict_for_all_orders({"a": flat, "b": upright}) is False
    assert verdict_for_all_orders({"a": flat}) is False
