"""``chain check-trajectory LEVEL TRAJ.json``: the exact verdict on a pose trajectory
(``chain-trajectory/1``, see :mod:`chaingeo.worldmodel.trajectory`): exit 0 valid, 1 invalid, 2
unreadable; the last line printed is one JSON object."""

from __future__ import annotations

import argparse
import json
from typing import Any

from chaingeo.cli.level_arg import add_level


def register(sub: Any) -> None:
    p = sub.add_parser(
        "check-trajectory",
        help="check a pose trajectory against a level: rigid pieces, allowed motions, no "
        "overlap or teleport, the goal reached; exit 0 valid, 1 invalid, 2 unreadable",
        description="Reads a chain-trajectory/1 file: frames of every piece's pose (a 3x3 "
        "rotation and a translation in lattice units, or the cells it fills). Prints one line a "
        "violation and, last, one JSON object: "
        '{"valid", "violations": [{"kind", "frame", "piece", "reason"}], "undecided", "plan", '
        '"goal"}.',
    )
    add_level(p)
    p.add_argument("trajectory", help="a chain-trajectory/1 JSON file")
    p.add_argument(
        "--max-jump",
        type=float,
        default=None,
        help="also a teleport: any piece moving farther than this (lattice units) between two "
        "frames (default: no bound; a jump through a piece is a teleport anyway)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.cli.errors import CommandError
    from chaingeo.cli.level_arg import find_level
    from chaingeo.core.files import UnreadableFile, read_bounded
    from chaingeo.core.limits import MAX_TRAJECTORY_BYTES
    from chaingeo.worldmodel.trajectory import TrajectoryError, parse_trajectory
    from chaingeo.worldmodel.trajectory_verdict import check_trajectory

    if args.max_jump is not None and not args.max_jump > 0:
        raise CommandError(f"--max-jump must be a positive number, got {args.max_jump}")
    level = find_level(args.level)
    try:
        raw = read_bounded(args.trajectory, MAX_TRAJECTORY_BYTES)
        traj = parse_trajectory(raw)
    except UnreadableFile as e:
        raise CommandError(f"{args.trajectory}: {e.reason}") from None
    except TrajectoryError as e:
        raise CommandError(f"{args.trajectory}: {e}") from None
    verdict = check_trajectory(level, traj, args.max_jump)
    for v in verdict.violations:
        print(f"frame {v['frame']}: {v['kind']}: {v['piece'] or '-'}: {v['reason']}")
    for u in verdict.undecided:
        print(f"frame {u['frame']}: undecided: {'+'.join(u['pieces'])}: {u['reason']}")
    print(json.dumps(verdict.to_json(), sort_keys=True))
    return 0 if verdict.valid else 1
