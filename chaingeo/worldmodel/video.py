"""Videos of plans: a level's optimal plan (or any legal plan) as continuous motion.

One fixed camera (the iso view of a frame that holds every position of the plan); slides are
eased over a few frames, quarter turns rotate through their 90 degrees about the turn's axis
(:mod:`chaingeo.core.turns`), a group that leaves the puzzle is carried out of the picture and
stays gone, and each frame's title is the current step. An assembly plan is shown as the
disassembly that undoes it, played backwards. Stacking pieces wait in a row beside the box and
are carried in one by one: up, over the box, down into place. Every step's end pose of a puzzle
is checked against the reference kinematics, so what the video shows is what the engine does.

Frames are drawn by :func:`chaingeo.pictures.scene.render_frame`: the same level and plan give
the same pixels; at a step's end the frame is the still picture of that position. GIF is written by
Pillow; MP4 needs the optional extra ``video`` (imageio with its own ffmpeg).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Final

import numpy as np
from PIL import Image

from chaingeo.core.arrays import F64
from chaingeo.core.errors import ChainGeoError
from chaingeo.core.geometry import Cell, Shape
from chaingeo.core.kinematics import (
    DIRECTIONS,
    Assembly,
    Move,
    MoveError,
    disassembly_of_assembly_plan,
)
from chaingeo.core.level import Level, PuzzleSolution, StackingSolution
from chaingeo.core.turns import AXES, TurnMove
from chaingeo.envs.actions.types import action_of_move
from chaingeo.pictures.raster import RGB, Posed, parse_color
from chaingeo.pictures.scene import render_frame

PuzzleStep = Move | TurnMove
#: Frames per kind of step (a slide, a turn, a group carried out, a piece lowered), and the
#: frames a position is held at the start, after each step and at the end.
SLIDE_FRAMES: Final = 8
TURN_FRAMES: Final = 12
OUT_FRAMES: Final = 10
DROP_FRAMES: Final = 8
LIFT_FRAMES: Final = 4
STEP_HOLD: Final = 2
END_HOLD: Final = 6
FPS: Final = 10  # 100 ms a frame: GIF counts time in hundredths of a second
VIDEO_SIZE: Final = 384  # a multiple of 16, as H.264 wants


class VideoError(ChainGeoError, ValueError):
    """A plan that cannot be shown (illegal for the level, or the wrong family), or a format
    that cannot be written here; the message says which and why."""


@dataclass(frozen=True)
class PlanVideo:
    """The frames of a plan, their captions (one per frame), the fixed world frame the camera
    shows (``lo``, ``hi``: cell corners) and the frame rate."""

    frames: tuple[Image.Image, ...]
    captions: tuple[str, ...]
    frame: tuple[Cell, Cell]
    fps: int = FPS


#: One picture's content: every visible piece's name and pose (rotation, translation).
_Pose = tuple[F64, F64]
_Shot = tuple[tuple[str, F64, F64], ...]


def _ease(i: int, n: int) -> float:
    """Smooth start and stop: 0 at i = 0, 1 at i = n."""
    return (1.0 - math.cos(math.pi * i / n)) / 2.0


def _turn_matrix(axis: int, angle: float) -> F64:
    """Right-handed rotation by ``angle`` radians about coordinate axis ``axis``."""
    c, s = math.cos(angle), math.sin(angle)
    u, v = (axis + 1) % 3, (axis + 2) % 3
    m = np.eye(3)
    m[u, u], m[u, v], m[v, u], m[v, v] = c, -s, s, c
    return m


def _cells(shape: Shape, pose: _Pose) -> frozenset[Cell]:
    rot, t = pose
    centres = (shape.voxels + 0.5) @ rot.T + t - 0.5
    return frozenset((int(x), int(y), int(z)) for x, y, z in np.rint(centres).tolist())


class _Timeline:
    """Poses of every piece over a disassembly, one list of shots per step (both end poses
    included), kept equal to the reference kinematics at every step's end."""

    def __init__(self, level: Level) -> None:
        self.shapes = level.shapes
        self.poses: dict[str, _Pose] = {n: (np.eye(3), np.zeros(3)) for n in self.shapes}
        self.gone: set[str] = set()
        self.engine = Assembly.assembled(self.shapes, level.rods)
        self.lo = np.full(3, np.iinfo(np.int64).max)
        self.hi = np.full(3, np.iinfo(np.int64).min)
        self._grow()
        every = np.concatenate([s.voxels for s in self.shapes.values()])
        self.away = 3.0 * float(np.ptp(every, axis=0).max() + 1) + 4.0

    def shot(self, moving: Sequence[str] = (), extra: _Pose | None = None) -> _Shot:
        """The visible pieces, ``moving`` ones under the extra motion ``extra``."""
        out = []
        for n in sorted(self.poses):
            if n in self.gone:
                continue
            rot, t = self.poses[n]
            if extra is not None and n in moving:
                rot, t = extra[0] @ rot, extra[0] @ t + extra[1]
            out.append((n, rot, t))
        return tuple(out)

    def _grow(self) -> None:
        for n, pose in self.poses.items():
            if n not in self.gone:
                cells = np.array(sorted(_cells(self.shapes[n], pose)))
                self.lo = np.minimum(self.lo, cells.min(axis=0))
                self.hi = np.maximum(self.hi, cells.max(axis=0) + 1)

    def step(self, move: PuzzleStep) -> list[_Shot]:
        try:
            removes = self.engine.removes(move) if isinstance(move, Move) else False
            after = self.engine.apply(move)
        except MoveError as e:
            raise VideoError(f"the plan's step {action_of_move(move).to_text()!r}: {e}") from e
        group = [n for n in move.pieces if n not in self.gone]
        shots: list[_Shot] = []
        if isinstance(move, TurnMove):
            a = AXES.index(move.axis)
            pivot = np.array(move.centre2, dtype=np.float64) / 2.0 + 0.5
            for i in range(TURN_FRAMES + 1):
                r = _turn_matrix(a, move.quarter * math.pi / 2 * _ease(i, TURN_FRAMES))
                shots.append(self.shot(group, (r, pivot - r @ pivot)))
            q = move.matrix().astype(np.float64)
            assert np.abs(q - _turn_matrix(a, move.quarter * math.pi / 2)).max() < 1e-12
            for n in move.pieces:
                rot, t = self.poses[n]
                self.poses[n] = (q @ rot, np.rint(q @ (t - pivot) + pivot))
        else:
            d = np.array(DIRECTIONS[move.direction], dtype=np.float64)
            frames = OUT_FRAMES if removes else SLIDE_FRAMES
            far = self.away if removes else float(move.distance or 0)
            for i in range(frames + 1):
                shots.append(self.shot(group, (np.eye(3), d * far * _ease(i, frames))))
            if removes:
                self.gone.update(move.pieces)
            else:
                for n in move.pieces:
                    rot, t = self.poses[n]
                    self.poses[n] = (rot, t + d * far)
        self.engine = after
        for n in self.shapes:
            if _cells(self.shapes[n], self.poses[n]) != after.cells_of(n):
                raise VideoError(f"internal: the video's {n} left the engine's position")
        shots[-1] = self.shot()
        self._grow()
        return shots


