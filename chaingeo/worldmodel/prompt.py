"""What a video (world) model is given for a level, and what it should produce.

``chain worldmodel LEVEL --out DIR`` writes ``reference.png`` (the first frame: the level's start
position from the fixed camera of the videos), ``prompt.txt`` (the task in our own words: the
physical rules CHAIN's world-model prompt asks a generated video to keep, with this level's
pieces, colours and goal) and ``ground_truth.mp4`` (or ``.gif``), the video of the level's
optimal plan from :mod:`chaingeo.worldmodel.video`, plus ``manifest.json`` naming the files and
their SHA-256. The same level gives the same bytes (MP4 too: one encoder thread, bit-exact flags).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Final

from chaingeo.core.files import atomic_write
from chaingeo.core.level import Level
from chaingeo.pictures.raster import png_bytes
from chaingeo.worldmodel.video import PlanVideo, VideoError, plan_video, write_video

FORMATS: Final = ("mp4", "gif")


def _pieces_text(level: Level) -> str:
    rows = []
    for p in level.pieces:
        n = len(p.shape)
        rows.append(f"- {p.name} ({p.rgb}): {n} cube{'s' if n != 1 else ''}")
    return "\n".join(rows)


def _goal_text(level: Level) -> str:
    n = len(level.pieces)
    if level.family == "stacking":
        assert level.box is not None
        a, b, c = level.box
        return (
            f"Goal: pack all {n} pieces into the empty {a}x{b}x{c} box until it is completely "
            "full. Each piece is lowered into the box from above, one piece at a time; a piece "
            "never passes through a piece already in the box and ends resting on the floor or "
            "on other pieces."
        )
    if level.goal == "disassemble":
        return (
            f"Goal: the image shows an interlocking puzzle of {n} pieces, assembled. Take it "
            "apart until every piece stands alone. Begin with the key piece, the one piece (or "
            "group) that can slide first; then move each piece only once it has become free to "
            "move, and carry pieces that come out away from the rest."
        )
    return (
        f"Goal: the image shows the {n} pieces of an interlocking puzzle apart. Put them "
        "together into the assembled puzzle: each piece (or group) slides in along a straight "
        "line, in an order in which every slide is possible, the last pieces locking the others."
    )


_RULES: Final = (
    "Rules the video must keep:\n"
    "- Every piece is a rigid body made of whole unit cubes: it never bends, stretches, "
    "shrinks or breaks.\n"
    "- Pieces never pass through one another, not even partly, at any moment.\n"
    "- Motion is continuous: no piece jumps, teleports, vanishes or appears from nowhere.\n"
    "{motion}\n"
    "- The geometry is exact: keep the number of pieces, each piece's shape, size and colour "
    "as in the image. Add nothing, remove nothing, resize nothing; the camera does not move."
)
_SLIDES: Final = (
    "- A piece moves only by sliding along one of the three axes of the puzzle (left-right, "
    "front-back, up-down), in a direction in which nothing blocks it; it does not rotate while "
    "any other piece still holds it, only once it is free."
)
_TURNS: Final = (
    "- A piece moves only by sliding along one of the three axes of the puzzle (left-right, "
    "front-back, up-down) in a direction in which nothing blocks it, or, in this puzzle, by a "
    "quarter turn (90 degrees) about a line parallel to one of the axes when the turning "
    "pieces sweep through no other piece (a round rod may spin in place); no other rotation."
)


def worldmodel_prompt(level: Level) -> str:
    """The prompt for a video model: the task, the physical rules, this level's pieces."""
    motion = _TURNS if getattr(level.rules, "turns", False) else _SLIDES
    return (
        f"{_goal_text(level)}\n\n{_RULES.format(motion=motion)}\n\n"
        f"The pieces ({len(level.pieces)}, each a single colour):\n{_pieces_text(level)}\n"
    )


def write_worldmodel(level: Level, out: Path, fmt: str = "mp4", size: int = 384) -> dict[str, Path]:
    """Write the reference image, the prompt, the ground-truth video and a manifest into
    ``out``; returns them by role."""
    if fmt not in FORMATS:
        raise VideoError(f"unknown video format {fmt!r}: use one of {list(FORMATS)}")
    video: PlanVideo = plan_video(level, None, size)
    out.mkdir(parents=True, exist_ok=True)
    files = {
        "reference": out / "reference.png",
        "prompt": out / "prompt.txt",
        "ground_truth": out / f"ground_truth.{fmt}",
    }
    atomic_write(files["reference"], png_bytes(video.frames[0]))
    atomic_write(files["prompt"], worldmodel_prompt(level).encode("utf-8"))
    write_video(video, files["ground_truth"])
    manifest = {
        "level": level.id,
        "frames": len(video.frames),
        "fps": video.fps,
        "files": {
            role: {"name": p.name, "sha256": hashlib.sha256(p.read_bytes()).hexdigest()}
            for role, p in sorted(files.items())
        },
    }
    files["manifest"] = out / "manifest.json"
    text = json.dumps(manifest, indent=2, sort_keys=True) + "\n"
    atomic_write(files["manifest"], text.encode("utf-8"))
    return files
