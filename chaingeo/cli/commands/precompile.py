"""``chain precompile [FILE...] [--status]``: compile the analysis kernels ahead of time, so that
``chain analyze`` starts in milliseconds instead of half a second.

The command runs a workload under numba (every shipped puzzle level, each also as a BurrTools
puzzle; the BurrTools feature examples of :mod:`chaingeo.generator.bt_examples`: colour rules,
piece groups, ranges, several problems; any ``FILE``: levels or ``.xmpuzzle`` files; BurrTools
puzzles with mirrors kept and dropped; each analysis capped at ``--seconds``), then compiles
every kernel signature that work used into one extension module in the user cache
(:mod:`chaingeo.kernels.aot_build`). ``chain analyze`` uses it while it matches the installed
sources and numpy, and falls back to numba for a call the workload did not cover. Needs a C
compiler (numba's ``pycc`` links the module with it).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path
from typing import Any

from chaingeo.cli.errors import CommandError


def register(sub: Any) -> None:
    p = sub.add_parser(
        "precompile", help="compile the analysis kernels ahead of time (fast `chain analyze`)"
    )
    p.add_argument(
        "files",
        nargs="*",
        metavar="FILE",
        help="further inputs for the workload: level files or ids, .xmpuzzle files",
    )
    p.add_argument(
        "--seconds",
        type=float,
        default=2.0,
        help="cap on each analysis of the workload (the kernels compile on their first call)",
    )
    p.add_argument(
        "--status", action="store_true", help="say what is stored and whether it is used"
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.kernels import aot

    if args.status:
        print(f"{aot.store_dir()}: {aot.status().sentence}")
        return 0
    if not args.seconds > 0:
        raise CommandError(f"--seconds: expected a positive number, got {args.seconds}")
    _numba_mode()
    from chaingeo.kernels import aot_build, jit

    start = time.perf_counter()
    for label, run_one in _workload(args.files, args.seconds):
        print(f"chain precompile: running {label}", file=sys.stderr, flush=True)
        run_one()
    found = aot_build.exports(jit.dispatchers())
    ran = time.perf_counter() - start
    print(f"chain precompile: compiling {len(found)} signatures", file=sys.stderr, flush=True)
    try:
        manifest = aot_build.build(found)
    except Exception as e:  # pycc needs a C compiler; say why and change nothing
        raise CommandError(f"compiling failed ({type(e).__name__}: {e})") from None
    print(
        f"{aot.store_dir()}: {len(found)} signatures of {len(manifest.exports)} kernels "
        f"(workload {ran:.0f} s, compile {time.perf_counter() - start - ran:.0f} s)"
    )
    return 0


def _numba_mode() -> None:
    from chaingeo.kernels.jit import ENV, set_mode

    if os.environ.get(ENV, "numba") != "numba":
        raise CommandError(f"{ENV}={os.environ[ENV]}: precompiling needs numba's kernels")
    try:
        set_mode("numba")
    except RuntimeError as e:
        raise CommandError(str(e)) from None


def _workload(files: list[str], seconds: float) -> list[tuple[str, Any]]:
    """(label, thunk) pairs: every shipped puzzle level as a level and as a BurrTools puzzle,
    the BurrTools feature examples, then the given files (puzzles with mirrors kept and
    dropped)."""
    from chaingeo.core.formats.bt_write import assembled_puzzle
    from chaingeo.core.suite import load_level, shipped_levels
    from chaingeo.generator.bt_examples import EXAMPLES

    work: list[tuple[str, Any]] = []
    for level_id in shipped_levels("puzzle"):
        level = load_level(level_id)
        work.append((level_id, _analysis(level, seconds, "keep")))
        puzzle = assembled_puzzle(level.shapes)
        for mirrors in ("keep", "drop"):
            work.append((f"{level_id} as .xmpuzzle", _analysis(puzzle, seconds, mirrors)))
    for name, make in EXAMPLES.items():
        example = make()
        for mirrors in ("keep", "drop"):
            work.append((f"BurrTools example {name}", _analysis(example, seconds, mirrors)))
    for spec in files:
        source: Any = spec if Path(spec).suffix == ".xmpuzzle" else load_level(spec)
        for mirrors in ("keep", "drop"):
            work.append((spec, _analysis(source, seconds, mirrors)))
    return work


def _analysis(source: Any, seconds: float, mirrors: str) -> Any:
    def thunk() -> None:
        from chaingeo.core.errors import ChainGeoError
        from chaingeo.core.kinematics import SearchLimitError
        from chaingeo.solvers.analysis import analyze
        from chaingeo.solvers.limits import SearchLimits

        limits = SearchLimits(seconds=seconds, optimal_seconds=seconds)
        try:
            analyze(source, limits=limits, mirrors=mirrors)  # type: ignore[arg-type]
        except (ChainGeoError, SearchLimitError, ValueError, RuntimeError) as e:
            print(f"chain precompile: (stopped: {e})", file=sys.stderr)

    return thunk
