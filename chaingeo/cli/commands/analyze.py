"""``chain analyze FILE [--problem N] [--mirrors keep|drop]``: assemblies, solutions, level, moves
and o_i of a puzzle (one of our level files or a BurrTools ``.xmpuzzle``), printed as one JSON
object. A ``.xmpuzzle`` with several problems and no ``--problem`` gives
``{"problems": [...], "seconds": ...}``, one object per problem.

``--mirrors keep`` (default) counts mirror images apart: BurrTools' stored figures (e.g. 1063
assemblies / 314 solutions on its SolidSixPieceBurrs example); ``--mirrors drop`` identifies an
assembly with its mirror image when that is an assembly too: what BurrTools' command-line
solver prints (588 / 179 there).

``--seconds`` bounds the whole command: the enumeration of assemblies, every disassembly and the
optimal search share one deadline; past it the command fails with the limit's message (exit
status 2), except that a spent optimal search alone is reported as ``optimal_error``."""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path
from typing import Any

from chaingeo.cli.errors import CommandError


def register(sub: Any) -> None:
    p = sub.add_parser(
        "analyze", help="assemblies, solutions, level and optimal steps of a puzzle file"
    )
    p.add_argument("file", type=Path, help="a chain-level/1 puzzle file or a .xmpuzzle file")
    p.add_argument(
        "--problem",
        type=int,
        default=None,
        help="problem index in a .xmpuzzle file (default: every problem)",
    )
    p.add_argument(
        "--mirrors",
        choices=("keep", "drop"),
        default="keep",
        help="keep mirror-image assemblies apart (BurrTools' stored counts) or drop them "
        "(BurrTools' command-line solver)",
    )
    p.add_argument(
        "--seconds",
        type=float,
        default=120.0,
        help="time limit of the whole analysis (assemblies, disassembly and optimal search)",
    )
    p.add_argument("--max-states", type=int, default=2_000_000, help="state cap per part")
    p.add_argument("--no-optimal", action="store_true", help="skip the optimal-plan search")
    p.add_argument(
        "--no-assemble", action="store_true", help="skip counting assemblies (level only)"
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.core.kinematics import SearchLimitError
    from solvers.analysis import level_figures, xmpuzzle_figures
    from solvers.partsearch import SearchLimits

    if not (math.isfinite(args.seconds) and args.seconds > 0):
        raise CommandError(f"--seconds: expected a positive number of seconds, got {args.seconds}")
    limits = SearchLimits(max_states=args.max_states, seconds=args.seconds)
    start = time.perf_counter()
    try:
        if args.file.suffix == ".xmpuzzle":
            out = xmpuzzle_figures(
                args.file,
                args.problem,
                limits,
                not args.no_optimal,
                not args.no_assemble,
                args.mirrors,
            )
        else:
            from chaingeo.core.level import load_level  # a BurrTools file needs no level reader

            level = load_level(args.file)
            out = level_figures(
                level, limits, not args.no_optimal, not args.no_assemble, args.mirrors
            )
    except SearchLimitError as e:
        raise CommandError(str(e)) from None
    except (IndexError, RuntimeError) as e:
        raise CommandError(str(e)) from None
    out["seconds"] = round(time.perf_counter() - start, 3)
    print(json.dumps(out, sort_keys=True))
    return 0