def _captioned(
    level: Level,
    segments: list[list[_Shot]],
    texts: list[str],
    ends: tuple[_Shot, _Shot],
    reached: bool,
) -> tuple[list[_Shot], list[str]]:
    start, end = ends
    n = len(texts)
    shots = [start] * END_HOLD
    # no step count: the first frame is also the reference image a video model is given
    captions = [f"start: {_start_words(level)}"] * END_HOLD
    for i, (seg, text) in enumerate(zip(segments, texts, strict=True)):
        body = seg[1:] + [seg[-1]] * STEP_HOLD
        shots += body
        captions += [f"step {i + 1}/{n}: {text}"] * len(body)
    shots += [end] * END_HOLD
    last = f"done: {_goal_words(level)}" if reached else "end of the plan (goal not reached)"
    captions += [last] * END_HOLD
    return shots, captions


def _start_words(level: Level) -> str:
    if level.family == "stacking":
        return "the box empty"
    return "assembled" if level.goal == "disassemble" else "the pieces apart"


def _goal_words(level: Level) -> str:
    if level.family == "stacking":
        return "the box full"
    return "every piece apart" if level.goal == "disassemble" else "assembled"


def _puzzle_shots(
    level: Level, moves: Sequence[PuzzleStep]
) -> tuple[list[_Shot], list[str], tuple[Cell, Cell]]:
    plan = list(moves) if level.goal == "disassemble" else disassembly_of_assembly_plan(moves)
    line = _Timeline(level)
    first = line.shot()
    segments = [line.step(m) for m in plan]
    last = line.shot()
    texts = [action_of_move(m).to_text() for m in moves]
    reached = line.engine.is_separated()
    if level.goal == "assemble":  # the disassembly backwards: last step first, each reversed
        segments = [seg[::-1] for seg in reversed(segments)]
        first, last = last, first
        reached = True  # read_plan refuses an assembly plan that does not assemble
    lo = tuple(int(v) for v in line.lo)
    hi = tuple(int(v) for v in line.hi)
    shots, captions = _captioned(level, segments, texts, (first, last), reached)
    return shots, captions, ((lo[0], lo[1], lo[2]), (hi[0], hi[1], hi[2]))


