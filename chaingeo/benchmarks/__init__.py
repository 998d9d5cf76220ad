"""Benchmarks for ``chain bench NAME``: one module each, exposing ``run(args) -> int`` and a
docstring whose first line is its help. Each reports ratios against a reference timed in the
same run, with JIT warm-up kept out of the timed figures."""
