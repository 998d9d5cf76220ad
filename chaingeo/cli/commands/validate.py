"""``chain validate PATH...``: load and fully verify level files, print a summary line each.

Beyond what loading checks, a puzzle's ``optimal_steps`` is re-derived by the optimal search
when that search stays within :data:`chaingeo.core.limits.RECHECK_MAX_STATES` states (the same
cap the tests use): a stored value that is not the optimum is an error (exit status 2). Larger
puzzles are reported with ``"optimal_checked": false``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # the level reader is imported when a command runs, not to list commands
    from chaingeo.core.level import Level


def register(sub: Any) -> None:
    p = sub.add_parser("validate", help="verify level files (format, geometry, stored solutions)")
    p.add_argument("paths", nargs="+", type=Path, help="level files or folders of them")
    p.add_argument(
        "--no-recheck", action="store_true", help="skip re-deriving optimal_steps by search"
    )
    p.set_defaults(func=run)


def recheck_optimal(level: Level) -> int | None:
    """The true optimum of a puzzle level when the capped search finds it, else None
    (stacking levels: their optimum is the piece count, which loading already checks)."""
    from chaingeo.core.kinematics import SearchLimitError
    from chaingeo.core.limits import RECHECK_MAX_STATES
    from solvers.analysis import analyze_level
    from solvers.partsearch import SearchLimits

    if level.family != "puzzle":
        return len(level.pieces)
    limits = SearchLimits(
        max_states=RECHECK_MAX_STATES, seconds=None, max_total_states=RECHECK_MAX_STATES
    )
    try:
        return analyze_level(level, limits).optimal_steps
    except SearchLimitError:
        return None


def run(args: argparse.Namespace) -> int:
    from chaingeo.core.level import content_hash, level_set_hash, load_level

    files: list[Path] = []
    for path in args.paths:
        files.extend(sorted(path.rglob("*.json")) if path.is_dir() else [path])
    levels = []
    status = 0
    for f in files:
        lv = load_level(f)
        levels.append(lv)
        row: dict[str, Any] = {
            "file": str(f),
            "id": lv.id,
            "family": lv.family,
            "difficulty": lv.difficulty,
            "optimal_steps": lv.optimal_steps,
            "content_hash": content_hash(lv),
        }
        if not args.no_recheck:
            true_optimum = recheck_optimal(lv)
            row["optimal_checked"] = true_optimum is not None
            if true_optimum is not None and true_optimum != lv.optimal_steps:
                row["error"] = (
                    f"{f}: optimal_steps: {lv.optimal_steps} recorded but the optimum is "
                    f"{true_optimum}"
                )
                status = 2
        print(json.dumps(row))
    print(json.dumps({"levels": len(levels), "level_set_hash": level_set_hash(levels)}))
    return status
