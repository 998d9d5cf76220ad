"""Time budgets of tests, which are written for numba's kernels: interpreted kernels
(``CHAINGEO_JIT=python``) run 20-100 times slower, so there a bound on wall time is widened,
never in the compiled mode (results and memory bounds are checked the same in both)."""

from __future__ import annotations

from chaingeo.kernels import jit

#: Kernels are numba's in this process (read from ``CHAINGEO_JIT``, fixed for the process).
COMPILED = jit.mode() == "numba"


def seconds_for(compiled: float) -> float:
    """``compiled`` seconds under numba; a hundred times that for interpreted kernels."""
    return compiled if COMPILED else 100 * compiled
