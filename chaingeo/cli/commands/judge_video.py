"""``chain judge-video VIDEO [--level LEVEL] [--evidence DIR]``: is a generated video of a
puzzle coming apart physically valid? (see :mod:`chaingeo.worldmodel.judge_video`). Exit 0
valid, 1 invalid, 2 unreadable input; the last line printed is the JSON report."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any


def register(sub: Any) -> None:
    p = sub.add_parser(
        "judge-video",
        help="judge a generated video: pieces disappearing, appearing, split, merged, "
        "recoloured, duplicated, teleported or pushed through each other",
    )
    p.add_argument("video", type=Path, help="an MP4 (or any video ffmpeg reads) or a GIF")
    p.add_argument(
        "--level",
        default=None,
        metavar="LEVEL",
        help="the level shown (a chain-level/1 file or the id of a shipped level): its piece "
        "colours, and for a video drawn by 'chain video' the kinematic check of every move "
        "(default: colours from the first frame)",
    )
    p.add_argument(
        "--evidence",
        type=Path,
        default=None,
        metavar="DIR",
        help="folder (created when missing): one PNG a violation",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.cli.errors import CommandError
    from chaingeo.cli.level_arg import find_level
    from chaingeo.worldmodel.judge_video import VideoJudgeError, judge_video

    level = find_level(args.level) if args.level is not None else None
    try:
        report = judge_video(args.video, level, args.evidence)
    except VideoJudgeError as e:
        raise CommandError(str(e)) from None
    for v in report["violations"]:
        first, last = v["frames"]
        span = f"frame {first}" if first == last else f"frames {first}-{last}"
        print(f"{span}: {v['kind']} ({v['piece']}): {v['detail']}")
    for u in report["undecided"]:
        print(f"undecided: {u}")
    print(json.dumps(report, sort_keys=True))
    return 0 if report["valid"] else 1
