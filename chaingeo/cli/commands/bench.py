"""``chain bench NAME``: performance figures, each reported against a reference timed in the
same run (the machines are shared and noisy, so only ratios travel)."""

from __future__ import annotations

import argparse
import importlib
import importlib.util
from typing import Any

import chaingeo.benchmarks
from chaingeo.cli.errors import CommandError

#: Benchmark names: the modules of :mod:`chaingeo.benchmarks`, discovered.
BENCHMARKS: tuple[str, ...] = chaingeo.benchmarks.BENCHMARKS.names()


def register(sub: Any) -> None:
    p = sub.add_parser("bench", help="run a benchmark: " + (", ".join(BENCHMARKS) or "none yet"))
    p.add_argument("name", choices=BENCHMARKS, help="which benchmark")
    p.add_argument("--quick", action="store_true", help="smaller instances, for a smoke run")
    p.add_argument("--repeat", type=int, default=3, help="timed repetitions (best is reported)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    module = importlib.import_module(chaingeo.benchmarks.BENCHMARKS.get(args.name))
    missing = [m for m in getattr(module, "REQUIRES", ()) if importlib.util.find_spec(m) is None]
    if missing:  # before any work: one line saying what to install, not a traceback
        extra = getattr(module, "EXTRA", "bench")
        raise CommandError(
            f"the {args.name} benchmark needs {', '.join(missing)}, which is not installed: "
            f"pip install 'chaingeo[{extra}]'"
        )
    return int(module.run(args) or 0)
