"""``chain export LEVEL --format glb|stl|obj``: a level's pieces at their solution positions as
a mesh file (one named, coloured mesh per piece in GLB and OBJ; one solid in STL)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

#: The same as :data:`chaingeo.envs.render.mesh.FORMATS` (kept here so ``chain --help`` loads no
#: mesh code).
FORMATS = ("glb", "stl", "obj")


def register(sub: Any) -> None:
    p = sub.add_parser("export", help="write a level's pieces (solved) as a GLB, STL or OBJ mesh")
    p.add_argument("level", type=Path, help="a chain-level/1 file")
    p.add_argument("--format", choices=FORMATS, default="glb", help="mesh format (default glb)")
    p.add_argument("--out", type=Path, help="output file (default: LEVEL_ID.FORMAT here)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.core.level import load_level
    from chaingeo.envs.render.mesh import export_level

    level = load_level(args.level)
    target: Path = args.out or Path(f"{level.id}.{args.format}")
    data = export_level(level, args.format)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = target.with_name(f".{target.name}.tmp")
    tmp.write_bytes(data)
    tmp.replace(target)
    print(target)
    return 0
