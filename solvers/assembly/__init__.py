"""Assemblies of a puzzle's pieces: BurrTools problems (colours, groups, hole caps) assembled by
exact cover, each assembly checked for disassembly by :mod:`chaingeo.solvers.motion`, counted
the way BurrTools counts them (:mod:`chaingeo.solvers.assembly.btcount`)."""
