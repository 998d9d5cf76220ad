"""Benchmarks for ``chain bench NAME``: one module each, exposing ``run(args) -> int`` and a
docstring whose first line is its help. Each reports ratios against a reference timed in the
same run, with JIT warm-up kept out of the timed figures."""

from __future__ import annotations

import pkgutil

from chaingeo.core.registry import Registry

#: Benchmark name -> its module (imported only when run: ``chain --help`` stays fast).
BENCHMARKS: Registry[str] = Registry("benchmark")
for _module in sorted(m.name for m in pkgutil.iter_modules(__path__)):
    if not _module.startswith("_"):  # a private module is a part of one (robustness's classes)
        BENCHMARKS.register(_module, f"{__name__}.{_module}")
