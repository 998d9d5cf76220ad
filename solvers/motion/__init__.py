"""Exact motion of voxel pieces: which groups can slide or turn (numba kernels), breadth-first
searches over one part's configurations, and the disassembly searches built on them (the
level of a puzzle and a plan, :mod:`chaingeo.solvers.motion.disassemble`)."""