def _free_way(cells: Shape, filled: set[Cell], box: Cell) -> tuple[Cell, int] | None:
    """The last leg into place: straight down (the first way whose path no placed cell
    blocks), else in from the -x, -y or +y side of the box at the piece's own height (the
    waiting row lies on the +x side); (direction, length of the leg, 0 for down), or None."""
    own = cells.cell_set
    ways: tuple[Cell, ...] = ((0, 0, -1), (1, 0, 0), (0, 1, 0), (0, -1, 0))
    for d in ways:
        axis = next(i for i in range(3) if d[i])
        reach = box[axis] + 1 if d[2] == 0 else 0
        back = reach if reach else box[2] + 1
        if all(
            tuple(c[i] - d[i] * j for i in range(3)) not in filled
            for c in own
            for j in range(1, back + 1)
        ):
            return d, reach
    return None


def _approach(cells: Shape, filled: set[Cell], box: Cell | None) -> tuple[Cell, int]:
    """:func:`_free_way`, or straight down when every way is blocked (the piece is then
    shown passing through placed ones, and a trajectory checker says so)."""
    assert box is not None
    return _free_way(cells, filled, box) or ((0, 0, -1), 0)


#: Placing orders tried by :func:`carried_order` before it keeps the level's own.
ORDER_SEARCH_NODES: Final = 20_000


def carried_order(level: Level) -> list[tuple[str, Shape]]:
    """The level's solution in a placing order that its state machine accepts and in which
    every piece has a free way in (:func:`_free_way`), found by a depth-first search over
    orders (the level's own order first); the level's own order when none is found in
    :data:`ORDER_SEARCH_NODES` steps."""
    from chaingeo.envs.actions.types import ActionError, PlaceAction
    from chaingeo.envs.machines import new_state

    assert isinstance(level.solution, StackingSolution) and level.box is not None
    sol, box = level.solution, level.box
    own = [(n, sol.placements[n]) for n in sol.order]
    state = new_state(level)
    budget = [ORDER_SEARCH_NODES]

    dead: set[frozenset[str]] = set()  # placed sets known to lead nowhere (the rest depends
    # only on which pieces are in: the cells are fixed)

    def search(done: list[tuple[str, Shape]], filled: set[Cell]) -> bool:
        if len(done) == len(own):
            return True
        key = frozenset(n for n, _ in done)
        if key in dead:
            return False
        for name, cells in own:
            if budget[0] <= 0:
                return False
            if any(name == n for n, _ in done) or _free_way(cells, filled, box) is None:
                continue
            budget[0] -= 1
            try:
                state.apply(PlaceAction(name, tuple(cells.cells)))
            except ActionError:
                continue
            done.append((name, cells))
            if search(done, filled | cells.cell_set):
                return True
            done.pop()
            state.pop()
        if budget[0] > 0:
            dead.add(key)
        return False

    found: list[tuple[str, Shape]] = []
    return found if search(found, set()) else own


