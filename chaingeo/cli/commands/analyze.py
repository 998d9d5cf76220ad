"""``chain analyze FILE... [--problem N] [--mirrors keep|drop]``: assemblies, solutions, level,
moves and o_i of puzzles (our level files or level ids, BurrTools ``.xmpuzzle`` files), one JSON
line per file, so a designer's batch pays the start-up once. A ``.xmpuzzle`` with several
problems and no ``--problem`` gives ``{"problems": [...], ...}``, one object per problem.

By default the counts are what BurrTools' command-line solver burrTxt prints for the same file:
``--mirrors drop`` identifies an assembly with its mirror image when that is an assembly too
(588 assemblies / 179 solutions on BurrTools' SolidSixPieceBurrs example, 928 / 927 on its
DemoPieceGenerator); ``--mirrors keep`` counts mirror images apart, BurrTools' stored figures
(1063 / 314 there, 1760 / 1759). The JSON names the one used: ``"convention": "burrtxt"`` or
``"mirrors-kept"``.

A file that takes more than a few seconds reports on standard error what it is doing
(:mod:`chaingeo.cli.progress`). ``--seconds`` bounds the whole analysis of one file: the
enumeration of assemblies, every disassembly and the optimal search share one deadline (a spent
optimal search alone is reported as ``optimal_error``).

``--jit auto`` (default) uses the kernels ``chain precompile`` compiled ahead of time when they
match the installed sources (loading them takes milliseconds, starting numba ~0.5 s); a call
they were not compiled for makes the command start again with numba for the files not yet
printed. Without them, a single small file runs with interpreted kernels: starting numba costs
more than the work (:mod:`chaingeo.kernels.jit`); if the work takes more than
:data:`INTERPRETED_SECONDS` of CPU time, the command starts again with numba.

When a cap (``--seconds``, ``--max-states``) stops the counting of assemblies, nothing finished
is thrown away: the line keeps the counts so far with ``"counts_complete": false`` (they are
lower bounds) and ``limit`` naming the cap and its flag, and still gives level, moves and o_i of
the known assembly (the first solution found, a ``.xmpuzzle``'s stored assembly, or a level's
own), which get a further :data:`chaingeo.solvers.analysis.GRACE_SECONDS` at most.

``--jobs N`` (default: the machine's cores) cuts a large count's search into subtrees that N
worker processes enumerate and take apart (:mod:`chaingeo.solvers.assembly.btparallel`), merged
in a fixed order: the same bytes whatever N, in less wall time. ``--scheduler ADDRESS`` sends the
same subtrees to a Dask cluster.

Exit status: 0 when every figure is complete; 1 when counting was cut short by a cap; 2 when
some file failed (its line carries ``error``; the message is also on standard error).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import sys
import time
from collections.abc import Sequence
from dataclasses import replace
from functools import lru_cache
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING, Any, Final

from chaingeo.cli.errors import CommandError
from chaingeo.cli.level_arg import find_level
from chaingeo.cli.progress import ProgressLines

if TYPE_CHECKING:
    from chaingeo.core.formats.burrtools import BTProblem, BTPuzzle
    from chaingeo.core.kinematics import SearchLimitError
    from chaingeo.solvers.figures import PuzzleFigures

#: Work an interpreted run may do before the command starts again with numba (seconds of the
#: process' CPU time, so that a busy machine does not change the choice).
INTERPRETED_SECONDS: Final = 0.15
#: A file is tried interpreted only up to these sizes (pieces, voxels of all pieces).
SMALL_PIECES: Final = 12
SMALL_VOXELS: Final = 160
#: A BurrTools file is tried interpreted up to this many placements of its pieces in its
#: result (:func:`placements_within`): the work grows with them, not with the voxels (Soma in a
#: 3x3x3 box, 27 voxels, has 688; the soma file's 12-piece problem 188 and a 376-voxel maze
#: 278 both overran the interpreted budget and paid a restart; 4 rings on a pin, 56, did not).
SMALL_ROWS: Final = 150
#: ... and up to this many result voxels (bounding the look itself).
SMALL_RESULT_VOXELS: Final = 1000


#: The flags that set the fields of ``SearchLimits`` a search may reach.
LIMIT_FLAGS: Final = {
    "seconds": "--seconds",
    "max_states": "--max-states",
    "optimal_seconds": "--optimal-seconds",
}


def register(sub: Any) -> None:
    p = sub.add_parser(
        "analyze",
        help="assemblies, solutions, level and optimal steps of puzzles (one JSON line each)",
    )
    p.add_argument(
        "files",
        nargs="+",
        metavar="FILE",
        help="chain-level/1 puzzle files, level ids of the shipped suite, or .xmpuzzle files",
    )
    p.add_argument(
        "--problem",
        type=int,
        default=None,
        help="problem index in a .xmpuzzle file (default: every problem)",
    )
    p.add_argument(
        "--mirrors",
        choices=("keep", "drop"),
        default="drop",
        help="drop mirror-image assemblies, as BurrTools' command-line solver burrTxt does "
        "(default; JSON convention 'burrtxt'), or keep them apart, BurrTools' stored counts "
        "(convention 'mirrors-kept')",
    )
    p.add_argument(
        "--seconds",
        type=float,
        default=120.0,
        help="time limit of one file's analysis (assemblies, disassembly and optimal search)",
    )
    p.add_argument(
        "--optimal-seconds",
        type=float,
        default=10.0,
        help="time limit of the search for o_i within a file's analysis (past it o_i is "
        "reported unknown, with the reason; the other figures stand)",
    )
    p.add_argument("--max-states", type=int, default=2_000_000, help="state cap per part")
    p.add_argument(
        "--jobs",
        type=int,
        default=None,
        help="worker processes that search and take apart the assemblies of a large count "
        "(default: the machine's cores); the figures are the same whatever it is",
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        default=None,
        help="count on the Dask cluster at ADDRESS instead of local workers (the cluster "
        "extra); the same figures",
    )
    p.add_argument("--no-optimal", action="store_true", help="skip the optimal-plan search")
    p.add_argument(
        "--no-assemble", action="store_true", help="skip counting assemblies (level only)"
    )
    p.add_argument(
        "--jit",
        choices=("auto", "aot", "numba", "python"),
        default="auto",
        help="kernels compiled ahead of time (chain precompile), by numba, interpreted, or "
        "auto: ahead of time when compiled, else interpreted for one small file, else numba",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    for flag, value in (("--seconds", args.seconds), ("--optimal-seconds", args.optimal_seconds)):
        if not (math.isfinite(value) and value > 0):
            raise CommandError(f"{flag}: expected a positive number of seconds, got {value}")
    if args.max_states < 1:
        raise CommandError(f"--max-states: expected a positive number, got {args.max_states}")
    if args.jobs is not None and args.jobs < 1:
        raise CommandError(f"--jobs: expected a positive number of processes, got {args.jobs}")
    if _ahead_of_time_first(args):
        return _run_ahead_of_time(args)
    if _interpreted_first(args):
        return _run_interpreted(args)
    if args.jit != "auto":
        _set_mode(args.jit)
    return _run_all(args, *_resumed())


def _run_all(args: argparse.Namespace, done: int = 0, status: int = 0) -> int:
    """Analyse the files after the first ``done`` (printed by an earlier start of the command
    whose exit status so far was ``status``), one JSON line each, all within the command's one
    ``--seconds``: a file (or problem) the deadline does not reach is reported as not reached."""
    end = time.monotonic() + args.seconds
    for i, spec in enumerate(args.files):
        if i < done:
            continue
        _printed[:] = [i, status]
        if end - time.monotonic() <= 0:
            print(replace(_not_reached(args), file=str(spec)).to_json(LIMIT_FLAGS), flush=True)
            status = max(status, 1)
            continue
        try:
            figures = analyze_file(spec, args, end)
            status = max(status, _cut_short(spec, figures))
            line = figures.to_json(LIMIT_FLAGS)
        except CommandError as e:
            if len(args.files) == 1:
                raise
            print(f"chain analyze: {spec}: error: {e}", file=sys.stderr)
            line, status = json.dumps({"file": str(spec), "error": str(e)}, sort_keys=True), 2
        print(line, flush=True)
    return status


def _cut_short(spec: str, figures: PuzzleFigures) -> int:
    """Say on stderr which cap cut counting short, naming its flag, and return the exit
    status: 1 when some count is a lower bound, else 0."""
    missed = [r for r in figures.cut_short() if (r.limit or "").startswith("not reached")]
    if missed:
        limit = with_flag(missed[0].limit or "", missed[0].limit_cap)
        print(f"chain analyze: {spec}: {len(missed)} not analysed ({limit})", file=sys.stderr)
    for row in figures.cut_short():
        if row in missed:
            continue
        limit = with_flag(row.limit or "", row.limit_cap)
        print(
            f"chain analyze: {spec}: counting stopped ({limit}); the counts are lower "
            "bounds, the other figures are those of the known assembly",
            file=sys.stderr,
        )
    return 1 if figures.cut_short() else 0


def _not_reached(args: argparse.Namespace, **known: Any) -> PuzzleFigures:
    """The figures of a file or problem the command's deadline did not reach."""
    from chaingeo.solvers.figures import PuzzleFigures

    reason = f"not reached: the command's time limit ({args.seconds:g} s) was spent"
    return PuzzleFigures(counts_complete=False, limit=reason, limit_cap="seconds", **known)


