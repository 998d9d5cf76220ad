"""``chain video LEVEL [--plan optimal|FILE] --out FILE.mp4|.gif``: a plan as continuous motion
from one fixed camera (see :mod:`chaingeo.worldmodel.video`)."""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

from chaingeo.cli.level_arg import add_level
from chaingeo.cli.out_arg import add_out


def register(sub: Any) -> None:
    p = sub.add_parser("video", help="render a level's plan as an MP4 or GIF video")
    add_level(p)
    p.add_argument(
        "--plan",
        default="optimal",
        help="'optimal' (the level's own plan) or a text file of actions, one a line, "
        "as an agent would type them",
    )
    add_out(p, "file", "the video, FILE.mp4 or FILE.gif", required=True)
    p.add_argument("--size", type=int, default=384, help="frame size in pixels")
    p.add_argument(
        "--trajectory-out",
        type=Path,
        default=None,
        metavar="FILE",
        help="also write the plan's pose trajectory (chain-trajectory/1 JSON; chain "
        "check-trajectory reads it)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.cli.errors import CommandError
    from chaingeo.cli.level_arg import find_level
    from chaingeo.worldmodel.trajectory import write_trajectory
    from chaingeo.worldmodel.video import VideoError, plan_video, write_video

    if args.out.suffix.lower() not in (".mp4", ".gif"):
        raise CommandError(f"--out must end in .mp4 or .gif, got {str(args.out)!r}")
    if args.size < 128 or args.size % 16:
        raise CommandError(f"--size must be a multiple of 16, at least 128; got {args.size}")
    level = find_level(args.level)
    start = time.perf_counter()
    try:
        text = None
        if args.plan != "optimal":
            path = Path(args.plan)
            if not path.is_file():
                raise CommandError(f"--plan: no file {args.plan!r} (or say 'optimal')")
            text = path.read_text(encoding="utf-8")
        video = plan_video(level, text, args.size)
        if args.trajectory_out is not None:
            write_trajectory(level, text, args.trajectory_out)
        write_video(video, args.out)
    except VideoError as e:
        raise CommandError(str(e)) from None
    seconds = time.perf_counter() - start
    print(f"{args.out}: {len(video.frames)} frames at {video.fps} fps, rendered in {seconds:.1f} s")
    return 0
