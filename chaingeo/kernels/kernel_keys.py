"""Type keys of kernel arguments, computed from Python values without numba and from numba types.

Ahead-of-time kernels (:mod:`chaingeo.kernels.aot`) are compiled once per argument signature and
chosen at call time by the arguments' types. Numba's own ``typeof`` would need numba imported,
which is the start-up cost the compiled kernels exist to avoid, so :func:`value_key` reproduces
numba's typing rules for the values kernels take (arrays, integers, floats, booleans, ``None``
and tuples / NamedTuples of those) as a short string, and :func:`type_key` gives the same string
for the numba type the build recorded. ``value_key(v) == type_key(numba.typeof(v))`` is tested
on generated values; a value of any other kind has no key, and the call goes to numba.

Arrays are keyed by dtype, rank, layout (``C`` when C-contiguous, else ``F`` when
Fortran-contiguous, else ``A``, numba's rule) and writability: a kernel compiled for one layout
reads another wrongly, so none of these may be left out.
"""

from __future__ import annotations

from typing import Any, Final

import numpy as np

#: Python ints numba types as int64 (those of fewer than 64 bits; larger ones are uint64 or
#: refused).
_INT64: Final = (-(2**63) + 1, 2**63 - 1)


def value_key(value: object) -> str | None:
    """The key of ``value``'s numba type, or ``None`` for a kind kernels are not compiled for."""
    kind = type(value)
    if kind is np.ndarray:
        return _array_key(value)  # type: ignore[arg-type]
    known = _SCALARS.get(kind)
    if known is not None:
        return known
    if kind is int:
        return "<i8" if _INT64[0] <= value <= _INT64[1] else None  # type: ignore[operator]
    if isinstance(value, tuple):
        return _tuple_key(value)
    if isinstance(value, np.ndarray):  # a subclass: numba types it as an array too
        return _array_key(value)
    if isinstance(value, bool | np.bool_):
        return "b"
    if isinstance(value, np.integer | np.floating):
        return _dtype_key(value.dtype)
    if isinstance(value, int):
        return value_key(int(value))
    if isinstance(value, float):
        return "<f8"
    return None


#: Keys of the exact scalar types seen most (a dict look-up instead of isinstance chains: a
#: kernel call keys every argument, ~1 us each).
_SCALARS: Final[dict[type, str]] = {
    bool: "b",
    np.bool_: "b",
    float: "<f8",
    type(None): "n",
    **{t: np.dtype(t).str for t in (np.int8, np.int16, np.int32, np.int64)},
    **{t: np.dtype(t).str for t in (np.uint8, np.uint16, np.uint32, np.uint64)},
    **{t: np.dtype(t).str for t in (np.float32, np.float64)},
}


def args_key(args: tuple[Any, ...]) -> str | None:
    """The key of a whole argument list (``None`` if any argument has none)."""
    keys = [value_key(a) for a in args]
    if None in keys:
        return None
    return ";".join(keys)  # type: ignore[arg-type]


#: Array dtypes' keys (a dtype's ``str`` is built anew on each access).
_DTYPES: dict[np.dtype[Any], str | None] = {}


def _dtype_key(dtype: np.dtype[Any]) -> str | None:
    try:
        return _DTYPES[dtype]
    except KeyError:
        ok = dtype.kind in "biuf" and dtype.isnative and dtype.fields is None
        key = _DTYPES[dtype] = dtype.str if ok else None
        return key


def _array_key(a: np.ndarray[Any, Any]) -> str | None:
    dtype = _dtype_key(a.dtype)
    if dtype is None:
        return None
    flags = a.flags
    layout = "C" if flags.c_contiguous else "F" if flags.f_contiguous else "A"
    return f"{'w' if flags.writeable else 'r'}{layout}{a.ndim}{dtype}"


def _tuple_key(t: tuple[Any, ...]) -> str | None:
    keys = [value_key(v) for v in t]
    if None in keys:
        return None
    cls = type(t)
    name = _NAMES.get(cls)
    if name is None:
        name = _NAMES[cls] = f"{cls.__module__}.{cls.__qualname__}"
    return f"{name}({','.join(keys)})"  # type: ignore[arg-type]


#: Tuple classes' names in keys (a plain tuple has none).
_NAMES: dict[type, str] = {tuple: ""}


def type_key(nbtype: Any) -> str | None:
    """The key of numba type ``nbtype`` as :func:`value_key` gives it for a value of that type
    (imports numba: used where kernels are built, not where they are called)."""
    from numba.core import types
    from numba.np import numpy_support

    if isinstance(nbtype, types.Array):
        key = np.dtype(numpy_support.as_dtype(nbtype.dtype)).str
        if nbtype.layout not in "CFA":
            return None
        return f"{'w' if nbtype.mutable else 'r'}{nbtype.layout}{nbtype.ndim}{key}"
    if isinstance(nbtype, types.Literal):  # a kernel-to-kernel call with a constant: never
        return None  # what numba types a Python argument as
    if isinstance(nbtype, types.Boolean):
        return "b"
    if isinstance(nbtype, types.Integer | types.Float):
        return np.dtype(str(nbtype)).str  # "int64", "float32": numpy's names too
    if isinstance(nbtype, types.NoneType):
        return "n"
    if isinstance(nbtype, types.BaseTuple):
        return _tuple_type_key(nbtype)
    return None


def _tuple_type_key(nbtype: Any) -> str | None:
    from numba.core import types

    keys = [type_key(t) for t in nbtype.types]
    if any(k is None for k in keys):
        return None
    if isinstance(nbtype, types.BaseNamedTuple):
        cls = nbtype.instance_class  # type: ignore[attr-defined]
        name = f"{cls.__module__}.{cls.__qualname__}"
    else:
        name = ""
    return f"{name}({','.join(keys)})"  # type: ignore[arg-type]