def analyze_file(spec: str, args: argparse.Namespace, end: float | None = None) -> PuzzleFigures:
    """The figures of one file within the command's deadline ``end`` (``time.monotonic``;
    default ``--seconds`` from now); ``CommandError`` for any failure, with the reason. The
    problems of a BurrTools file are analysed one by one, each with the time left."""
    from chaingeo.core.errors import ChainGeoError
    from chaingeo.core.formats.burrtools import BTPuzzle
    from chaingeo.core.kinematics import SearchLimitError
    from chaingeo.kernels.jit import mode
    from chaingeo.solvers.figures import PuzzleFigures

    end = time.monotonic() + args.seconds if end is None else end
    start = time.perf_counter()
    try:
        source = read_puzzle(spec) if Path(spec).suffix == ".xmpuzzle" else find_level(spec)
        if isinstance(source, BTPuzzle) and args.problem is None and len(source.problems) > 1:
            rows = [
                _within(source, k, args, end, spec) or _not_reached(args, problem=k, name=p.name)
                for k, p in enumerate(source.problems)
            ]
            rows = [replace(r, file=None, kernels=None, seconds=None) for r in rows]
            figures = PuzzleFigures(problems=tuple(rows), several=True, kernels=mode())
        else:
            figures = _within(source, args.problem, args, end, spec) or _not_reached(args)
    except SearchLimitError as e:
        raise CommandError(limit_message(e)) from None
    except (ChainGeoError, FileNotFoundError) as e:
        raise CommandError(str(e)) from None
    except (IndexError, RuntimeError, ValueError) as e:
        raise CommandError(str(e)) from None
    return replace(figures, file=str(spec), seconds=round(time.perf_counter() - start, 3))


