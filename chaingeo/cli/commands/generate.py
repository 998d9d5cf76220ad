"""``chain generate FAMILY``: make levels at scale (joblib locally, or a Dask cluster).

``chain generate stacking --box 3x3x4 --mode hard --count 100 --seed 7 --out DIR --jobs 2``
``chain generate suite [--out levels/stacking]``: rebuild the shipped 77-level stacking suite.
Each family is one subparser; the run options (``--count --seed --out --jobs --dask``...) and
the runner are shared, so a new family only adds how to build its configuration.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any, Final

from chaingeo.cli.errors import CommandError
from chaingeo.cli.out_arg import add_out


def register(sub: Any) -> None:
    p = sub.add_parser(
        "generate", help="generate stacking or puzzle levels, or rebuild a shipped suite"
    )
    fam = p.add_subparsers(dest="family", metavar="FAMILY", required=True)
    _register_stacking(fam)
    _register_suite(fam)
    _register_puzzle(fam)
    _register_puzzle_suite(fam)
    _register_puzzle_counts(fam)


def add_run_options(p: argparse.ArgumentParser, *, count: bool = True) -> None:
    """Options every family shares: how many, which seed, where, on what."""
    if count:
        p.add_argument("--count", type=int, default=10, help="levels to accept")
        p.add_argument("--seed", type=int, default=0, help="item i uses SeedSequence([seed, i])")
        add_out(p, "folder", "the levels (and their pictures)", required=True)
        p.add_argument(
            "--max-items",
            type=int,
            default=None,
            help="most items to try (default: 10 x count, at least 100)",
        )
        p.add_argument("--first-index", type=int, default=0, help="first item index")
        p.add_argument("--no-pictures", action="store_true", help="skip the PNG pictures")
        p.add_argument(
            "--split",
            choices=("any", "train"),
            default="any",
            help="train: skip (and count) every level whose split signature matches a level of "
            "the shipped suite, so training data never holds a test level",
        )
    p.add_argument("--jobs", type=int, default=1, help="local worker processes (joblib)")
    p.add_argument("--dask", metavar="ADDRESS", help="run on the Dask cluster at ADDRESS")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


#: Steps of each family's curriculum (chaingeo.generator.curriculum.CURRICULA, which a test
#: compares): importing the generator to build ``--help`` would load numpy for every command.
CURRICULUM_STEPS: Final = {"stacking": 8, "puzzle": 7}


def add_curriculum_option(p: argparse._ActionsContainer, family: str) -> None:
    """``--curriculum K``: step K of the family's easy-to-hard list
    (chaingeo.generator.curriculum)."""
    p.add_argument(
        "--curriculum",
        type=int,
        metavar="K",
        help=f"difficulty step 0 (easiest) .. {CURRICULUM_STEPS[family] - 1} (hardest) instead "
        "of the shape options; explicit options still override it",
    )


def run_job(args: argparse.Namespace, family: str, make: Any, config: Any) -> int:
    """Run one generation job from parsed options; print the summary as one JSON line."""
    from chaingeo.generator.batch import HELD_OUT, GenerationError, GenerationJob, run
    from chaingeo.generator.signature import shipped_signatures
    from chaingeo.pictures.pictures import level_pictures

    held_out = shipped_signatures() if args.split == "train" else frozenset()
    try:
        job = GenerationJob(
            family,
            make,
            config,
            args.seed,
            args.count,
            max_items=args.max_items,
            first_index=args.first_index,
            pictures=None if args.no_pictures else level_pictures,
            held_out=held_out,
        )
        summary = run(job, args.out, jobs=args.jobs, dask=args.dask, progress=not args.no_progress)
    except GenerationError as e:
        raise CommandError(str(e)) from None
    if args.split == "train":
        skipped = summary.outcomes[HELD_OUT]
        print(f"split train: skipped {skipped} level(s) of the shipped suite", file=sys.stderr)
    print(json.dumps(summary.to_json(), sort_keys=True))
    return 0 if summary.complete else 1


# -- stacking ------------------------------------------------------------------------------------


def _register_stacking(fam: Any) -> None:
    p = fam.add_parser("stacking", help="pack-the-box levels (easy / mid / hard)")
    what = p.add_argument_group(
        "what to generate (required: --box and --mode, or --config, or --curriculum)"
    )
    what.add_argument("--box", help="box size AxBxC, e.g. 3x3x4")
    what.add_argument("--mode", choices=("easy", "mid", "hard"), help="difficulty mode")
    what.add_argument("--config", help="a registered config name instead of --box/--mode")
    add_curriculum_option(what, "stacking")
    p.add_argument("--min-nodes", type=int, help="least exact-cover nodes to a first packing")
    p.add_argument("--max-pieces", type=int, help="most pieces")
    p.add_argument("--min-piece", type=int, help="smallest piece (first stage)")
    p.add_argument("--max-piece-cells", type=int, help="largest piece")
    p.add_argument("--attempts", type=int, help="attempts per item")
    p.add_argument(
        "--no-linear-assembly", action="store_true", help="do not require a linear assembly"
    )
    add_run_options(p)
    p.set_defaults(func=_run_stacking)


def stacking_config_from_args(args: argparse.Namespace) -> Any:
    from chaingeo.generator.config import get_config, parse_box, stacking_config

    overrides: dict[str, Any] = {}
    for opt, fld in (
        ("min_nodes", "min_nodes"),
        ("max_pieces", "max_pieces"),
        ("min_piece", "min_piece"),
        ("max_piece_cells", "max_piece_cells"),
        ("attempts", "attempts"),
    ):
        if getattr(args, opt) is not None:
            overrides[fld] = getattr(args, opt)
    if args.no_linear_assembly:
        overrides["linear_assembly"] = False
    if args.curriculum is not None:
        from chaingeo.generator.curriculum import stacking_step

        if args.config or args.box or args.mode:
            raise CommandError("give either --curriculum or --config or --box/--mode")
        return stacking_step(args.curriculum).replace(**overrides)
    if args.config:
        if args.box or args.mode:
            raise CommandError("give either --config or --box/--mode, not both")
        return get_config(args.config).replace(**overrides)
    box = parse_box(args.box) if args.box else None
    if box is None or not args.mode:
        raise CommandError("--box and --mode are required (or --config NAME)")
    return stacking_config(box, args.mode, **overrides)


def _run_stacking(args: argparse.Namespace) -> int:
    from chaingeo.generator.stacking import make

    return run_job(args, "stacking", make, stacking_config_from_args(args))


# -- the suite -----------------------------------------------------------------------------------


def _register_suite(fam: Any) -> None:
    p = fam.add_parser("suite", help="rebuild the shipped 77-level stacking suite, byte for byte")
    add_out(p, "folder", "the suite's levels", default=Path("levels") / "stacking")
    p.add_argument("--pictures", type=Path, help="also write the pictures into this folder")
    add_run_options(p, count=False)
    p.set_defaults(func=_run_suite)


def _run_suite(args: argparse.Namespace) -> int:
    from chaingeo.generator.suite import build_suite
    from chaingeo.pictures.pictures import level_pictures

    try:
        summaries = build_suite(
            args.out,
            jobs=args.jobs,
            dask=args.dask,
            progress=not args.no_progress,
            pictures=args.pictures,
            picture_maker=level_pictures if args.pictures is not None else None,
        )
    except RuntimeError as e:
        raise CommandError(str(e)) from None
    for s in summaries:
        print(json.dumps(s.to_json() | {"levels": len(s.accepted)}, sort_keys=True))
    print(json.dumps({"suite": str(args.out), "levels": sum(len(s.accepted) for s in summaries)}))
    return 0


# -- puzzles -------------------------------------------------------------------------------------


def _register_puzzle(fam: Any) -> None:
    p = fam.add_parser("puzzle", help="interlocking puzzles (burrs, plate burrs, cubes)")
    p.add_argument(
        "--shape",
        help=(
            "burr3, plate3, burr6, burr6x8 / burr6x8u (Cutler's standard six-piece burr; u: "
            "unique assembly), burr12, burr18, burr24, burr36 (towers; with --max-group 1 "
            "built and proven unit by unit), cubeN or mazeN (maze burr: level grows with N) "
            "(default: burr6)"
        ),
    )
    p.add_argument("--min-level", type=int, help="least moves to free the first part (default: 1)")
    p.add_argument("--pieces", type=int, default=0, help="pieces of a cubeN partition")
    p.add_argument("--hole-rate", type=float, help="chance a shared cell starts empty")
    p.add_argument("--hill-steps", type=int, help="single-voxel improvement steps")
    p.add_argument(
        "--goal",
        choices=("disassemble", "assemble"),
        default="disassemble",
        help="what the levels ask",
    )
    p.add_argument("--max-group", type=int, help="most pieces one move may carry")
    p.add_argument("--seconds", type=float, help="time limit of the optimal-plan search")
    p.add_argument("--restarts", type=int, help="annealing runs (burr6x8; default: 2)")
    p.add_argument(
        "--unique", action="store_true", help="only designs that assemble in one way (burr6x8)"
    )
    add_curriculum_option(p, "puzzle")
    add_run_options(p)
    p.set_defaults(func=_run_puzzle)


def _run_puzzle(args: argparse.Namespace) -> int:
    from chaingeo.generator.config import PuzzleConfig
    from chaingeo.generator.curriculum import PUZZLE_STEPS, puzzle_step
    from chaingeo.generator.puzzle import make

    fields: dict[str, Any] = {"shape": "burr6", "min_level": 1}
    if args.curriculum is not None:
        puzzle_step(args.curriculum)  # checks the range
        fields.update(PUZZLE_STEPS[args.curriculum])
    fields.update(pieces=args.pieces, goal=args.goal, max_group=args.max_group, unique=args.unique)
    for opt in ("shape", "min_level", "hole_rate", "hill_steps", "seconds", "restarts"):
        if getattr(args, opt) is not None:
            fields[opt] = getattr(args, opt)
    return run_job(args, "puzzle", make, PuzzleConfig(**fields))


def _register_puzzle_suite(fam: Any) -> None:
    p = fam.add_parser("puzzle-suite", help="rebuild the shipped 32-level puzzle suite")
    add_out(p, "folder", "the suite's levels", default=Path("levels") / "puzzle")
    p.add_argument("--models", type=Path, required=True,
                   help="CHAIN's puzzle models (e.g. ../shared/chain-models)")  # fmt: skip
    p.add_argument("--jobs", type=int, default=1, help="suite entries built in parallel")
    p.set_defaults(func=_run_puzzle_suite)


def _register_puzzle_counts(fam: Any) -> None:
    p = fam.add_parser(
        "puzzle-counts",
        help="complete assembly and solution counts into the puzzle levels' stats",
    )
    p.add_argument("--levels", type=Path, default=Path("levels") / "puzzle",
                   help="the folder of puzzle levels to count (written back)")  # fmt: skip
    p.add_argument("--only", nargs="+", default=(), metavar="ID", help="count these levels only")
    p.add_argument("--recount", action="store_true", help="count levels that have counts too")
    p.add_argument("--jobs", type=int, default=None,
                   help="worker processes of a count (default: the machine's cores)")  # fmt: skip
    p.add_argument("--scheduler", metavar="ADDRESS", default=None,
                   help="count on the Dask cluster at ADDRESS")  # fmt: skip
    p.set_defaults(func=_run_puzzle_counts)


def _run_puzzle_counts(args: argparse.Namespace) -> int:
    import sys

    from chaingeo.core.errors import ChainGeoError
    from chaingeo.generator.counts import count_folder
    from chaingeo.solvers.jobs import as_farm

    if args.jobs is not None and args.jobs < 1:
        raise CommandError(f"--jobs: expected a positive number of processes, got {args.jobs}")
    try:
        done = count_folder(
            args.levels,
            as_farm(args.jobs, args.scheduler),
            recount=args.recount,
            only=args.only,
            log=lambda s: print(s, file=sys.stderr, flush=True),
        )
    except (ChainGeoError, RuntimeError) as e:
        raise CommandError(str(e)) from None
    print(json.dumps({"levels": str(args.levels), "counted": [lv.id for lv in done]}))
    return 0


def _run_puzzle_suite(args: argparse.Namespace) -> int:
    import sys

    from chaingeo.generator.puzzle_suite import build_puzzle_suite

    try:
        levels = build_puzzle_suite(
            args.out,
            args.models,
            jobs=args.jobs,
            log=lambda s: print(s, file=sys.stderr, flush=True),
        )
    except RuntimeError as e:
        raise CommandError(str(e)) from None
    print(json.dumps({"suite": str(args.out), "levels": len(levels)}))
    return 0
