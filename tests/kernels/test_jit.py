"""The kernel entry points of :mod:`chaingeo.kernels.jit`."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from chaingeo.kernels.jit import Pinned, njit

I64 = npt.NDArray[np.int64]


class _Pair(NamedTuple):
    a: I64
    b: I64


@njit
def _dot(pair: _Pair, scale: int) -> int:
    return int((pair.a * pair.b).sum()) * scale


def test_pinned_resolves_once_and_serves_new_arrays_of_the_same_types() -> None:
    """A pinned kernel gives the kernel's results for every call, new arrays included, and
    keeps the entry point its first call resolved (no typing per call)."""
    pinned = Pinned(_dot)
    first = _Pair(np.arange(3, dtype=np.int64), np.ones(3, dtype=np.int64))
    assert pinned(first, 2) == _dot(first, 2) == 6
    kept = pinned._call
    other = _Pair(np.arange(5, dtype=np.int64), np.arange(5, dtype=np.int64))
    assert pinned(other, 1) == _dot(other, 1) == 30
    assert pinned._call is kept is not None
