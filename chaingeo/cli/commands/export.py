"""``chain export LEVEL --format glb|stl|obj``: a level's pieces at their solution positions as
a mesh file (one named, coloured mesh per piece in GLB and OBJ; one solid in STL)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from chaingeo.cli.level_arg import add_level
from chaingeo.cli.out_arg import add_out

#: The same as :data:`chaingeo.pictures.mesh.FORMATS` (kept here so ``chain --help`` loads no
#: mesh code).
FORMATS = ("glb", "stl", "obj")


def register(sub: Any) -> None:
    p = sub.add_parser("export", help="write a level's pieces (solved) as a GLB, STL or OBJ mesh")
    add_level(p)
    p.add_argument("--format", choices=FORMATS, default="glb", help="mesh format")
    add_out(p, "file", "the mesh (default: LEVEL_ID.FORMAT here)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.cli.level_arg import find_level
    from chaingeo.core.files import atomic_write
    from chaingeo.pictures.mesh import export_level

    level = find_level(args.level)
    target: Path = args.out or Path(f"{level.id}.{args.format}")
    data = export_level(level, args.format)
    atomic_write(target, data)  # a unique temporary name, removed if the disk is full
    print(target)
    return 0
