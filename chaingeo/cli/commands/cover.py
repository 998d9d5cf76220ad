"""``chain cover``: count the packings of a piece set into a box with the exact-cover engine.

Prints one JSON object: ``solutions`` (all packings), ``distinct`` (up to the box's rotations
and reflections, reflections only when the piece set is mirror-closed), ``seconds`` (wall time
of the count, JIT loading excluded), ``nodes`` and the search details. Pieces are always free
3D pieces (a flat pentomino may be turned over or stood up), so the solid-pentomino counts need
no extra flag. ``--jobs N`` (default: the machine's cores) searches the subtrees of a large
search on N worker processes (:mod:`chaingeo.solvers.cover.parallel`), ``--scheduler ADDRESS`` on
a Dask cluster: the same counts, a different ``nodes`` (each subtree's search places its forced
rows again).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from chaingeo.cli.errors import CommandError

if TYPE_CHECKING:
    from chaingeo.core.level import Level


def register(sub: Any) -> None:
    p = sub.add_parser("cover", help="count packings of a piece set into a box (exact cover)")
    p.add_argument(
        "--pieces",
        required=True,
        help="a built-in piece set (soma, pentominoes, bedlam), a level file or the id of a "
        "shipped level, or a JSON file holding a list (or a name -> voxels mapping) of voxel "
        "lists",
    )
    p.add_argument("--box", help="box size AxBxC (default: the level file's box)")
    p.add_argument(
        "--engine", choices=("auto", "dlx", "bitboard"), default="auto", help="exact-cover engine"
    )
    p.add_argument(
        "--rotations-only", action="store_true", help="count distinct up to rotations only"
    )
    p.add_argument("--no-distinct", action="store_true", help="count all packings only")
    p.add_argument("--no-symmetry", action="store_true", help="search without symmetry reduction")
    p.add_argument("--node-limit", type=int, default=None, help="stop after this many nodes")
    p.add_argument(
        "--jobs",
        type=int,
        default=None,
        help="worker processes searching subtrees of a large search (default: the machine's "
        "cores; one with --node-limit); the same counts whatever it is",
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        default=None,
        help="search the subtrees on the Dask cluster at ADDRESS instead of local workers (the "
        "cluster extra); the same counts",
    )
    p.set_defaults(func=run)


def parse_box(text: str) -> tuple[int, int, int]:

    parts = text.lower().split("x")
    try:
        dims = tuple(int(p) for p in parts)
    except ValueError:
        dims = ()
    if len(dims) != 3 or min(dims) < 1:
        raise CommandError(f"--box: expected AxBxC with positive sizes, got {text!r}")
    return dims


def load_pieces(source: str) -> tuple[dict[str, Any], tuple[int, int, int] | None]:
    """Pieces by name (and the level's box, if the source is a level file)."""
    from chaingeo.core.geometry import Shape
    from chaingeo.core.level import parse_level
    from chaingeo.core.piecesets import get_pieceset

    path = Path(source)
    if not (path.exists() or path.is_symlink()):  # a name: a piece set or a level id
        try:
            return dict(get_pieceset(source).pieces), None
        except KeyError as e:
            level = _shipped_level(source)
            if level is None:
                raise CommandError(f"--pieces: no such file or level id, and {e.args[0]}") from None
            return dict(level.shapes), level.box
    from chaingeo.core import limits
    from chaingeo.core.files import UnreadableFile, read_json

    try:  # the one bounded JSON reader
        data = read_json(path, limits.MAX_FILE_BYTES)
    except UnreadableFile as e:
        raise CommandError(f"--pieces: cannot read {source}: {e.reason}") from None
    if isinstance(data, dict) and "format" in data:
        level = parse_level(data, source)
        return dict(level.shapes), level.box
    items = data.items() if isinstance(data, dict) else enumerate(data, start=1)
    pieces: dict[str, Any] = {}
    for key, voxels in items:
        try:
            shape = Shape(voxels)
        except (TypeError, ValueError) as e:
            raise CommandError(
                f"--pieces: piece {key!r} in {source} is not a voxel list: {e}"
            ) from None
        if len(shape) == 0:
            raise CommandError(f"--pieces: piece {key!r} in {source} is empty")
        pieces[str(key)] = shape
    if not pieces:
        raise CommandError(f"--pieces: {source} holds no pieces")
    return pieces, None


def _shipped_level(spec: str) -> Level | None:
    """The shipped level of id ``spec``, if any (an unknown name is the piece-set error)."""
    from chaingeo.cli.level_arg import find_level

    try:
        return find_level(spec)
    except CommandError:
        return None


def run(args: argparse.Namespace) -> int:
    from chaingeo.core.geometry import Shape
    from chaingeo.solvers.cover.packings import CoverLimitError, count_packings

    pieces, level_box = load_pieces(args.pieces)
    if args.box is not None:
        box = parse_box(args.box)
    elif level_box is not None:
        box = level_box
    else:
        raise CommandError("--box is required unless --pieces is a stacking level file")
    from chaingeo.solvers.jobs import as_farm

    if args.jobs is not None and args.jobs < 1:
        raise CommandError(f"--jobs: expected a positive number of processes, got {args.jobs}")
    jobs = as_farm(args.jobs, args.scheduler)
    count_packings([Shape([(0, 0, 0)])], (1, 1, 1), engine=args.engine)  # load the JIT
    t0 = time.perf_counter()
    try:
        result = count_packings(
            pieces,
            box,
            distinct=not args.no_distinct,
            reflections=not args.rotations_only,
            engine=args.engine,
            node_limit=args.node_limit,
            symmetry=not args.no_symmetry,
            jobs=jobs,
        )
    except CoverLimitError as e:
        raise CommandError(str(e)) from None
    seconds = time.perf_counter() - t0
    print(
        json.dumps(
            {
                "solutions": result.solutions,
                "distinct": result.distinct,
                "seconds": round(seconds, 6),
                "search_seconds": round(result.stats.seconds, 6),
                "nodes": result.stats.nodes,
                "updates": result.stats.updates,
                "engine": result.stats.engine,
                "anchor": result.anchor,
                "symmetry_order": result.symmetry_order,
                "pieces": len(pieces),
                "box": list(box),
            }
        )
    )
    return 0
