"""The numpy row lookup of symmetry maps against a plain dictionary (equal rows: the last)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.solvers.cover.constrained import _lookup_rows


def _reference(table: np.ndarray, queries: np.ndarray) -> list[int]:
    index = {tuple(row): i for i, row in enumerate(table.tolist())}
    return [index.get(tuple(row), -1) for row in queries.tolist()]


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(0, 40),
    m=st.integers(0, 60),
    width=st.integers(1, 5),
    span=st.integers(1, 4),
)
def test_lookup_matches_a_dictionary(seed: int, n: int, m: int, width: int, span: int) -> None:
    rng = np.random.default_rng(seed)
    table = rng.integers(-span, span, size=(n, width), dtype=np.int64)
    queries = rng.integers(-span, span, size=(m, width), dtype=np.int64)
    got = _lookup_rows(table, queries)
    assert got.dtype == np.int32
    assert got.tolist() == _reference(table, queries)