def _within(
    source: Any, problem: int | None, args: argparse.Namespace, end: float, spec: str
) -> PuzzleFigures | None:
    """``analyze`` of ``source`` (one problem) with the time left before ``end``; None when
    none is left."""
    from chaingeo.solvers.analysis import analyze
    from chaingeo.solvers.deadline import Deadline
    from chaingeo.solvers.limits import SearchLimits

    left = end - time.monotonic()
    if left <= 0:
        return None
    limits = SearchLimits(
        max_states=args.max_states, seconds=left, optimal_seconds=args.optimal_seconds
    )
    deadline = Deadline(limits.seconds, stated=args.seconds)
    with ProgressLines(f"chain analyze: {spec}", deadline.progress):
        figures = analyze(
            source,
            limits=limits,
            problem=problem,
            optimal=not args.no_optimal,
            assemble=not args.no_assemble,
            mirrors=args.mirrors,
            deadline=deadline,
            jobs=args.jobs,
            scheduler=getattr(args, "scheduler", None),
        )
    workers = deadline.progress.workers
    if len(workers) > 1:  # how evenly the workers shared the count (stderr: not the figures)
        cpu = ", ".join(f"{s:.2f}" for s in sorted(workers.values(), reverse=True))
        print(f"chain analyze: {spec}: counting CPU seconds per worker: {cpu}", file=sys.stderr)
    return figures