def _stacking_shots(
    level: Level, order: Sequence[tuple[str, Shape]]
) -> tuple[list[_Shot], list[str], tuple[Cell, Cell]]:
    """The pieces wait on the floor in a row beside the box (+x), already turned as they will
    lie, in placing order; each in turn rises above everything, travels over the box (along x,
    then y) and is lowered into place (nothing appears from nowhere or passes through a piece)."""
    assert level.box is not None
    bx, by, bz = level.box
    eye = np.eye(3)
    # a grid beside the box: about sqrt(n) pieces a row along +x, rows one behind another
    placed = {n for n, _ in order}
    rest = [(p.name, p.shape) for p in level.pieces if p.name not in placed]  # stay waiting
    per_row = max(1, math.ceil(math.sqrt(len(order) + len(rest))))
    waiting: dict[str, F64] = {}
    x, y, row_depth, width = bx + 1, 0, 0, bx
    for i, (name, cells) in enumerate([*order, *rest]):
        if i and i % per_row == 0:
            x, y, row_depth = bx + 1, y + row_depth + 1, 0
        lo = cells.min_corner
        waiting[name] = np.array([x - lo[0], y - lo[1], -lo[2]], dtype=np.float64)
        x += cells.extent[0] + 1
        row_depth = max(row_depth, cells.extent[1])
        width = max(width, x - 1)
    tallest = max((s.extent[2] for _, s in [*order, *rest]), default=0)
    clear = max(bz, tallest) + 1  # the height a carried piece's bottom rises to
    at: dict[str, F64] = dict(waiting)
    segments: list[list[_Shot]] = []

    def shot() -> _Shot:
        return tuple((n, eye, at[n]) for n in sorted(at))

    filled: set[Cell] = set()
    low, high = np.zeros(3, dtype=np.int64), np.zeros(3, dtype=np.int64)  # sides entered from
    for name, cells in order:
        start = waiting[name]
        lift = np.array([start[0], start[1], clear - cells.min_corner[2]], dtype=np.float64)
        d, back = _approach(cells, filled, level.box)
        entry = np.array([-back * d[0], -back * d[1], 0.0])  # where the last leg starts
        low = np.minimum(low, entry.astype(np.int64) + cells.min_corner)
        high = np.maximum(high, entry.astype(np.int64) + cells.max_corner + 1)
        path = [
            start,
            lift,
            np.array([entry[0], lift[1], lift[2]]),  # along x, then y: axis-aligned slides
            np.array([entry[0], entry[1], lift[2]]),
            entry,
            np.zeros(3),
        ]
        seg = [shot()]
        for a, b in itertools.pairwise(path):
            if np.array_equal(a, b):
                continue
            frames = LIFT_FRAMES if a is start else DROP_FRAMES
            for i in range(1, frames + 1):
                at[name] = a + (b - a) * _ease(i, frames)
                seg.append(shot())
        at[name] = np.zeros(3)
        seg[-1] = shot()
        segments.append(seg)
        filled |= cells.cell_set
    texts = [f"place {name}" for name, _ in order]
    full = len(order) == len(level.pieces)
    first = tuple((n, eye, waiting[n]) for n in sorted(waiting))
    shots, captions = _captioned(level, segments, texts, (first, shot()), full)
    depth = max(by, y + row_depth, int(high[1]))
    return shots, captions, ((int(low[0]), int(low[1]), 0), (width, depth, clear + tallest))


