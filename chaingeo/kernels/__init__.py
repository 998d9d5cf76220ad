"""Kernel tooling: how the hot loops of every layer run (numba's ``njit`` with ``cache=True``,
ahead-of-time builds, the argument keys of both).

Not part of the domain: the geometry core knows nothing of it, and the solvers, the pictures and
the video checks use it (:mod:`.jit` is their one entry point).
"""