@lru_cache(maxsize=1)
def read_puzzle(spec: str) -> BTPuzzle:
    """The ``.xmpuzzle`` file read once a process: the look that chooses the kernels and the
    analysis share it (parsing SolidSixPieceBurrs takes 0.03 s)."""
    from chaingeo.core.formats.burrtools import read_xmpuzzle

    return read_xmpuzzle(spec)


def limit_message(e: SearchLimitError) -> str:
    """The limit's reason, naming the flag that raises it (not the Python field)."""
    return with_flag(e.reason, e.cap) if e.cap in LIMIT_FLAGS else str(e)


def with_flag(reason: str, cap: str | None) -> str:
    """``reason`` and the flag that raises cap ``cap`` (a ``SearchLimits`` field), if any."""
    from chaingeo.solvers.figures import with_flag as with_option

    return with_option(reason, cap, LIMIT_FLAGS)


# -- kernels compiled ahead of time ---------------------------------------------------------

#: Set for a command started again after a kernel miss: "files printed:exit status so far".
RESUME_ENV: Final = "CHAINGEO_ANALYZE_RESUMED"
#: [index of the file being analysed, exit status before it] (read when a kernel misses).
_printed: list[int] = [0, 0]


def _resumed() -> tuple[int, int]:
    """Files printed and status so far when this process continues a restarted command."""
    raw = os.environ.pop(RESUME_ENV, "")
    try:
        done, status = (int(x) for x in raw.split(":"))
    except ValueError:
        return 0, 0
    return max(done, 0), min(max(status, 0), 2)


def _ahead_of_time_first(args: argparse.Namespace) -> bool:
    """Whether to use the precompiled kernels: ``--jit aot``, or ``--jit auto`` when they match
    the sources, no mode is forced by ``CHAINGEO_JIT`` and the command can start itself again
    (not a call of ``main``)."""
    from chaingeo.kernels import aot, jit

    if _aot_forced(args):
        return True
    argv = getattr(args, "command_line", None)
    if args.jit != "auto" or argv is None or jit.ENV in os.environ or RESUME_ENV in os.environ:
        return False
    if aot.load() is not None:  # checked once: setting the mode finds it loaded
        return True
    if aot.refused:  # a store is there but fails its checks: one line, then numba
        print(f"chain analyze: precompiled kernels {aot.refused}; using numba", file=sys.stderr)
    return False


def _aot_forced(args: argparse.Namespace) -> bool:
    from chaingeo.kernels.jit import ENV

    return bool(args.jit == "aot" or (args.jit == "auto" and os.environ.get(ENV) == "aot"))


def _run_ahead_of_time(args: argparse.Namespace) -> int:
    """Analyse with the precompiled kernels; on a call they do not cover, start again with
    numba for the files not yet printed (``--jit aot``: report the miss instead)."""
    from chaingeo.kernels.aot import KernelMiss

    _set_mode("aot")
    try:
        return _run_all(args)
    except KernelMiss as miss:
        if _aot_forced(args) or args.command_line is None:
            raise CommandError(f"--jit aot: {miss} (run `chain precompile FILE`)") from None
        done, status = _printed
        _restart_with_numba(args.command_line, done, status)
        raise AssertionError("unreachable") from None  # execve does not return


# -- interpreted kernels for one small file ---------------------------------------------------


