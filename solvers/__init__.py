"""Exact solvers, in rooms by stage: exact cover (:mod:`.cover`) and motion (:mod:`.motion`) at
the bottom, assemblies (:mod:`.assembly`) and the optimal plan (:mod:`.optimal`) above them,
one analysis of a level (:mod:`.analysis`) on top; search caps (:mod:`.limits`) and the shared
clock (:mod:`.deadline`) below all. Imports nothing above chaingeo.core."""
