"""``chain render LEVEL``: pictures of a level solved (four views), of its pieces (each from two
opposite corners) and, with ``--exploded``, of the solved level pushed apart."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from chaingeo.cli.level_arg import add_level
from chaingeo.cli.out_arg import add_out


def register(sub: Any) -> None:
    p = sub.add_parser("render", help="write PNG pictures of a level, solved, and of its pieces")
    add_level(p)
    add_out(p, "folder", "the PNGs, LEVEL_ID-VIEW.png", default=Path("."))
    p.add_argument("--size", type=int, default=512, help="picture size in pixels")
    p.add_argument(
        "--exploded",
        action="store_true",
        help="also write LEVEL-exploded.png: the solved level, each piece pushed out along its "
        "first slide in the optimal plan (or radially)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.cli.level_arg import find_level
    from chaingeo.cli.out_arg import out_folder
    from chaingeo.core.files import atomic_write
    from chaingeo.pictures.pictures import render_exploded
    from chaingeo.pictures.scene import render_level_tray, render_solution_views

    level = find_level(args.level)
    pictures = dict(render_solution_views(level, size=args.size))
    pictures["pieces"] = render_level_tray(level, args.size)
    if args.exploded:
        pictures["exploded"] = render_exploded(level, args.size)
    out_folder(args.out)
    for view, data in pictures.items():
        target = args.out / f"{level.id}-{view}.png"
        atomic_write(target, data)
        print(target)
    return 0
