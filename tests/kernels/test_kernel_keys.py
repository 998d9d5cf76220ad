"""Argument keys without numba agree with numba's own typing: a precompiled kernel is chosen by
:func:`value_key`, compiled for :func:`type_key` of what numba typed, so the two must name the
same type for every value a kernel takes, and refuse what they cannot name."""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from chaingeo.kernels.kernel_keys import args_key, type_key, value_key

numba = pytest.importorskip("numba")

DTYPES = [np.bool_, np.int8, np.int16, np.int32, np.int64, np.uint8, np.uint16, np.uint32]
DTYPES += [np.uint64, np.float32, np.float64]


class Pair(NamedTuple):
    a: Any
    b: Any


class Same(NamedTuple):
    a: Any
    b: Any


@st.composite
def arrays(draw: st.DrawFn) -> np.ndarray[Any, Any]:
    """Arrays of every dtype kernels take, ranks 0-3, C / F / strided layouts, read-only too."""
    dtype = draw(st.sampled_from(DTYPES))
    shape = draw(hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=4))
    a = draw(hnp.arrays(dtype, shape))
    view = draw(st.sampled_from(["as is", "fortran", "transpose", "step", "reverse"]))
    if view == "fortran":
        a = np.asfortranarray(draw(hnp.arrays(dtype, (2, draw(st.integers(2, 4))))))
    elif view == "transpose":
        a = a.T
    elif view == "step" and a.ndim:
        a = a[::2]
    elif view == "reverse" and a.ndim:
        a = a[::-1]
    if draw(st.booleans()):
        a.flags.writeable = False
    return a


scalars = st.one_of(
    st.booleans(),
    st.integers(min_value=-(2**63) + 1, max_value=2**63 - 1),
    st.floats(allow_nan=True),
    st.sampled_from(DTYPES).flatmap(lambda t: hnp.from_dtype(np.dtype(t)).map(t)),
    st.none(),
)
leaves = st.one_of(arrays(), scalars)


def _tuples(children: st.SearchStrategy[Any]) -> st.SearchStrategy[Any]:
    pairs = st.tuples(children, children)
    return st.one_of(
        pairs,
        pairs.map(lambda p: Pair(*p)),
        children.map(lambda x: Same(x, x)),
        st.tuples(children),
    )


values = st.recursive(leaves, _tuples, max_leaves=6)


@given(arrays())
def test_array_keys_name_numba_typeof(a: np.ndarray[Any, Any]) -> None:
    assert value_key(a) == type_key(numba.typeof(a))


@given(values)
def test_value_key_names_numba_typeof(value: Any) -> None:
    key = value_key(value)
    assert key is not None
    assert key == type_key(numba.typeof(value))


@given(st.lists(values, max_size=4))
def test_args_key_joins_the_keys(args: list[Any]) -> None:
    assert args_key(tuple(args)) == ";".join(value_key(a) or "?" for a in args)


def test_what_kernels_do_not_take_has_no_key() -> None:
    for value in ("text", [1, 2], {"a": 1}, 2**64, np.zeros(2, complex), np.zeros(2, "U1")):
        assert value_key(value) is None, value
    assert value_key((1, "x")) is None
    assert args_key((np.zeros(2), "x")) is None


def test_literal_types_have_no_key() -> None:
    """A kernel calling another with a constant compiles it for the literal; Python never
    passes one, so such a signature is not precompiled."""
    assert type_key(numba.types.literal(0)) is None
    assert type_key(numba.types.Tuple((numba.types.literal(1), numba.types.int64))) is None
    assert type_key(numba.types.int32) == "<i4" and type_key(numba.types.uint64) == "<u8"


def test_layouts_and_writability_are_told_apart() -> None:
    a = np.zeros((3, 4), np.int64)
    keys = {value_key(a), value_key(a.T), value_key(a[:, ::2])}
    ro = a.copy()
    ro.flags.writeable = False
    keys.add(value_key(ro))
    assert len(keys) == 4
