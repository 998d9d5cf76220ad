"""``chain convert``: move levels between our format, the original CHAIN stacking JSON and
BurrTools' ``.xmpuzzle``.

``--to xmpuzzle`` writes any level (a file or a level id of the shipped suite) as a BurrTools
file: the assembled shape (puzzles) or the box (stacking) as the result, each piece its own
shape, the level's assembly stored as the solution (:mod:`chaingeo.core.formats.bt_level`);
rules BurrTools cannot express (turns, a cap on group size) are named on standard error.

``--from chain`` (or ``--to chain-level``) reads CHAIN's level file as CHAIN writes it: packed
(the cells fill the box) or in tray form (each piece where it lies beside the box). A tray
file is packed here with the exact-cover engine (``chaingeo.solvers.cover.packings.first_packing``,
the pieces as free shapes, rotations only as in CHAIN); the level keeps CHAIN's piece ids and is
verified like any level file before it is written. ``--rules chain`` gives it CHAIN's rules profile.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from chaingeo.cli.errors import CommandError
from chaingeo.cli.level_arg import find_level
from chaingeo.cli.out_arg import add_out

if TYPE_CHECKING:  # the command imports its work lazily, so `chain --help` stays fast
    from chaingeo.core.formats.chain_json import ChainStacking
    from chaingeo.core.geometry import Shape
    from chaingeo.core.level import Level

#: Exact-cover nodes allowed when packing a tray file (CHAIN's hardest levels need thousands).
PACK_NODE_LIMIT = 50_000_000
#: Said on standard error when the file to write comes positionally (the old grammar).
DEPRECATED_TARGET = (
    "chain convert: warning: a positional TARGET is deprecated and goes in the next release; "
    "write --out {target}"
)
_DIFFICULTY_RE = re.compile(r"(?:^|[_\-.])(easy|mid|hard)(?:$|[_\-.])")


def register(sub: Any) -> None:
    p = sub.add_parser(
        "convert",
        help="import/export CHAIN's stacking JSON; export any level as a BurrTools .xmpuzzle",
    )
    p.add_argument(
        "source",
        help="the file to read: on import CHAIN's level file; on export a chain-level/1 file "
        "or the id of a shipped level",
    )
    # Deprecated (one release): the file to write, as --out; hidden from the help.
    p.add_argument("target", type=Path, nargs="?", help=argparse.SUPPRESS)
    add_out(p, "file", "the level (import; default: standard output) or the exported file")
    required = p.add_argument_group("direction (required: one of)")
    direction = required.add_mutually_exclusive_group(required=True)
    direction.add_argument(
        "--to",
        choices=("chain-level", "chain-json", "xmpuzzle"),
        help="chain-level: import an original file; chain-json: export one of our stacking "
        "levels; xmpuzzle: export one of our levels as a BurrTools file",
    )
    direction.add_argument(
        "--from",
        dest="source_format",
        choices=("chain",),
        help="chain: import CHAIN's level file, packed or in tray form (same as --to chain-level)",
    )
    p.add_argument("--id", help="level id on import (default: the file name)")
    p.add_argument(
        "--difficulty",
        choices=("easy", "mid", "hard"),
        help="on import (default: from the file name, as CHAIN names them, else easy)",
    )
    p.add_argument(
        "--rules",
        choices=("default", "chain"),
        default="default",
        help="on import: our stacking rules, or CHAIN's game exactly (rules profile 'chain')",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.target is not None:
        if args.out is not None and args.target != args.out:
            raise CommandError("give the file to write once: as TARGET or as --out")
        print(DEPRECATED_TARGET.format(target=args.target), file=sys.stderr)
    else:
        args.target = args.out
    from chaingeo.core.formats.chain_json import write_chain_stacking
    from chaingeo.core.level import level_bytes, save_level

    if args.to in ("chain-json", "xmpuzzle"):
        if args.target is None:
            raise CommandError(f"--to {args.to} needs a target file (--out FILE)")
        level = find_level(args.source)
        if args.to == "xmpuzzle":
            export_xmpuzzle(level, args.target)
        else:
            write_chain_stacking(level, args.target)
        print(args.target)
        return 0
    level = import_chain_file(Path(args.source), args.id, args.difficulty, args.rules)
    if args.target is None:
        sys.stdout.write(level_bytes(level).decode("utf-8"))
        return 0
    save_level(level, args.target)
    print(args.target)
    return 0


def export_xmpuzzle(level: Level, target: Path) -> None:
    """Write ``level`` as a BurrTools file, naming on stderr the rules the file cannot carry."""
    from chaingeo.core.formats.bt_level import level_puzzle, rules_not_carried
    from chaingeo.core.formats.bt_write import write_xmpuzzle

    write_xmpuzzle(level_puzzle(level), target)
    for rule in rules_not_carried(level):
        print(
            f"chain convert: {level.id}: not carried into the BurrTools file: {rule}",
            file=sys.stderr,
        )


def import_chain_file(
    path: Path, level_id: str | None, difficulty: str | None, rules: str = "default"
) -> Level:
    """A verified level from CHAIN's file, packed or in tray form."""
    from chaingeo.core.formats.chain_json import chain_level, load_chain_file
    from chaingeo.core.rules import StackingRules

    spec = load_chain_file(path)
    if difficulty is None:
        m = _DIFFICULTY_RE.search(path.stem.lower())
        difficulty = m.group(1) if m else "easy"
    placements = None if spec.packed else pack(spec, str(path))
    return chain_level(
        spec,
        level_id or path.stem,
        difficulty,
        placements=placements,
        rules=StackingRules(profile="chain" if rules == "chain" else "default"),
        source=str(path),
    )


def pack(spec: ChainStacking, source: str) -> list[Shape]:
    """A packing of the file's pieces into its box (piece ``i`` first at index ``i``)."""
    from chaingeo.core.level import LevelError
    from chaingeo.solvers.cover.packings import CoverError, CoverLimitError, first_packing

    volume = spec.box[0] * spec.box[1] * spec.box[2]
    cubes = sum(len(s) for s in spec.pieces)
    if cubes != volume:
        raise LevelError(source, "pieces", f"{cubes} cubes in all cannot fill a {spec.box} box")
    try:
        solution = first_packing(spec.shapes, spec.box, node_limit=PACK_NODE_LIMIT)
    except CoverLimitError:
        raise LevelError(
            source, "pieces", f"no packing found within {PACK_NODE_LIMIT} search nodes"
        ) from None
    except CoverError as e:
        raise LevelError(source, "pieces", str(e)) from None
    if solution is None:
        raise LevelError(source, "pieces", "the pieces cannot fill the box in any way")
    placed = dict(solution.placements)
    return [placed[str(i)] for i in range(len(spec.pieces))]
