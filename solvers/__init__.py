"""Exact solvers: exact cover, disassembly search, plan search. Import nothing above them."""
