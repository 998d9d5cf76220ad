"""The one place kernels are compiled: numba's ``njit``, ahead of time, or the plain function.

Every kernel of the toolkit is written once, for numba, on flat numpy arrays, and decorated with
:func:`njit` from here. By default that is numba's ``njit``. Starting numba and loading its
cached kernels costs ~0.5 s of a process, many times the work of a small puzzle, so two other
modes exist, both without importing numba:

- *ahead-of-time* (``aot``): each kernel is an :class:`chaingeo.kernels.aot.AotKernel` calling the
  functions ``chain precompile`` compiled for the argument types a workload used; ``chain
  analyze`` uses them when they match the sources and starts again with numba on a miss;
- *interpreted* (``python``): the decorator returns the function itself; ``chain analyze`` runs
  a single small file so when nothing is precompiled, and moves to numba when the work turns
  out larger (see :mod:`chaingeo.cli.commands.analyze`).

The mode is read from ``CHAINGEO_JIT`` (``numba``, the default, ``aot`` or ``python``) when a
kernel module is first imported, so it is fixed for a process before any kernel is defined;
changing it later raises. Every mode computes the same results: fixed-width numpy integers wrap
as numba's do (numpy's overflow warnings are silenced in interpreted mode).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from typing import Any, Final, Generic, Literal, ParamSpec, TypeVar, overload

import numpy as np

Mode = Literal["numba", "aot", "python"]
ENV: Final = "CHAINGEO_JIT"
MODES: Final[tuple[Mode, ...]] = ("numba", "aot", "python")

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
        try:
            _fix(raw)
        except RuntimeError as e:  # an unusable store: one line, then numba's kernels
            print(f"chaingeo: {ENV}=aot: {e}; using numba", file=sys.stderr)
            _fix("numba")
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
    if wanted == "aot" and _mode != "aot":
        from chaingeo.kernels import aot

        if aot.load() is None:
            raise RuntimeError(f"no usable ahead-of-time kernels: {aot.status().sentence}")
    _mode = wanted
    if wanted == "python":
        np.seterr(over="ignore")  # numpy scalars warn where numba's integers wrap silently


@overload
def njit(fn: F, /) -> F: ...
@overload
def njit(**options: Any) -> Callable[[F], F]: ...
def njit(*args: Any, **options: Any) -> Any:
    """``numba.njit`` with the same arguments, the kernel compiled ahead of time, or
    (interpreted) the function unchanged."""
    current = mode()
    if current == "python":
        make: Callable[[Any], Any] = _identity
    elif current == "aot":
        make = _ahead_of_time
    else:
        import numba  # only here: the other modes never import it

        compiled = numba.njit(**options)

        def make(fn: Any) -> Any:
            dispatcher = compiled(fn)
            _dispatchers.append(dispatcher)
            return dispatcher

    if args and callable(args[0]):
        return make(args[0])
    return make


_dispatchers: list[Any] = []


def dispatchers() -> list[Any]:
    """Every numba dispatcher :func:`njit` made in this process (what ``chain precompile``
    reads the compiled signatures from)."""
    return list(_dispatchers)


def _identity(fn: F) -> F:
    return fn


def _ahead_of_time(fn: Callable[..., Any]) -> Any:
    from chaingeo.kernels import aot

    loaded = aot.load()
    assert loaded is not None  # the mode is set only once a build loaded
    return aot.AotKernel(fn, loaded.exports_of(aot.kernel_name(fn)))


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
    resolve = getattr(kernel, "resolve", None)
    if resolve is not None:  # ahead of time
        return resolve(args)  # type: ignore[no-any-return]
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
