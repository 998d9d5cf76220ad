"""What an agent is shown each turn: the task, the pieces, recent turns, the budget, pictures.

Text follows the agent convention: cells are 1-based (converted by
:mod:`chaingeo.envs.actions.types`). The pictures come from :mod:`chaingeo.pictures.scene`,
called from :func:`render_state` only. Stacking shows the box (placed pieces where they are) and the
tray of unplaced pieces; a puzzle shows its largest part where it is and every other part laid out
beside it along +x (parts apart never interact, so only their shapes matter), and its goal as
``target``: assembled (assembly) or every piece apart (disassembly).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Final

from chaingeo.core.geometry import Cell, Shape
from chaingeo.core.rules import PuzzleRules, StackingRules
from chaingeo.envs.actions.types import cells_text
from chaingeo.envs.machines import text_state
from chaingeo.envs.machines.state import BaseState

if TYPE_CHECKING:  # pictures are drawn only when asked for
    from PIL import Image

    from chaingeo.envs.machines.puzzle import PuzzleState

#: The views rendered for every state (the tray and the target are added where they apply).
VIEWS: Final[tuple[str, ...]] = ("front", "side", "top", "iso")
DEFAULT_HISTORY: Final = 5
DEFAULT_IMAGE_SIZE: Final = 512
_LAYOUT_GAP: Final = 2


@dataclass(frozen=True)
class Observation:
    """One turn's observation. ``color_table`` maps colour name -> description; ``history``
    holds one line per recent turn; ``images`` maps a view name to PNG bytes."""

    instruction: str
    color_table: dict[str, str]
    history: list[str]
    steps_left: int
    text_state: str | None = None
    images: dict[str, bytes] = field(default_factory=dict)

    def to_text(self, views: Sequence[str] | None = None) -> str:
        """Everything but the pictures, as one prompt text. ``views`` names the pictures shown
        beside it when they are not in ``images`` (the Gymnasium environments draw them as
        arrays); by default the names of ``images``."""
        shown = list(self.images) if views is None else list(views)
        parts = [
            self.instruction,
            "Pieces:\n" + "\n".join(f"  {k}: {v}" for k, v in self.color_table.items()),
        ]
        if self.history:
            parts.append("Recent turns:\n" + "\n".join(f"  {h}" for h in self.history))
        if self.text_state:
            parts.append("Current state:\n" + self.text_state)
        parts.append(f"Steps left: {self.steps_left}")
        if shown:
            parts.append("Views: " + ", ".join(shown))
        return "\n\n".join(parts)


# ---------------------------------------------------------------------------------------------
# Instruction
# ---------------------------------------------------------------------------------------------

_COORDS = (
    "Cells are written (x,y,z) and counted from 1; z points up. The pictures label the axes and "
    "the cell numbers."
)


def instruction(state: BaseState) -> str:
    """The task, its rules and the action grammar, for this level."""
    level = state.level
    if level.family == "stacking":
        assert level.box is not None and isinstance(level.rules, StackingRules)
        a, b, c = level.box
        drop = (
            " It must also be lowerable straight down into place: no piece may already be above "
            "any of its cells."
            if level.rules.support == "drop"
            else ""
        )
        chain = level.rules.profile == "chain"
        pickup = (
            "  pickup COLOUR  take a placed piece back to the tray\n"
            if chain
            else "  pickup COLOUR  take a placed piece back to the tray (it may not leave "
            "another piece floating)\n"
        )
        return (
            f"Pack all {len(level.pieces)} pieces into the {a}x{b}x{c} box so that it is "
            f"completely full. {_COORDS} The box spans x 1-{a}, y 1-{b}, z 1-{c}. The pieces "
            "start in the tray, shown in the orientation they are handed out; you may place a "
            "piece in any rotation. A placed piece must lie inside the box, overlap no other "
            f"piece, and rest on the floor (z=1) or touch another piece face to face.{drop} "
            "Actions, one per turn:\n"
            "  place COLOUR (x,y,z) (x,y,z) ...  list every cell the piece will fill, e.g. "
            "place red (1,1,1) (2,1,1) (1,2,1)\n"
            f"{pickup}"
            + (_CHAIN_ACTIONS if chain else "")
            + "  finish  end the game when you are done\n"
            "Every turn costs one step, including a turn whose action fails."
        )
    assert isinstance(level.rules, PuzzleRules)
    mg = level.rules.max_group
    group_rule = f" A move may carry at most {mg} piece(s)." if mg is not None else ""
    moves = (
        "A move slides a group of pieces that hold together along one axis, by a number of "
        "units or out to infinity; it is legal only if no unit step on the way collides with "
        f"another piece. Every move is one step, whatever its distance.{group_rule} "
        f"{_COORDS}\n"
    )
    turns = (
        "  rotate GROUP AXIS ANGLE about (x,y,z)  turn a group of one part a quarter turn, "
        "e.g. rotate red z +90 about (2,3,1): AXIS is x, y or z, ANGLE +90 or -90 (right hand "
        "about the positive axis), and the turn is about the line parallel to AXIS through the "
        "point given in cell units (a cell's own coordinates for its centre, .5 for the corner "
        "between cells; the coordinate along AXIS does not matter; it must lie within the "
        "group's bounding box). Legal only if the turning group sweeps through no other piece; "
        "one step. Leave out 'about' and the engine takes the only centre that works, or asks.\n"
        if level.rules.turns
        else ""
    )
    rods = level.rods if level.rules.turns else {}
    if rods:
        turns += (
            "  Round rods (cells of the assembled puzzle; a rod spins in place about its axis): "
            + (
                "; ".join(
                    f"{n} {cells_text(sorted(c for c, b in r.items() if b == a))} along {'xyz'[a]}"
                    for n, r in sorted(rods.items())
                    for a in sorted(set(r.values()))
                )
                + ".\n"
            )
        )
    if level.goal == "disassemble":
        return (
            "Take the interlocking puzzle apart until every piece stands alone. "
            + moves
            + "Actions, one per turn:\n"
            "  move GROUP DIRECTION DISTANCE  e.g. move red +x 2, move red+blue -z inf "
            "(GROUP joins colour names with +; DIRECTION is one of +x -x +y -y +z -z; inf takes "
            "the group out of the puzzle)\n" + turns + "  finish  end the game when you are done\n"
            "Every turn costs one step, including a turn whose action fails."
        )
    return (
        "Put the interlocking puzzle together: bring every piece into the target shape (the "
        "target view; the text state lists its cells). The pieces start apart. " + moves + ""
        "Actions, one per turn:\n"
        "  move GROUP DIRECTION inf  insert a whole part: it travels along DIRECTION from far "
        "away and joins another part, e.g. move red +x inf. Add 'into COLOUR' to say which part "
        "it joins and 'offset (dx,dy,dz)' to say where it lands, as a displacement from its place "
        "in the target ((0,0,0) is exactly there); left out, the engine takes the only fit, or "
        "the target place, or asks you to choose.\n"
        "  move GROUP DIRECTION DISTANCE  slide pieces within a part, e.g. move red -x 2\n"
        + turns
        + "  finish  end the game when you are done\n"
        "Nothing leaves a part once it has joined. Every turn costs one step, including a turn "
        "whose action fails."
    )


_CHAIN_ACTIONS = (
    "  state  show every piece's cells (changes nothing)\n"
    "A piece may also be named by its CHAIN id (place 2 (1,1,1) ...), and an action may be "
    'a CHAIN tool call: {"tool": "place", "piece_id": "2", "cells": [[1,1,1], [2,1,1]]}, '
    '{"tool": "pickup", "piece_id": "2"}, {"tool": "state"}, {"tool": "finish"}. A refused '
    "action is reported with CHAIN's error name.\n"
)


def color_table(state: BaseState) -> dict[str, str]:
    """Colour name -> its hex colour and size (and CHAIN's id), in the level's piece order."""
    return {
        p.name: f"{p.rgb}, {len(p.shape)} cube{'s' if len(p.shape) != 1 else ''}"
        + ("" if p.chain_id is None else f", CHAIN id {p.chain_id}")
        for p in state.level.pieces
    }


def history_lines(state: BaseState, window: int = DEFAULT_HISTORY) -> list[str]:
    turns = state.history[-window:] if window > 0 else []
    return [f"step {t.step}: {t.text.strip()} -> {t.feedback}" for t in turns]


# ---------------------------------------------------------------------------------------------
# Text state (for text-only ablations and the terminal)
# ---------------------------------------------------------------------------------------------


def state_text(state: BaseState) -> str:
    """Every piece's cells (1-based): where it is, or its shape in the tray."""
    return text_state.state_text(state)


def ordered_parts(state: BaseState) -> list[frozenset[str]]:
    """A puzzle's parts, largest first (then by name)."""
    from chaingeo.envs.machines.puzzle import PuzzleState

    assert isinstance(state, PuzzleState)
    return text_state.ordered_parts(state)


# ---------------------------------------------------------------------------------------------
# Pictures: the one place that calls the renderer
# ---------------------------------------------------------------------------------------------

PieceMap = dict[str, tuple[Shape, str]]


def scene(state: BaseState) -> tuple[PieceMap, tuple[int, int, int] | None, PieceMap]:
    """(pieces to draw where they are, the box or None, pieces for the tray)."""
    from chaingeo.envs.machines.puzzle import PuzzleState
    from chaingeo.envs.machines.stacking import StackingState

    rgb = {p.name: p.rgb for p in state.level.pieces}
    if isinstance(state, StackingState):
        placed = {n: (Shape(c), rgb[n]) for n, c in state.placed.items()}
        tray = {n: (state.tables.shapes[n], rgb[n]) for n in state.tray}
        return placed, state.box, tray
    assert isinstance(state, PuzzleState)
    return _puzzle_pieces(state, rgb), None, {}


def _puzzle_pieces(state: PuzzleState, rgb: dict[str, str]) -> PieceMap:
    """Each piece as it lies (its shape turned, then moved: the cells ``state.cells_of``
    lists, without building them one by one), every part after the largest moved along +x.
    A shape's voxels are sorted by x first, so its first and last give its x extent."""
    from chaingeo.core.kinematics import oriented

    asm = state.assembly
    pieces: PieceMap = {}
    cursor: int | None = None
    for part in ordered_parts(state):
        names = sorted(part)
        placed = [
            oriented(asm.shapes[n], asm.rotation_of(n)).translate(asm.offsets[n]) for n in names
        ]
        if cursor is not None:  # the largest part stays where it is
            shift: Cell = (cursor - min(s.cells[0][0] for s in placed), 0, 0)
            placed = [s.translate(shift) for s in placed]
        for n, shape in zip(names, placed, strict=True):
            pieces[n] = (shape, rgb[n])
        cursor = max(s.cells[-1][0] for s in placed) + 1 + _LAYOUT_GAP
    return pieces


def render_state(
    state: BaseState, size: int = DEFAULT_IMAGE_SIZE, reference: bool = False
) -> dict[str, bytes]:
    """PNG bytes per view: the four views, then ``tray`` (stacking) or ``target`` (puzzles)."""
    from chaingeo.pictures.raster import png_bytes

    images = state_images(state, size, reference)
    return {name: png_bytes(img) for name, img in images.items()}


def state_images(
    state: BaseState, size: int = DEFAULT_IMAGE_SIZE, reference: bool = False
) -> dict[str, Image.Image]:
    """The pictures of an observation as images (:func:`render_state` encodes them; the
    Gymnasium environments take their pixels): the four views, then the extra picture.
    ``reference`` draws them with :mod:`chaingeo.pictures.scene` itself, the slower reference
    of :mod:`chaingeo.pictures.scene_kernel` (the same pixels)."""
    pieces, box, _ = scene(state)
    images = _views(pieces, box, VIEWS, size, None, reference)
    images[extra_picture(state)] = extra_image(state, size, reference)
    return images


def _views(
    pieces: PieceMap,
    box: Sequence[int] | None,
    views: Sequence[str],
    size: int,
    title: str | None,
    reference: bool,
) -> dict[str, Image.Image]:
    """The views drawn by the reference renderer or by its kernels (the same pixels)."""
    if reference:
        from chaingeo.pictures.scene import render_images

        return render_images(pieces, box, views, size, title)
    from PIL import Image as PILImage

    from chaingeo.pictures.scene_kernel import render_arrays

    arrays = render_arrays(pieces, box, views, size, title)
    return {v: PILImage.fromarray(a) for v, a in arrays.items()}


def extra_picture(state: BaseState) -> str:
    """The name of the picture after the four views: ``tray`` (stacking) or ``target``."""
    return extra_picture_of(state.level.family)


def extra_picture_of(family: str) -> str:
    return "tray" if family == "stacking" else "target"


def extra_image(
    state: BaseState, size: int = DEFAULT_IMAGE_SIZE, reference: bool = False
) -> Image.Image:
    """The tray (stacking: the pieces not yet placed) or the target (puzzles: the goal)."""
    if state.level.family == "stacking":
        from PIL import Image as PILImage

        from chaingeo.pictures.scene import render_tray_image
        from chaingeo.pictures.sheet import tray_pixels

        tray = scene(state)[2]
        if reference:
            return render_tray_image(tray, size)
        return PILImage.fromarray(tray_pixels(tray, size))
    title = TARGET_TITLES[state.level.goal]
    return _views(target_scene(state), None, ("iso",), size, title, reference)["iso"]


#: The first title line of a puzzle's ``target`` picture (not the current view's title).
TARGET_TITLES: Final[dict[str, str]] = {
    "assemble": "TARGET: the puzzle assembled (3D view)",
    "disassemble": "TARGET: every piece apart (3D view)",
}


def target_scene(state: BaseState) -> PieceMap:
    """A puzzle's goal: assembled (assembly), or every piece apart side by side (disassembly)."""
    pieces: PieceMap = {}
    cursor = 0
    for p in sorted(state.level.pieces, key=lambda p: p.name):
        if state.level.goal == "assemble":
            pieces[p.name] = (p.shape, p.rgb)
            continue
        shape = p.shape.translate((cursor - int(p.shape.min_corner[0]), 0, 0))
        pieces[p.name] = (shape, p.rgb)
        cursor += shape.extent[0] + _LAYOUT_GAP
    return pieces


def observe(
    state: BaseState,
    history_window: int = DEFAULT_HISTORY,
    text_state: bool = False,
    images: bool = True,
    image_size: int = DEFAULT_IMAGE_SIZE,
) -> Observation:
    """The observation of ``state`` (which is not changed)."""
    return Observation(
        instruction=instruction(state),
        color_table=color_table(state),
        history=history_lines(state, history_window),
        steps_left=state.steps_left,
        text_state=state_text(state) if text_state else None,
        images=render_state(state, image_size) if images else {},
    )