def _draw(
    level: Level,
    shapes: dict[str, Shape],
    shots: list[_Shot],
    captions: list[str],
    frame: tuple[Cell, Cell],
    size: int,
) -> tuple[Image.Image, ...]:
    colors: dict[str, RGB] = {p.name: parse_color(p.rgb) for p in level.pieces}
    legend = [(n, colors[n]) for n in sorted(colors)]
    out = []
    for shot, caption in zip(shots, captions, strict=True):
        parts = [Posed(shapes[n].voxels, colors[n], rot, t) for n, rot, t in shot]
        out.append(render_frame(parts, legend, frame, "iso", size, caption, level.box))
    return tuple(out)


def read_plan(level: Level, text: str) -> tuple[list[PuzzleStep], list[tuple[str, Shape]]]:
    """(moves, placements): a plan written as an agent would type it, one action a line
    (blank lines and lines starting with ``#`` skipped, ``finish`` ends it), checked by the
    level's state machine: moves and turns for a puzzle, (piece, cells) placements for
    stacking. An assembly plan must assemble (the video plays its undoing backwards); a
    stacking plan may not pick up."""
    from chaingeo.envs.actions.parse import parse_action
    from chaingeo.envs.actions.types import (
        ActionError,
        FinishAction,
        MoveAction,
        PlaceAction,
        StateAction,
        TurnAction,
    )
    from chaingeo.envs.machines import new_state

    state = new_state(level)
    moves: list[PuzzleStep] = []
    places: list[tuple[str, Shape]] = []
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        try:
            action = parse_action(line, state)
        except ActionError as e:
            raise VideoError(f"plan line {number} ({line!r}): {e}") from None
        if isinstance(action, FinishAction):
            break
        if isinstance(action, StateAction):
            continue
        if isinstance(action, MoveAction):
            moves.append(action.move)
        elif isinstance(action, TurnAction):
            moves.append(action.turn)
        elif isinstance(action, PlaceAction):
            places.append((action.piece, Shape(action.cells)))
        else:
            raise VideoError(f"plan line {number} ({line!r}): a video shows no pickups")
        state.apply(action)
    if level.goal == "assemble" and not state.is_success():
        raise VideoError("an assembly plan must assemble the puzzle (it is shown undone backwards)")
    return moves, places


def puzzle_video(
    level: Level, moves: Sequence[PuzzleStep] | None = None, size: int = VIDEO_SIZE
) -> PlanVideo:
    """The video of a puzzle plan: its moves and turns (an assembly plan for an assembly
    level); None: the level's own optimal plan."""
    if not isinstance(level.solution, PuzzleSolution):
        raise VideoError(f"{level.id} is a {level.family} level, not a puzzle")
    plan = list(level.solution.moves) if moves is None else list(moves)
    shots, captions, frame = _puzzle_shots(level, plan)
    return PlanVideo(
        _draw(level, level.shapes, shots, captions, frame, size), tuple(captions), frame
    )


def stacking_video(
    level: Level, order: Sequence[tuple[str, Shape]] | None = None, size: int = VIDEO_SIZE
) -> PlanVideo:
    """The video of a stacking plan: (piece, the cells it fills) in placing order; None: the
    level's own solution in an order where each piece can be carried in
    (:func:`carried_order`)."""
    if not isinstance(level.solution, StackingSolution):
        raise VideoError(f"{level.id} is a {level.family} level, not a stacking level")
    plan = carried_order(level) if order is None else list(order)
    shots, captions, frame = _stacking_shots(level, plan)
    shapes = {**level.shapes, **dict(plan)}  # pieces never placed wait as given
    return PlanVideo(_draw(level, shapes, shots, captions, frame, size), tuple(captions), frame)


