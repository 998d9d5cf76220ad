"""``chain bench NAME``: performance figures, each reported against a reference timed in the
same run (the machines are shared and noisy, so only ratios travel)."""

from __future__ import annotations

import argparse
import importlib
from typing import Any

#: Benchmark name -> "module:function"; each function takes the parsed args and returns 0/1.
BENCHMARKS: dict[str, str] = {}


def register(sub: Any) -> None:
    p = sub.add_parser(
        "bench", help="run a benchmark: " + (", ".join(sorted(BENCHMARKS)) or "none yet")
    )
    p.add_argument("name", choices=sorted(BENCHMARKS) or None, help="which benchmark")
    p.add_argument("--quick", action="store_true", help="smaller instances, for a smoke run")
    p.add_argument("--repeat", type=int, default=3, help="timed repetitions (best is reported)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    module, func = BENCHMARKS[args.name].split(":")
    return int(getattr(importlib.import_module(module), func)(args) or 0)
