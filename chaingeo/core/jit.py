"""The one place kernels are compiled: numba's ``njit``, or the plain Python function.

Every kernel of the toolkit is written once, for numba, on flat numpy arrays, and decorated with
:func:`njit` from here. By default that is numba's ``njit``. In *interpreted* mode the decorator
returns the function itself and numba is never imported: starting numba and loading its cached
kernels costs ~0.3 s of a process, many times the work of a small puzzle, so ``chain analyze``
runs a single small file interpreted and moves to numba when the work turns out larger (it starts
itself again with the mode set, see :mod:`chaingeo.cli.commands.analyze`).

The mode is read from ``CHAINGEO_JIT`` (``numba``, the default, or ``python``) when a kernel
module is first imported, so it is fixed for a process before any kernel is defined; changing it
later raises. Interpreted kernels compute the same results: fixed-width numpy integers wrap as
numba's do (numpy's overflow warnings are silenced in that mode).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any, Final, Generic, Literal, ParamSpec, TypeVar, overload

import numpy as np

Mode = Literal["numba", "python"]
ENV: Final = "CHAINGEO_JIT"
MODES: Final[tuple[Mode, ...]] = ("numba", "python")

F = TypeVar("F", bound=Callable[..., Any])
P = ParamSpec("P")
R = TypeVar("R")

_mode: Mode | None = None


def mode() -> Mode:
    """The process' mode, fixed at the first call (``CHAINGEO_JIT``; default numba)."""
    if _mode is None:
        raw = os.environ.get(ENV, "numba").strip().lower() or "numba"
        if raw not in MODES:
            raise ValueError(f"{ENV}: expected one of {', '.join(MODES)}, got {raw!r}")
        _fix("python" if raw == "python" else "numba")
    assert _mode is not None
    return _mode


def set_mode(wanted: Mode) -> None:
    """Fix the mode before any kernel is defined; ``RuntimeError`` once another is in force.
    (The environment is left alone: a child process chooses for itself.)"""
    if wanted not in MODES:
        raise ValueError(f"mode: expected one of {', '.join(MODES)}, got {wanted!r}")
    if _mode is not None and _mode != wanted:
        raise RuntimeError(f"kernels are already {_mode}; the mode is fixed per process")
    _fix(wanted)


def _fix(wanted: Mode) -> None:
    global _mode
    _mode = wanted
    if wanted == "python":
        np.seterr(over="ignore")  # numpy scalars warn where numba's integers wrap silently


@overload
def njit(fn: F, /) -> F: ...
@overload
def njit(**options: Any) -> Callable[[F], F]: ...
def njit(*args: Any, **options: Any) -> Any:
    """``numba.njit`` with the same arguments, or (interpreted) the function unchanged."""
    if mode() == "python":
        if args and callable(args[0]):
            return args[0]
        return _identity
    import numba  # only here: interpreted processes never import it

    return numba.njit(*args, **options)


def _identity(fn: F) -> F:
    return fn


_entries: dict[tuple[object, tuple[bytes, ...]], Any] = {}


def entry(kernel: F, *args: Any) -> F:
    """``kernel``'s compiled specialisation for the types of ``args`` (compiled or loaded now if
    new), to be called many times with arguments of exactly those types; interpreted: ``kernel``.

    Numba's dispatcher types every argument of every call, and a NamedTuple bundle costs about
    1 us there (an array 0.05 us): a Python loop that calls a bundle-taking kernel hundreds of
    times per search (A*'s loop serving pattern-database misses, one sub-puzzle enumeration per
    miss) lost 5-15% of a small search to it. The entry point skips that typing, not the
    unboxing, and does not check types: an argument of another type (another dtype, rank or
    layout of an array) would be misread, so call it only with the same kinds of arrays (buffers
    replaced by grown copies). Resolving costs numba's C fingerprints of ``args`` and a dict
    look-up; the first time per types, numba's Python typing (about 10 us an array)."""
    dispatcher: Any = kernel
    if not hasattr(dispatcher, "overloads"):  # interpreted, or a plain function standing in
        return kernel
    from numba._dispatcher import compute_fingerprint

    try:
        key = (kernel, tuple(compute_fingerprint(a) for a in args))
    except ValueError:  # a type numba has no fingerprint for: let the dispatcher type it
        return kernel
    found = _entries.get(key)
    if found is None:
        sig = tuple(dispatcher.typeof_pyval(a) for a in args)
        compiled = dispatcher.overloads.get(sig)
        if compiled is None:
            dispatcher.compile(sig)
            compiled = dispatcher.overloads[sig]
        found = _entries[key] = compiled.entry_point
    return found  # type: ignore[no-any-return]


class Pinned(Generic[P, R]):
    """A kernel called through the entry point :func:`entry` resolves for its first call's
    arguments, kept for the process.

    For a kernel that one Python caller calls many times a search, each call doing little work,
    with arguments whose types that caller fixes by construction (arrays it allocates with
    explicit dtypes): numba's dispatcher types every call's bundles (about 1 us a NamedTuple),
    and :func:`entry` fingerprints them (as much), where a part search's typical call expands
    one or two nodes. A call with other argument types would be misread (see :func:`entry`),
    so each caller keeps its own ``Pinned``."""

    def __init__(self, kernel: Callable[P, R]) -> None:
        self.kernel = kernel
        self._call: Callable[P, R] | None = None

    def __call__(self, *args: P.args, **kwargs: P.kwargs) -> R:
        call = self._call
        if call is None:
            call = self._call = entry(self.kernel, *args)
        return call(*args, **kwargs)