def plan_video(level: Level, plan_text: str | None = None, size: int = VIDEO_SIZE) -> PlanVideo:
    """The video of a plan written as text (:func:`read_plan`), or of the level's own optimal
    plan (None), whatever the level's family."""
    moves, places = (None, None) if plan_text is None else read_plan(level, plan_text)
    if isinstance(level.solution, PuzzleSolution):
        return puzzle_video(level, moves, size)
    return stacking_video(level, places, size)


# ---------------------------------------------------------------------------------------------
# Files
# ---------------------------------------------------------------------------------------------


def write_gif(video: PlanVideo, path: Path) -> Path:
    """An endlessly looping GIF (Pillow). Pillow stores a run of identical frames once, with
    their durations added, so a reader counts runs, and the total time is kept."""
    first, *rest = video.frames
    first.save(
        path,
        format="GIF",
        save_all=True,
        append_images=rest,
        duration=round(1000 / video.fps),
        loop=0,
        optimize=False,
    )
    return path


def mp4_available() -> bool:
    """Whether the optional extra ``video`` (imageio with its bundled ffmpeg) is installed."""
    try:
        import imageio.v2  # noqa: F401
        import imageio_ffmpeg  # noqa: F401
    except ImportError:
        return False
    return True


def write_mp4(video: PlanVideo, path: Path) -> Path:
    """An H.264 MP4 (yuv420p, so every player shows it) through imageio's ffmpeg, one thread
    and bit-exact flags so that the same frames give the same bytes."""
    if not mp4_available():
        raise VideoError(
            "MP4 needs the optional extra 'video' (pip install 'chaingeo[video]'); "
            "write a .gif instead"
        )
    import imageio.v2 as imageio

    writer = imageio.get_writer(
        str(path),
        format="FFMPEG",
        fps=video.fps,
        codec="libx264",
        macro_block_size=16,
        ffmpeg_log_level="error",
        output_params=[
            "-pix_fmt",
            "yuv420p",
            "-threads",
            "1",
            "-map_metadata",
            "-1",
            "-fflags",
            "+bitexact",
            "-flags:v",
            "+bitexact",
        ],
    )
    try:
        for image in video.frames:
            writer.append_data(np.asarray(image))
    finally:
        writer.close()
    return path


def write_video(video: PlanVideo, path: Path) -> Path:
    """``.gif`` or ``.mp4``, by the file's suffix, written to a temporary name, checked whole
    (:func:`written_whole`) and renamed into place: a full disk leaves no file, never an
    unreadable one reported as written."""
    from chaingeo.core.files import atomic_path

    suffix = path.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise VideoError(f"unknown video format {path.suffix!r}: use .mp4 or .gif")
    with atomic_path(path, durable=True) as tmp:
        try:
            (write_gif if suffix == ".gif" else write_mp4)(video, tmp)
        except OSError as e:  # ffmpeg's broken pipe on a full disk hides the real cause
            raise VideoError(f"{path}: could not be written ({e.strerror or e})") from None
        if not written_whole(tmp):
            raise VideoError(f"{path}: the video could not be written whole (is the disk full?)")
    return path


def written_whole(path: Path) -> bool:
    """Whether a GIF ends with its trailer, or an MP4's top-level boxes span the file exactly
    and hold the movie header (``moov``) and the data (``mdat``): what a writer stopped by a
    full disk does not leave."""
    data = path.read_bytes()
    if path.suffix.lower() == ".gif":
        return data[:6] in (b"GIF87a", b"GIF89a") and data.endswith(b";")
    at, kinds = 0, set()
    while at + 8 <= len(data):
        size, kind = int.from_bytes(data[at : at + 4], "big"), data[at + 4 : at + 8]
        if size == 1 and at + 16 <= len(data):
            size = int.from_bytes(data[at + 8 : at + 16], "big")
        if size < 8:
            return False
        kinds.add(kind)
        at += size
    return at == len(data) and {b"moov", b"mdat"} <= kinds
