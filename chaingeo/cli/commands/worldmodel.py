"""``chain worldmodel LEVEL --out DIR``: what a video model is given for a level (reference
image and prompt) and the ground-truth video of its optimal plan (see
:mod:`chaingeo.worldmodel.prompt`)."""

from __future__ import annotations

import argparse
from typing import Any

from chaingeo.cli.level_arg import add_level
from chaingeo.cli.out_arg import add_out


def register(sub: Any) -> None:
    p = sub.add_parser(
        "worldmodel",
        help="write a level's reference image, video-model prompt and ground-truth video",
    )
    add_level(p)
    add_out(p, "folder", "the reference image, the prompt and the video", required=True)
    p.add_argument(
        "--format",
        choices=("mp4", "gif"),
        default=None,
        help="ground-truth video format (default: mp4 with the extra 'video', else gif)",
    )
    p.add_argument("--size", type=int, default=384, help="frame size in pixels")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.cli.errors import CommandError
    from chaingeo.cli.level_arg import find_level
    from chaingeo.worldmodel.prompt import write_worldmodel
    from chaingeo.worldmodel.video import VideoError, mp4_available

    if args.size < 128 or args.size % 16:
        raise CommandError(f"--size must be a multiple of 16, at least 128; got {args.size}")
    fmt = args.format or ("mp4" if mp4_available() else "gif")
    level = find_level(args.level)
    try:
        files = write_worldmodel(level, args.out, fmt, args.size)
    except VideoError as e:
        raise CommandError(str(e)) from None
    for path in files.values():
        print(path)
    return 0