class _TooLong(BaseException):
    """The interpreted run's budget is spent (a BaseException: no analysis code catches it)."""


def _set_mode(wanted: str) -> None:
    from chaingeo.kernels.jit import set_mode

    try:
        set_mode("python" if wanted == "python" else "aot" if wanted == "aot" else "numba")
    except RuntimeError as e:  # the process has kernels already (a caller of main())
        raise CommandError(f"--jit {wanted}: {e}") from None


def _interpreted_first(args: argparse.Namespace) -> bool:
    """Whether to try the one file interpreted: ``--jit auto``, one small file, no mode forced
    by ``CHAINGEO_JIT``, and a command line to start again with (not a call of ``main``)."""
    from chaingeo.kernels import jit

    argv = getattr(args, "command_line", None)
    if args.jit != "auto" or len(args.files) != 1 or argv is None or jit.ENV in os.environ:
        return False
    return _small(args.files[0], args.problem)


def _small(spec: str, problem: int | None) -> bool:
    """A cheap look at the file: few pieces and voxels (anything unreadable: not small, and the
    real run says why)."""
    try:
        if Path(spec).suffix == ".xmpuzzle":
            puzzle = read_puzzle(spec)
            problems = (
                puzzle.problems if problem is None else puzzle.problems[problem : problem + 1]
            )
            pieces = sum(p.max for prob in problems for p in prob.parts)
            voxels = sum(len(puzzle.shapes[prob.result].cells) for prob in problems)
            return (
                0 < pieces <= SMALL_PIECES
                and voxels <= SMALL_RESULT_VOXELS
                and placements_within(puzzle, problems, SMALL_ROWS)
            )
        else:
            level = find_level(spec)
            pieces = len(level.pieces)
            voxels = sum(len(p.shape) for p in level.pieces)
    except Exception:  # a look only: the analysis itself reports what is wrong
        return False
    return 0 < pieces <= SMALL_PIECES and voxels <= SMALL_VOXELS


def placements_within(puzzle: BTPuzzle, problems: Sequence[BTProblem], limit: int) -> bool:
    """Whether the problems' parts have at most ``limit`` placements in their results (every
    orientation and offset that lies in the result's voxels; colours not checked, so this is
    an upper bound on the assembler's rows). Plain numpy: no kernel is loaded before the
    interpreted mode is chosen."""
    from chaingeo.solvers.cover.placements import placements

    count = 0
    for prob in problems:
        result = puzzle.shapes[prob.result].cells
        for part in prob.parts:
            count += len(placements(puzzle.shapes[part.shape].cells, result).cells)
            if count > limit:
                return False
    return True


def _run_interpreted(args: argparse.Namespace) -> int:
    """Analyse interpreted within :data:`INTERPRETED_SECONDS`, else start again with numba
    (nothing has been printed by then)."""

    def expire(signum: int, frame: FrameType | None) -> None:
        raise _TooLong

    _set_mode("python")
    import chaingeo.solvers.analysis  # noqa: F401 - imports are start-up, not the work the budget bounds

    previous = signal.signal(signal.SIGPROF, expire)
    signal.setitimer(signal.ITIMER_PROF, INTERPRETED_SECONDS)
    try:
        figures = analyze_file(args.files[0], args)
        signal.setitimer(signal.ITIMER_PROF, 0)
    except _TooLong:
        _restart_with_numba(args.command_line)
    finally:
        signal.signal(signal.SIGPROF, previous)
    status = _cut_short(args.files[0], figures)
    print(figures.to_json(LIMIT_FLAGS), flush=True)
    return status


def _restart_with_numba(argv: list[str], done: int = 0, status: int = 0) -> None:
    """Start the command again with numba's kernels, skipping the ``done`` files printed."""
    from chaingeo.kernels.jit import ENV

    env = dict(os.environ, **{ENV: "numba", RESUME_ENV: f"{done}:{status}"})
    sys.stdout.flush()
    os.execve(sys.executable, [sys.executable, "-m", "chaingeo.cli.main", *argv], env)
