"""``chain validate PATH...``: load and fully verify level files, print a summary line each.

Beyond what loading checks, a puzzle's ``optimal_steps`` is re-derived by the optimal search
when that search stays within :data:`chaingeo.core.limits.RECHECK_MAX_STATES` states (the same
cap the tests use): a stored value that is not the optimum is an error. A puzzle the search
cannot settle (past the state cap, or a part of more pieces than the search kernels take) is
reported with ``"optimal_checked": false`` and ``"unchecked_reason"``: every level the loader
accepts gets a row, never an exception.

Exit status: 0 when every file loads and no re-derived optimum contradicts the stored one
(unchecked puzzles included); 2 when a file does not load, a stored optimum is not the optimum
or the structure a proven bound needs (``stats.blocks``) is malformed.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

from chaingeo.core.errors import ChainGeoError

if TYPE_CHECKING:  # the level reader is imported when a command runs, not to list commands
    from chaingeo.core.level import Level


def register(sub: Any) -> None:
    p = sub.add_parser("validate", help="verify level files (format, geometry, stored solutions)")
    p.add_argument(
        "paths",
        nargs="+",
        metavar="LEVEL",
        help="level files, folders of them, or ids of shipped levels",
    )
    p.add_argument(
        "--no-recheck", action="store_true", help="skip re-deriving optimal_steps by search"
    )
    p.set_defaults(func=run)


class NotRechecked(ChainGeoError):
    """The optimal search cannot settle this level's optimum; ``reason`` says why."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


class BadBlocks(ChainGeoError, ValueError):
    """``stats.blocks`` (the towers a proven bound uses) is malformed: the file is wrong."""


def recheck_optimal(level: Level) -> int:
    """The true optimum of a puzzle level (stacking levels: the piece count, which loading
    already checks). Raises :class:`NotRechecked` when the capped search cannot settle it and
    :class:`BadBlocks` when the level's ``stats.blocks`` is malformed."""
    from chaingeo.core.kinematics import SearchLimitError
    from chaingeo.core.limits import RECHECK_MAX_STATES
    from chaingeo.solvers.analysis import analyze_level, level_blocks
    from chaingeo.solvers.limits import SearchLimits
    from chaingeo.solvers.motion.kinematics_kernel import MAX_PIECES

    if level.family != "puzzle":
        return len(level.pieces)
    if len(level.pieces) > MAX_PIECES:  # the search starts from one part of every piece
        raise NotRechecked(
            f"{len(level.pieces)} pieces; the optimal search takes at most {MAX_PIECES} "
            "pieces in a part"
        )
    try:
        blocks = level_blocks(level)
    except ValueError as e:
        raise BadBlocks(str(e)) from None
    limits = SearchLimits(
        max_states=RECHECK_MAX_STATES, seconds=None, max_total_states=RECHECK_MAX_STATES
    )
    try:
        optimum = analyze_level(level, limits).optimal_steps
    except SearchLimitError as e:
        raise NotRechecked(f"the search stopped at its cap: {e}") from None
    except ValueError as e:  # the solvers refuse what they cannot take with a ValueError
        if blocks is not None:  # blocks the bound cannot use (with turns, not a tower, ...)
            raise BadBlocks(str(e)) from None
        raise NotRechecked(f"the search cannot take this level: {e}") from None
    if optimum is None:  # the stored plan replays, so this is the search's shortfall
        raise NotRechecked("the search found no plan")
    return optimum


def _recheck_row(level: Level, f: Path) -> tuple[dict[str, Any], bool]:
    """The row's re-check fields and whether they report an error."""
    try:
        true_optimum = recheck_optimal(level)
    except NotRechecked as e:
        return {"optimal_checked": False, "unchecked_reason": e.reason}, False
    except BadBlocks as e:
        return {"optimal_checked": False, "error": f"{f}: stats.blocks: {e}"}, True
    row: dict[str, Any] = {"optimal_checked": True}
    if true_optimum != level.optimal_steps:
        row["error"] = (
            f"{f}: optimal_steps: {level.optimal_steps} recorded but the optimum is {true_optimum}"
        )
    return row, "error" in row


def run(args: argparse.Namespace) -> int:
    from chaingeo.cli.level_arg import level_file
    from chaingeo.core.level import content_hash, level_set_hash, load_level

    files: list[Path] = []
    for spec in args.paths:
        path = Path(spec)
        files.extend(sorted(path.rglob("*.json")) if path.is_dir() else [level_file(spec)])
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
            checked, failed = _recheck_row(lv, f)
            row.update(checked)
            status = 2 if failed else status
        print(json.dumps(row))
    print(json.dumps({"levels": len(levels), "level_set_hash": level_set_hash(levels)}))
    return status
